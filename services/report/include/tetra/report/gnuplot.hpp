#pragma once
// Running gnuplot for the PNG plots of the reports: a temporary directory for data and script,
// quoting, and the terminal fallback (pngcairo, else png).

#include <filesystem>
#include <string>

#include "tetra/core/result.hpp"

namespace tetra::report {

//! Error::subject of the errors of a report's plot (score_plot, pointing_plot, the Allan plot): a command
//! words it as its own option.
inline constexpr const char* kPlotSubject = "plot";

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
//! `dir` holds the script. Errors say when gnuplot is missing; they carry `subject` (the output the plot
//! is for, e.g. "plot") as their Error::subject.
Status run_gnuplot(const std::filesystem::path& dir, const std::string& png_path, int width, int height,
                   const std::string& body, const std::string& subject);

}  // namespace tetra::report
