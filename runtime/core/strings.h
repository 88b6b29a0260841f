// Small string helpers shared by the readers and the CLI.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace autoshovel::core {

/// Levenshtein edit distance (insertions, deletions, substitutions all cost 1).
std::size_t EditDistance(std::string_view a, std::string_view b);

/// The candidate closest to `word` by edit distance, or "" when none is close enough to be a
/// plausible typo (distance above a third of the word's length, at least 2).
std::string NearestWord(std::string_view word, const std::vector<std::string>& candidates);

/// `value` with `digits` decimals, as printf's "%.*f" writes it (for tables and log lines).
std::string Fixed(double value, int digits);

/// Formats a double with the shortest representation that reads back to the same value.
std::string FormatNumber(double value);

}  // namespace autoshovel::core
