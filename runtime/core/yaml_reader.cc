#include "runtime/core/yaml_reader.h"

#include <yaml-cpp/eventhandler.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include "runtime/core/input_file.h"
#include "runtime/core/strings.h"

namespace autoshovel::core {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string WithUnit(double value, const std::string& unit) {
  return FormatNumber(value) + (unit.empty() ? "" : " " + unit);
}

std::string Describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Null:
      return "nothing";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a mapping";
    case YAML::NodeType::Scalar:
      return "'" + node.Scalar() + "'";
    default:
      return "an undefined value";
  }
}

// Finds keys given twice in one mapping, from the parser's events: the loaded node tree cannot
// tell (yaml-cpp keeps both pairs and `node[key]` returns the first), and walking the events
// never expands an alias, so a file of nested aliases costs no more than its size.
class DuplicateKeyFinder : public YAML::EventHandler {
 public:
  explicit DuplicateKeyFinder(std::string file) : file_(std::move(file)) {}

  const std::vector<Diagnostic>& duplicates() const { return duplicates_; }

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { Leaf(mark, nullptr); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { Leaf(mark, nullptr); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string& value) override {
    Leaf(mark, &value);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    Open(mark, /*is_map=*/false);
  }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    Open(mark, /*is_map=*/true);
  }
  void OnSequenceEnd() override { Close(); }
  void OnMapEnd() override { Close(); }

 private:
  struct Collection {
    bool is_map = false;
    std::string path;
    bool expecting_key = true;                           // maps: the next node is a key
    std::string key;                                     // maps: the key whose value comes next
    std::size_t index = 0;                               // sequences: the next item's index
    std::map<std::string, int, std::less<>> first_line;  // maps: key -> 1-based line
  };

  static std::string Join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

  // The key path of the node that starts now, or nullopt when it is a mapping's key.
  std::optional<std::string> Begin(const YAML::Mark& mark, const std::string* scalar) {
    if (stack_.empty()) return std::string();
    Collection& parent = stack_.back();
    if (!parent.is_map) return parent.path + "[" + std::to_string(parent.index++) + "]";
    if (!parent.expecting_key) return Join(parent.path, parent.key);
    // A key. Only names can repeat meaningfully; other keys MapReader::Finish() refuses.
    parent.key = scalar != nullptr ? *scalar : "?";
    if (scalar != nullptr) {
      const auto [it, inserted] = parent.first_line.emplace(*scalar, mark.line + 1);
      if (!inserted) {
        duplicates_.push_back(
            {{file_, mark.line + 1, mark.column + 1},
             Join(parent.path, *scalar),
             "duplicate key '" + *scalar + "' (first at line " + std::to_string(it->second) + ")"});
      }
    }
    return std::nullopt;
  }

  // A node is complete: in a mapping, a key is followed by its value and a value by a key.
  void End() {
    if (!stack_.empty() && stack_.back().is_map) {
      stack_.back().expecting_key = !stack_.back().expecting_key;
    }
  }

  void Leaf(const YAML::Mark& mark, const std::string* scalar) {
    Begin(mark, scalar);
    End();
  }

  void Open(const YAML::Mark& mark, bool is_map) {
    const std::optional<std::string> path = Begin(mark, nullptr);
    Collection c;
    c.is_map = is_map;
    // A mapping or list used as a key has no name: its contents are named after the mapping.
    c.path = path ? *path : Join(stack_.back().path, "?");
    stack_.push_back(std::move(c));
  }

  void Close() {
    if (!stack_.empty()) stack_.pop_back();
    End();
  }

  std::string file_;
  std::vector<Collection> stack_;
  std::vector<Diagnostic> duplicates_;
};

std::string MebibyteText(std::uintmax_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1 << 20));
  return text;
}

}  // namespace

YAML::Node LoadYamlFile(const std::filesystem::path& path, DiagnosticSink& sink,
                        std::uintmax_t max_bytes) {
  const std::string file = path.string();
  std::error_code error;
  if (const std::string why = NotARegularFile(path); !why.empty()) {
    sink.Add({file, 0, 0}, "", "cannot open: " + why);
    return YAML::Node();
  }
  // Measured before anything is read: a huge file is refused in microseconds, not after
  // gigabytes of parsing.
  const std::uintmax_t bytes = std::filesystem::file_size(path, error);
  if (!error && bytes > max_bytes) {
    sink.Add({file, 0, 0}, "",
             "the file is " + std::to_string(bytes) + " bytes (" + MebibyteText(bytes) +
                 "), more than the " + MebibyteText(max_bytes) +
                 " a YAML input may have (docs/robustness.md, \"Input size limits\"): not parsed");
    return YAML::Node();
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    sink.Add({file, 0, 0}, "", "cannot open for reading");
    return YAML::Node();
  }
  std::ostringstream bytes_read;
  bytes_read << in.rdbuf();
  const std::string text = bytes_read.str();
  // Parsed twice, once for the events (duplicate keys) and once for the nodes: the file is
  // small (the limit above) and the event pass is the only place a duplicate is still visible.
  DuplicateKeyFinder finder(file);
  YAML::Node root;
  try {
    std::istringstream events(text);
    YAML::Parser parser(events);
    parser.HandleNextDocument(finder);
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    sink.Add({file, e.mark.line + 1, e.mark.column + 1}, "", "YAML syntax error: " + e.msg);
    return YAML::Node();
  }
  if (!finder.duplicates().empty()) {
    for (const Diagnostic& d : finder.duplicates()) sink.Add(d.where, d.key_path, d.message);
    return YAML::Node();
  }
  return root;
}

NumberRule NumberRule::Any(std::string unit) { return {0, Bound::kNone, 0, Bound::kNone, unit}; }
NumberRule NumberRule::Positive(std::string unit) {
  return {0, Bound::kExclusive, 0, Bound::kNone, unit};
}
NumberRule NumberRule::NonNegative(std::string unit) {
  return {0, Bound::kInclusive, 0, Bound::kNone, unit};
}
NumberRule NumberRule::Closed(double min, double max, std::string unit) {
  return {min, Bound::kInclusive, max, Bound::kInclusive, unit};
}
NumberRule NumberRule::Open(double min, double max, std::string unit) {
  return {min, Bound::kExclusive, max, Bound::kExclusive, unit};
}

std::string NumberRule::Check(double value) const {
  const std::string got = ", got " + WithUnit(value, unit);
  const bool low_ok =
      min_bound == Bound::kNone || (min_bound == Bound::kInclusive ? value >= min : value > min);
  const bool high_ok =
      max_bound == Bound::kNone || (max_bound == Bound::kInclusive ? value <= max : value < max);
  if (low_ok && high_ok) return "";
  if (min_bound != Bound::kNone && max_bound != Bound::kNone) {
    const char* open = min_bound == Bound::kInclusive ? "[" : "(";
    const char* close = max_bound == Bound::kInclusive ? "]" : ")";
    return "must be in " + std::string(open) + FormatNumber(min) + ", " + FormatNumber(max) +
           close + (unit.empty() ? "" : " " + unit) + got;
  }
  if (!low_ok) {
    return std::string("must be ") + (min_bound == Bound::kInclusive ? ">= " : "> ") +
           WithUnit(min, unit) + got;
  }
  return std::string("must be ") + (max_bound == Bound::kInclusive ? "<= " : "< ") +
         WithUnit(max, unit) + got;
}

SourceLocation LocationOf(const std::string& file, const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (mark.is_null()) return {file, 0, 0};
  return {file, mark.line + 1, mark.column + 1};
}

YamlFile::YamlFile(const std::filesystem::path& path, DiagnosticSink& sink)
    : file_(path.string()), sink_(&sink) {
  // The sink may already hold another file's problems: this file's are the ones added now.
  const std::size_t problems_before = sink.diagnostics().size();
  root_ = LoadYamlFile(path, sink);
  if (sink.diagnostics().size() != problems_before) return;
  if (!root_.IsMap()) {
    sink.Add({file_, 1, 1}, "",
             "expected a mapping of keys at the top level, got " + Describe(root_));
    return;
  }
  ok_ = true;
}

MapReader::MapReader(const YamlFile& file, const YAML::Node& node, std::string key_path,
                     LocationIndex* index)
    : file_(&file), node_(node), key_path_(std::move(key_path)), index_(index) {
  valid_ = node_.IsMap();
  // A missing or empty value arrives as a null node: the parent reports it as a missing key
  // (with its location), so it is not a second "expected a mapping" here.
  if (!valid_ && node_.IsDefined() && !node_.IsNull()) {
    file_->sink().Add(core::LocationOf(file_->file(), node_), key_path_,
                      "expected a mapping, got " + Describe(node_));
  }
}

MapReader MapReader::Root(const YamlFile& file, LocationIndex* index) {
  if (!file.ok()) return MapReader(file, YAML::Node(), "", index);
  return MapReader(file, file.root(), "", index);
}

bool MapReader::Has(std::string_view key) const {
  return valid_ && node_[std::string(key)].IsDefined() && !node_[std::string(key)].IsNull();
}

SourceLocation MapReader::location() const { return core::LocationOf(file_->file(), node_); }

SourceLocation MapReader::LocationOf(std::string_view key) const {
  if (!Has(key)) return location();
  return core::LocationOf(file_->file(), node_[std::string(key)]);
}

std::string MapReader::PathOf(std::string_view key) const {
  return key_path_.empty() ? std::string(key) : key_path_ + "." + std::string(key);
}

void MapReader::Error(std::string_view key, std::string message) const {
  file_->sink().Add(LocationOf(key), PathOf(key), std::move(message));
}

void MapReader::Record(std::string_view key, const YAML::Node& node) {
  if (index_ != nullptr) (*index_)[PathOf(key)] = core::LocationOf(file_->file(), node);
}

std::optional<YAML::Node> MapReader::Value(std::string_view key, bool required) {
  known_keys_.emplace(key);
  if (!valid_) return std::nullopt;
  const YAML::Node value = node_[std::string(key)];
  if (!value.IsDefined() || value.IsNull()) {
    if (required) missing_keys_.emplace_back(key);
    return std::nullopt;
  }
  Record(key, value);
  return value;
}

std::optional<double> MapReader::ParseNumber(const YAML::Node& node,
                                             const std::string& path) const {
  if (!node.IsScalar()) {
    file_->sink().Add(core::LocationOf(file_->file(), node), path,
                      "expected a number, got " + Describe(node));
    return std::nullopt;
  }
  double value = kNaN;
  if (!YAML::convert<double>::decode(node, value)) {
    file_->sink().Add(core::LocationOf(file_->file(), node), path,
                      "expected a number, got " + Describe(node));
    return std::nullopt;
  }
  if (!std::isfinite(value)) {
    file_->sink().Add(core::LocationOf(file_->file(), node), path,
                      "expected a finite number, got " + Describe(node));
    return std::nullopt;
  }
  return value;
}

double MapReader::Number(std::string_view key, const NumberRule& rule) {
  const auto node = Value(key, /*required=*/true);
  if (!node) return kNaN;
  const auto value = ParseNumber(*node, PathOf(key));
  if (!value) return kNaN;
  if (const std::string problem = rule.Check(*value); !problem.empty()) {
    Error(key, problem);
    return kNaN;
  }
  return *value;
}

double MapReader::Number(std::string_view key, const NumberRule& rule, double fallback) {
  known_keys_.emplace(key);
  if (!Has(key)) return fallback;
  return Number(key, rule);
}

double MapReader::AngleDeg(std::string_view key, const NumberRule& rule_deg) {
  return Number(key, rule_deg) * std::numbers::pi / 180.0;
}

double MapReader::AngleDeg(std::string_view key, const NumberRule& rule_deg, double fallback_deg) {
  return Number(key, rule_deg, fallback_deg) * std::numbers::pi / 180.0;
}

int MapReader::Integer(std::string_view key, int min, int max) {
  const auto node = Value(key, /*required=*/true);
  if (!node) return 0;
  int value = 0;
  if (!node->IsScalar() || !YAML::convert<int>::decode(*node, value)) {
    Error(key, "expected an integer, got " + Describe(*node));
    return 0;
  }
  if (value < min || value > max) {
    Error(key, "must be in [" + std::to_string(min) + ", " + std::to_string(max) + "], got " +
                   std::to_string(value));
    return 0;
  }
  return value;
}

int MapReader::Integer(std::string_view key, int min, int max, int fallback) {
  known_keys_.emplace(key);
  if (!Has(key)) return fallback;
  return Integer(key, min, max);
}

std::string MapReader::String(std::string_view key) {
  const auto node = Value(key, /*required=*/true);
  if (!node) return "";
  if (!node->IsScalar()) {
    Error(key, "expected a string, got " + Describe(*node));
    return "";
  }
  return node->Scalar();
}

std::optional<std::string> MapReader::OptionalString(std::string_view key) {
  known_keys_.emplace(key);
  if (!Has(key)) return std::nullopt;
  return String(key);
}

std::string MapReader::Enum(std::string_view key, const std::vector<std::string>& options) {
  const std::string value = String(key);
  if (value.empty() && !Has(key)) return "";
  for (const auto& option : options) {
    if (value == option) return value;
  }
  std::string list;
  for (const auto& option : options) list += (list.empty() ? "" : " | ") + option;
  std::string message = "must be one of " + list + ", got '" + value + "'";
  if (const std::string near = NearestWord(value, options); !near.empty()) {
    message += " (did you mean '" + near + "'?)";
  }
  Error(key, message);
  return "";
}

std::vector<double> MapReader::NumberList(std::string_view key, std::size_t size,
                                          const NumberRule& rule) {
  std::vector<double> out(size, kNaN);
  const auto node = Value(key, /*required=*/true);
  if (!node) return out;
  if (!node->IsSequence() || node->size() != size) {
    Error(key, "expected a list of " + std::to_string(size) + " numbers, got " + Describe(*node) +
                   (node->IsSequence() ? " of " + std::to_string(node->size()) : ""));
    return out;
  }
  for (std::size_t i = 0; i < size; ++i) {
    const std::string path = PathOf(key) + "[" + std::to_string(i) + "]";
    const auto value = ParseNumber((*node)[i], path);
    if (!value) continue;
    if (const std::string problem = rule.Check(*value); !problem.empty()) {
      file_->sink().Add(core::LocationOf(file_->file(), (*node)[i]), path, problem);
      continue;
    }
    out[i] = *value;
  }
  return out;
}

std::vector<std::string> MapReader::Strings(std::string_view key, bool required) {
  const auto node = Value(key, required);
  if (!node) return {};
  if (!node->IsSequence()) {
    Error(key, "expected a list of strings, got " + Describe(*node));
    return {};
  }
  std::vector<std::string> out;
  for (std::size_t i = 0; i < node->size(); ++i) {
    const YAML::Node item = (*node)[i];
    const std::string path = PathOf(key) + "[" + std::to_string(i) + "]";
    if (!item.IsScalar()) {
      file_->sink().Add(core::LocationOf(file_->file(), item), path,
                        "expected a string, got " + Describe(item));
      continue;
    }
    if (index_ != nullptr) (*index_)[path] = core::LocationOf(file_->file(), item);
    out.push_back(item.Scalar());
  }
  return out;
}

std::optional<YAML::Node> MapReader::Raw(std::string_view key, bool required) {
  return Value(key, required);
}

MapReader MapReader::Map(std::string_view key) {
  const auto node = Value(key, /*required=*/true);
  return MapReader(*file_, node ? *node : YAML::Node(), PathOf(key), index_);
}

std::optional<MapReader> MapReader::OptionalMap(std::string_view key) {
  known_keys_.emplace(key);
  if (!Has(key)) return std::nullopt;
  return Map(key);
}

std::vector<MapReader> MapReader::MapList(std::string_view key, bool required) {
  const auto node = Value(key, required);
  if (!node) return {};
  if (!node->IsSequence() || node->size() == 0) {
    Error(key, "expected a non-empty list of mappings, got " + Describe(*node));
    return {};
  }
  std::vector<MapReader> out;
  for (std::size_t i = 0; i < node->size(); ++i) {
    const std::string path = PathOf(key) + "[" + std::to_string(i) + "]";
    if (index_ != nullptr) (*index_)[path] = core::LocationOf(file_->file(), (*node)[i]);
    out.emplace_back(*file_, (*node)[i], path, index_);
  }
  return out;
}

void MapReader::Finish() {
  if (!valid_) return;
  const std::vector<std::string> known(known_keys_.begin(), known_keys_.end());
  std::set<std::string> explained;  // missing keys that an unknown key probably misspells
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    // YAML allows any node as a key (`? [a, b]`, `{[1, 2]: x}`, an empty `?`); converting one
    // that is not a scalar to a string throws YAML::BadConversion (found by tests/fuzz).
    if (!it->first.IsScalar()) {
      file_->sink().Add(core::LocationOf(file_->file(), it->first), key_path_,
                        "a key must be a name, got " + Describe(it->first));
      continue;
    }
    const std::string key = it->first.as<std::string>();
    if (known_keys_.count(key) > 0) continue;
    std::string message = "unknown key '" + key + "'";
    if (const std::string near = NearestWord(key, known); !near.empty()) {
      message += " (did you mean '" + near + "'?)";
      explained.insert(near);
    }
    file_->sink().Add(core::LocationOf(file_->file(), it->first), PathOf(key), message);
  }
  for (const auto& key : missing_keys_) {
    if (explained.count(key) > 0) continue;
    file_->sink().Add(location(), key_path_.empty() ? key : key_path_,
                      "missing required key '" + key + "'");
  }
  missing_keys_.clear();
}

}  // namespace autoshovel::core
