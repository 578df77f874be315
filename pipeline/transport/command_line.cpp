// Command-line parsing with one behaviour for every program, see command_line.hpp.
#include "pipeline/transport/command_line.hpp"

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace sss::cli {

CommandLine::CommandLine(const std::string& program, const std::string& description, const std::string& footer)
    : CLI::App(description, program) {
  if (!footer.empty()) this->footer(footer);
  // A flag given twice is a mistake, not "the last one wins" (CLI11's default for single values).
  option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::Throw);
}

namespace {
// A check on the number the text holds; an empty message: fine. A text that is no number is left
// to the conversion, which says so.
CLI::Validator numberCheck(const char* description, bool (*accept)(double), const char* wanted) {
  return CLI::Validator(
      [accept, wanted](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0') return {};
        return accept(value) ? std::string() : std::string("must be ") + wanted + ", got " + text;
      },
      description);
}
}  // namespace

CLI::Validator nonNegative() {
  return numberCheck(">= 0", [](double value) { return value >= 0.0; }, ">= 0");
}

CLI::Validator positive() {
  return numberCheck("> 0", [](double value) { return value > 0.0; }, "> 0");
}

CLI::Option* addIncreasingPair(CLI::App& app, const std::string& name, double& min, double& max,
                               const std::string& description, const CLI::Validator& check) {
  return app
      .add_option_function<std::vector<double>>(
          name,
          [name, &min, &max](const std::vector<double>& values) {
            if (!(values[0] < values[1])) {
              std::ostringstream text;
              text << "MIN,MAX needs MIN < MAX, got " << values[0] << "," << values[1];
              throw CLI::ValidationError(name, text.str());
            }
            min = values[0];
            max = values[1];
          },
          description)
      ->delimiter(',')
      ->expected(2)
      ->check(check);
}

int parseCommandLine(CLI::App& app, int argc, const char* const* argv) {
  try {
    app.parse(argc, argv);
    return -1;
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return 0;
  } catch (const CLI::ParseError& error) {
    std::fprintf(stderr, "%s: %s\n%s", app.get_name().c_str(), error.what(), app.help().c_str());
    return 2;
  }
}

}  // namespace sss::cli
