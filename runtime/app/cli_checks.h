// Checks on command-line values, run by CLI11 while it parses, so that a bad value is refused
// before any work starts, in one line naming the option (`--attack-speed: ...`), against the
// range documented in its --help. CLI11's own PositiveNumber lets NaN through (NaN <= 0 is
// false) and its unsigned conversion turns `-1` into 2^64 - 1 (issue 38); these do neither.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

namespace autoshovel::app {

/// A finite number in [low, high] (`open_low`: (low, high]). Refuses NaN, inf, trailing text.
CLI::Validator FiniteIn(double low, double high, bool open_low = false);

/// An integer in [low, high], written in decimal digits with an optional minus sign; refuses
/// fractions, exponents and anything beyond the range instead of wrapping it.
CLI::Validator IntegerIn(long long low, long long high);

/// The documented range of every seed: [0, 2^63 - 1], so that it is stored unchanged in SQLite's
/// signed 64-bit INTEGER and in config.yaml.
inline constexpr std::uint64_t kMaxSeed = 9223372036854775807ULL;
CLI::Validator SeedRange();

/// The error line of a refused command line: `autoshovel SUBCOMMAND: what (see --help)`.
std::string FailureLine(const CLI::App* app, const CLI::Error& error);

}  // namespace autoshovel::app
