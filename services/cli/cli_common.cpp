#include "cli_common.hpp"

#include <charconv>
#include <cstdint>
#include <cstdio>
#include <iostream>

#include <fmt/format.h>

#include "tetra/core/csv.hpp"
#include "tetra/core/provenance.hpp"
#include "tetra/report/gnuplot.hpp"

namespace tetra::cli {

namespace {

bool starts_with(const std::string& text, const char* prefix) {
  return text.rfind(prefix, 0) == 0;
}

// Plain decimal numbers only: CLI11 alone reads "0x10" as 16, "" as nothing and "1,5" as 1 or 15.
enum class NumberForm { kReal, kInteger, kUnsigned };

template <class T>
bool whole_number(const std::string& text) {
  T value{};
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return !text.empty() && ec == std::errc() && ptr == text.data() + text.size();
}

CLI::Validator plain_number(NumberForm form) {
  return CLI::Validator(
      [form](std::string& text) -> std::string {
        switch (form) {
          case NumberForm::kInteger:
            return whole_number<std::int64_t>(text) ? std::string() : "'" + text + "' is not a whole number";
          case NumberForm::kUnsigned:
            return whole_number<std::uint64_t>(text)
                       ? std::string()
                       : "'" + text + "' is not a whole number in 0.." + std::to_string(UINT64_MAX);
          case NumberForm::kReal:
            break;
        }
        return parse_decimal(text) ? std::string() : "'" + text + "' is not a finite decimal number";
      },
      "", "plain decimal");
}

// Every numeric option takes plain decimal numbers; a single-valued option given twice is an error.
void harden(CLI::App& app) {
  for (CLI::Option* opt : app.get_options()) {
    const std::string type = opt->get_type_name();
    if (starts_with(type, "FLOAT")) opt->check(plain_number(NumberForm::kReal));
    if (starts_with(type, "INT")) opt->check(plain_number(NumberForm::kInteger));
    if (starts_with(type, "UINT")) opt->check(plain_number(NumberForm::kUnsigned));
    if (opt->get_expected_max() == 1 && opt->get_items_expected_max() == 1)
      opt->multi_option_policy(CLI::MultiOptionPolicy::Throw);
  }
}

}  // namespace

CLI::Validator number_in(double min, double max, bool above_min) {
  const auto text_of = [](double v) {
    std::string out;
    append_double(out, v);
    return out;
  };
  const std::string range =
      (above_min ? "above " : "from ") + text_of(min) + (above_min ? " and at most " : " to ") + text_of(max);
  return CLI::Validator(
      [min, max, above_min, range](std::string& text) -> std::string {
        const auto v = parse_decimal(text);
        const bool ok = v && (above_min ? *v > min : *v >= min) && *v <= max;
        const std::string shown = text.size() > 40 ? text.substr(0, 40) + "..." : text;
        return ok ? std::string() : "'" + shown + "' must be " + range;
      },
      range, "in range");
}

std::optional<int> parse(CLI::App& app, int argc, char** argv) {
  harden(app);
  app.set_version_flag("--version", std::string("tetra ") + kVersion);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return kExitOk;
  } catch (const CLI::CallForAllHelp&) {
    std::cout << app.help("", CLI::AppFormatMode::All);
    return kExitOk;
  } catch (const CLI::CallForVersion&) {
    std::cout << "tetra " << kVersion << "\n";
    return kExitOk;
  } catch (const CLI::Success&) {  // a flag that did its work while parsing (replay --config-keys)
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    std::cerr << "tetra " << app.get_name() << ": " << e.what() << " (see 'tetra " << app.get_name()
              << " --help')\n";
    return kExitBadInput;
  }
  return std::nullopt;
}

std::string user_message(const Error& error, std::initializer_list<SubjectOption> options) {
  for (const SubjectOption& o : options) {
    if (error.subject.name != o.subject) continue;
    return one_line(fmt::format(fmt::runtime(o.format), fmt::arg("value", error.subject.value),
                                fmt::arg("message", error.message)));
  }
  // Every command that plots names its PNG option --plot.
  if (error.subject.name == report::kPlotSubject) return one_line("--plot: " + error.message);
  return describe(error);
}

int report(const std::string& command, const Error& error, std::initializer_list<SubjectOption> options) {
  std::cerr << "tetra " << command << ": " << user_message(error, options) << '\n';
  return error.kind == ErrorKind::kBadInput ? kExitBadInput : kExitFailure;
}

}  // namespace tetra::cli
