#include "tetra/core/provenance.hpp"

#include <ctime>

namespace tetra {

namespace {

std::string& command_line_store() {
  static std::string line;
  return line;
}

// A shell word: quoted with '' when it holds anything but plain characters.
std::string shell_word(const std::string& arg) {
  if (!arg.empty() && arg.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                            "-_./=:,+@%") == std::string::npos)
    return arg;
  std::string out = "'";
  for (const char c : arg) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace

void record_command_line(int argc, char** argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) line += (i == 0 ? "" : " ") + shell_word(i == 0 ? "tetra" : argv[i]);
  command_line_store() = line;
}

Provenance provenance(std::vector<std::string> inputs) {
  Provenance p;
  p.command_line = command_line_store();
  p.inputs = std::move(inputs);
  p.created_utc = utc_now();
  return p;
}

std::vector<std::pair<std::string, std::string>> provenance_metadata(const Provenance& p) {
  std::string inputs;
  for (const auto& in : p.inputs) inputs += (inputs.empty() ? "" : ";") + in;
  return {{"tetra_version", p.version},
          {"command", p.command_line},
          {"inputs", inputs},
          {"created_utc", p.created_utc}};
}

}  // namespace tetra
