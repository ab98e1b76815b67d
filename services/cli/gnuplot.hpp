#pragma once
// Running gnuplot for the PNG plots of the commands: a temporary directory for data and script,
// quoting, and the terminal fallback (pngcairo, else png).

#include <filesystem>
#include <string>

#include "tetra/core/result.hpp"

namespace tetra::cli {

//! A string inside single quotes for gnuplot ('' is a quote).
std::string gp_quote(const std::string& s);

//! A temporary directory removed with its contents when the object goes.
class TempDir {
 public:
  static Result<TempDir> create(const std::string& prefix);
  TempDir(TempDir&& other) noexcept : path_(std::move(other.path_)) { other.path_.clear(); }
  TempDir& operator=(TempDir&&) = delete;
  TempDir(const TempDir&) = delete;
  ~TempDir();
  const std::filesystem::path& path() const { return path_; }

 private:
  explicit TempDir(std::filesystem::path path) : path_(std::move(path)) {}
  std::filesystem::path path_;
};

//! Writes `png_path` with the gnuplot commands `body` on a canvas of `width`×`height` pixels;
//! `dir` holds the script. Errors say when gnuplot is missing. `option` names the option in messages.
Status run_gnuplot(const std::filesystem::path& dir, const std::string& png_path, int width, int height,
                   const std::string& body, const std::string& option);

}  // namespace tetra::cli
