#include "runtime/app/cli_checks.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

#include "runtime/core/strings.h"

namespace autoshovel::app {

namespace {

bool ParseDouble(const std::string& text, double& value) {
  if (text.empty()) return false;
  errno = 0;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && errno != ERANGE;
}

bool ParseInteger(const std::string& text, long long& value) {
  std::size_t digits_from = text.size() > 0 && (text[0] == '-' || text[0] == '+') ? 1 : 0;
  if (digits_from == text.size()) return false;
  for (std::size_t i = digits_from; i < text.size(); ++i) {
    if (text[i] < '0' || text[i] > '9') return false;
  }
  errno = 0;
  value = std::strtoll(text.c_str(), nullptr, 10);
  return errno != ERANGE;
}

std::string Range(double low, double high, bool open_low) {
  return (open_low ? "(" : "[") + core::FormatNumber(low) + ", " + core::FormatNumber(high) + "]";
}

}  // namespace

CLI::Validator FiniteIn(double low, double high, bool open_low) {
  const std::string range = Range(low, high, open_low);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double value = 0;
        if (!ParseDouble(text, value) || !std::isfinite(value)) {
          return "expected a finite number in " + range + ", got '" + text + "'";
        }
        if (value < low || value > high || (open_low && value == low)) {
          return "must be in " + range + ", got " + text;
        }
        return "";
      },
      "in " + range);
}

CLI::Validator IntegerIn(long long low, long long high) {
  const std::string range = "[" + std::to_string(low) + ", " + std::to_string(high) + "]";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        long long value = 0;
        if (!ParseInteger(text, value)) {
          return "expected an integer in " + range + ", got '" + text + "'";
        }
        if (value < low || value > high) return "must be in " + range + ", got " + text;
        return "";
      },
      "in " + range);
}

CLI::Validator SeedRange() { return IntegerIn(0, static_cast<long long>(kMaxSeed)); }

std::string FailureLine(const CLI::App* app, const CLI::Error& error) {
  // The deepest subcommand given names the command: `autoshovel calibrate arm: ...`.
  // Not the root's own name: that is argv[0] as typed (`./build/autoshovel`).
  std::string command = "autoshovel";
  for (const CLI::App* level = app;;) {
    const std::vector<CLI::App*> given = level->get_subcommands();
    if (given.empty()) break;
    level = given.front();
    command += " " + level->get_name();
  }
  return command + ": " + error.what() + " (see --help)\n";
}

}  // namespace autoshovel::app
