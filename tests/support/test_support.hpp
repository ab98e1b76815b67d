#pragma once
// Helpers shared by the tests: temporary directories, running the tetra program, reading files.

#include <filesystem>
#include <string>

namespace tetra::test {

//! A fresh directory under the system temp dir, removed when the object goes out of scope.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

struct CommandResult {
  int exit_status = -1;
  std::string out;  //!< stdout
  std::string err;  //!< stderr
};

//! Runs `tetra ARGS` (ARGS is shell text) and captures status, stdout and stderr.
CommandResult run_tetra(const std::string& args);
//! Runs any shell command line and captures the same.
CommandResult run_shell(const std::string& command_line);

std::string read_file(const std::string& path);
void write_file(const std::string& path, const std::string& content);
//! Path of a file in the source tree (e.g. "examples/factory.yaml").
std::string source_path(const std::string& relative);

}  // namespace tetra::test
