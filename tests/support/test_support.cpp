#include "test_support.hpp"

#include <sys/wait.h>

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

namespace tetra::test {

TempDir::TempDir() {
  static std::atomic<int> counter{0};
  std::random_device rd;
  path_ = std::filesystem::temp_directory_path() /
          ("tetra-test-" + std::to_string(rd()) + "-" + std::to_string(counter++));
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_file(const std::string& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary);
  out << content;
}

std::string source_path(const std::string& relative) {
  return std::string(TETRA_SOURCE_DIR) + "/" + relative;
}

CommandResult run_shell(const std::string& command_line) {
  TempDir dir;
  const std::string out_file = dir.file("stdout");
  const std::string err_file = dir.file("stderr");
  const std::string full = "(" + command_line + ") >" + out_file + " 2>" + err_file + " </dev/null";
  const int raw = std::system(full.c_str());
  CommandResult r;
  r.exit_status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = read_file(out_file);
  r.err = read_file(err_file);
  return r;
}

CommandResult run_tetra(const std::string& args) {
  return run_shell(std::string(TETRA_BINARY) + " " + args);
}

}  // namespace tetra::test
