// Strict YAML reading with located errors.
//
// Every value is read through a MapReader, which records where the value came from, checks its
// type and range, and at Finish() reports keys nobody asked for ("did you mean ...?"). Problems
// go to a DiagnosticSink as `file:line:column: key.path: message`; the caller throws once the
// whole file has been read, so one run reports every problem (STYLE.md, drake's strict reader).
//
// This header includes yaml-cpp: include it only from the .cc files that read files.
#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/core/diagnostics.h"

namespace autoshovel::core {

/// Where each value of a file came from, by key path (`arm.links[0].length`).
using LocationIndex = std::map<std::string, SourceLocation>;

/// Allowed range of a number, with its unit for messages.
struct NumberRule {
  enum class Bound { kNone, kInclusive, kExclusive };
  double min = 0.0;
  Bound min_bound = Bound::kNone;
  double max = 0.0;
  Bound max_bound = Bound::kNone;
  std::string unit;

  static NumberRule Any(std::string unit = "");
  static NumberRule Positive(std::string unit);
  static NumberRule NonNegative(std::string unit);
  /// min <= x <= max.
  static NumberRule Closed(double min, double max, std::string unit);
  /// min < x < max.
  static NumberRule Open(double min, double max, std::string unit);

  /// "" when `value` satisfies the rule, else e.g. "must be > 0 m, got -1.3".
  std::string Check(double value) const;
};

/// The largest YAML (or JSON) file a reader parses: 16 MiB. yaml-cpp holds about 45 times a
/// file's size in memory (a 70 MB file took 3.2 GB and 24 s), so a file is measured before it is
/// parsed. The largest YAML the project ships is under 7 KB (models/excavators/excavator_25t.yaml)
/// and a SAM mask file with compressed RLE a few hundred KB: the limit leaves a wide margin.
inline constexpr std::uintmax_t kMaxYamlBytes = std::uintmax_t{16} << 20;

/// Reads and parses one YAML (or JSON: YAML 1.2 flow style) file, refusing into `sink`:
/// - something that is not a regular file, or a file over `max_bytes`, before parsing it;
/// - a syntax error, at its location;
/// - a key given twice in one mapping, at the second one with the line of the first
///   (`file:9:3: arm.length: duplicate key 'length' (first at line 4)`). yaml-cpp keeps both and
///   `node[key]` returns the first, so a correction appended to a file would be ignored.
/// Returns the first document (null when refused). Every YAML reader of the project reads
/// through this function (YamlFile does).
YAML::Node LoadYamlFile(const std::filesystem::path& path, DiagnosticSink& sink,
                        std::uintmax_t max_bytes = kMaxYamlBytes);

/// A parsed YAML file. Parse errors are reported with their location; `root()` is then null.
class YamlFile {
 public:
  YamlFile(const std::filesystem::path& path, DiagnosticSink& sink);

  const std::string& file() const { return file_; }
  const YAML::Node& root() const { return root_; }
  bool ok() const { return ok_; }
  DiagnosticSink& sink() const { return *sink_; }

 private:
  std::string file_;
  YAML::Node root_;
  bool ok_ = false;
  DiagnosticSink* sink_;
};

/// Location of a node (1-based), in `file`.
SourceLocation LocationOf(const std::string& file, const YAML::Node& node);

/// Reads one YAML mapping strictly. Getters of required values report a missing key at the
/// mapping's own location; invalid values are reported at the value's location. A getter that
/// failed returns NaN / empty, and the caller must not use the result: the sink is not empty.
class MapReader {
 public:
  MapReader(const YamlFile& file, const YAML::Node& node, std::string key_path,
            LocationIndex* index);

  /// The reader of the file's root mapping.
  static MapReader Root(const YamlFile& file, LocationIndex* index);

  bool Has(std::string_view key) const;
  const std::string& key_path() const { return key_path_; }
  SourceLocation location() const;
  /// Location of `key`'s value, or of this mapping if the key is absent.
  SourceLocation LocationOf(std::string_view key) const;
  std::string PathOf(std::string_view key) const;

  double Number(std::string_view key, const NumberRule& rule);
  double Number(std::string_view key, const NumberRule& rule, double fallback);
  /// Reads degrees from the file (the key must end in `_deg`) and returns radians. The rule is
  /// in degrees.
  double AngleDeg(std::string_view key, const NumberRule& rule_deg);
  double AngleDeg(std::string_view key, const NumberRule& rule_deg, double fallback_deg);
  int Integer(std::string_view key, int min, int max);
  int Integer(std::string_view key, int min, int max, int fallback);
  std::string String(std::string_view key);
  std::optional<std::string> OptionalString(std::string_view key);
  /// One of `options`; otherwise "must be one of a | b, got 'c'".
  std::string Enum(std::string_view key, const std::vector<std::string>& options);
  /// A fixed-size list of numbers, e.g. a point `[x, z]`.
  template <std::size_t N>
  std::array<double, N> Numbers(std::string_view key, const NumberRule& rule);
  std::vector<std::string> Strings(std::string_view key, bool required);

  /// The raw node of `key` for structures the getters do not cover (recorded and known).
  std::optional<YAML::Node> Raw(std::string_view key, bool required);

  MapReader Map(std::string_view key);
  std::optional<MapReader> OptionalMap(std::string_view key);
  /// A non-empty list of mappings.
  std::vector<MapReader> MapList(std::string_view key, bool required);

  /// Reports missing required keys and every key that no getter asked for, suggesting the
  /// nearest known key. Must be called once all values are read.
  void Finish();

  /// Reports a problem with `key`'s value at its location.
  void Error(std::string_view key, std::string message) const;

 private:
  std::optional<YAML::Node> Value(std::string_view key, bool required);
  std::optional<double> ParseNumber(const YAML::Node& node, const std::string& path) const;
  void Record(std::string_view key, const YAML::Node& node);
  std::vector<double> NumberList(std::string_view key, std::size_t size, const NumberRule& rule);

  const YamlFile* file_;
  YAML::Node node_;
  std::string key_path_;
  LocationIndex* index_;
  bool valid_ = false;
  std::set<std::string, std::less<>> known_keys_;
  /// Required keys found missing; reported by Finish() unless an unknown key is a likely typo
  /// of one (then the single "did you mean" line says it all).
  std::vector<std::string> missing_keys_;
};

template <std::size_t N>
std::array<double, N> MapReader::Numbers(std::string_view key, const NumberRule& rule) {
  const std::vector<double> values = NumberList(key, N, rule);
  std::array<double, N> out{};
  for (std::size_t i = 0; i < N; ++i) out[i] = values[i];
  return out;
}

}  // namespace autoshovel::core
