#include "tetra/report/gnuplot.hpp"

#include <sys/wait.h>
#include <unistd.h>
#include <cstdlib>

#include "tetra/core/csv.hpp"

namespace tetra::report {

namespace {

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

}  // namespace

std::string gp_quote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) {
    if (c == '\'') out += '\'';
    out += c;
  }
  return out + "'";
}

Result<TempDir> TempDir::create(const std::string& prefix) {
  std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
  if (::mkdtemp(pattern.data()) == nullptr) return failure("cannot create a temporary directory");
  return TempDir(std::filesystem::path(pattern));
}

TempDir::~TempDir() {
  if (path_.empty()) return;
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

Status run_gnuplot(const std::filesystem::path& dir, const std::string& png_path, int width, int height,
                   const std::string& body, const std::string& subject) {
  const std::string size = std::to_string(width) + "," + std::to_string(height);
  for (const char* terminal : {"pngcairo", "png"}) {
    const std::string script_file = (dir / "plot.gp").string();
    const std::string script = std::string("set terminal ") + terminal + " size " + size + " enhanced\n" +
                               "set output " + gp_quote(png_path) + "\n" + body + "set output\n";
    if (Status s = write_text_file(script_file, script); !s) return s;
    const std::string err_file = (dir / "gnuplot.err").string();
    const int rc =
        std::system(("gnuplot " + shell_quote(script_file) + " 2>" + shell_quote(err_file)).c_str());
    if (rc == 0) return ok_status();
    if (rc == -1 || (WIFEXITED(rc) && WEXITSTATUS(rc) == 127)) {
      return failure(ErrorSubject(subject),
                     "gnuplot not found (install the Debian package gnuplot-nox; see scripts/setup.sh)");
    }
  }
  return failure(ErrorSubject(subject), "gnuplot could not write " + png_path);
}

}  // namespace tetra::report
