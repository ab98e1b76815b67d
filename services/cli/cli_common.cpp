#include "cli_common.hpp"

#include <cstdio>
#include <iostream>

namespace tetra::cli {

std::optional<int> parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return kExitOk;
  } catch (const CLI::CallForAllHelp&) {
    std::cout << app.help("", CLI::AppFormatMode::All);
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    std::cerr << "tetra " << app.get_name() << ": " << e.what() << " (see 'tetra " << app.get_name()
              << " --help')\n";
    return kExitBadInput;
  }
  return std::nullopt;
}

int report(const std::string& command, const Error& error) {
  std::cerr << "tetra " << command << ": " << error.message << '\n';
  return error.kind == ErrorKind::kBadInput ? kExitBadInput : kExitFailure;
}

}  // namespace tetra::cli
