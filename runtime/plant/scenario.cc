// Reading and validating yard scenarios (models/scenarios/README.md is the schema).
#include "runtime/plant/scenario.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>

#include "runtime/core/input_file.h"
#include "runtime/core/sha256.h"
#include "runtime/core/strings.h"
#include "runtime/core/yaml_reader.h"
#include "runtime/plant/fault_spec.h"
#include "runtime/plant/scenario_builder.h"

namespace autoshovel::plant {
namespace {

namespace fs = std::filesystem;
using core::MapReader;
using core::NumberRule;
using core::SemanticClass;

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kMaxLowPileHeight = 1.0;        // [m]
constexpr double kIrregularSlopeFraction = 0.8;  // of tan(repose), when the slope is derived
constexpr double kIrregularRoughness = 0.12;     // default bump amplitude, fraction of height
constexpr double kWallReflectivity = 0.45;       // concrete
constexpr double kMaxStartDepth = 0.05;          // [m] of material allowed under the start pose
constexpr long long kMaxCells = 25'000'000;      // about 0.5 GB of grids
const NumberRule kPileHeight =
    NumberRule{0, NumberRule::Bound::kExclusive, 30, NumberRule::Bound::kInclusive, "m"};

const std::vector<std::string> kShapes = {"cone",  "irregular", "low",
                                          "ridge", "windrow",   "against_wall"};
// Every key any shape reads: a pile whose shape is invalid still knows them (no second error).
const std::vector<std::string> kShapeKeys = {"height",      "base_radius", "length",
                                             "width",       "roughness",   "seed",
                                             "wall_length", "wall_height", "wall_thickness"};

std::string Num(double value) { return core::FormatNumber(std::round(value * 1000) / 1000); }

double WrapAngle(double angle) {
  angle = std::remainder(angle, 2 * std::numbers::pi);
  return angle <= -std::numbers::pi ? angle + 2 * std::numbers::pi : angle;
}

std::string Suggest(const std::string& word, const std::vector<std::string>& options) {
  const std::string near = core::NearestWord(word, options);
  return near.empty() ? "" : " (did you mean '" + near + "'?)";
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string list;
  for (const auto& name : names) list += (list.empty() ? "" : ", ") + name;
  return list.empty() ? "none" : list;
}

bool IsIdentifier(const std::string& name) {
  bool ok = !name.empty() && name.size() <= 64 && name[0] >= 'a' && name[0] <= 'z';
  for (const char ch : name) {
    ok = ok && ((ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_');
  }
  return ok;
}

template <std::size_t N>
std::array<double, N> OptionalNumbers(MapReader& map, std::string_view key, const NumberRule& rule,
                                      std::array<double, N> fallback) {
  if (!map.Has(key)) {
    map.Raw(key, /*required=*/false);  // known, absent
    return fallback;
  }
  return map.Numbers<N>(key, rule);
}

std::optional<double> OptionalNumber(MapReader& map, std::string_view key, const NumberRule& rule) {
  if (!map.Has(key)) {
    map.Raw(key, /*required=*/false);
    return std::nullopt;
  }
  return map.Number(key, rule);
}

// A planar frame: where local coordinates of a bin (or the yard) sit in the world.
struct Frame2 {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  double yaw = 0;

  Eigen::Vector2d ToWorld(const Eigen::Vector2d& local) const {
    const double c = std::cos(yaw), s = std::sin(yaw);
    return origin + Eigen::Vector2d(c * local.x() - s * local.y(), s * local.x() + c * local.y());
  }
};

struct Yard {
  bool ok = false;
  Eigen::Vector2d min = Eigen::Vector2d::Zero(), max = Eigen::Vector2d::Zero();
  GridGeometry geometry;
  double floor_height = 0;

  bool Contains(const Eigen::Vector2d& p) const {
    return p.x() >= min.x() && p.y() >= min.y() && p.x() <= max.x() && p.y() <= max.y();
  }
  std::string Text() const {
    return "[" + Num(min.x()) + ", " + Num(max.x()) + "] x [" + Num(min.y()) + ", " + Num(max.y()) +
           "] m";
  }
};

// Corners of a rectangle of half extents `half` centred at `center`, turned by `yaw`.
std::array<Eigen::Vector2d, 4> Corners(const Eigen::Vector2d& center, const Eigen::Vector2d& half,
                                       double yaw) {
  const Frame2 frame{center, yaw};
  return {frame.ToWorld({-half.x(), -half.y()}), frame.ToWorld({half.x(), -half.y()}),
          frame.ToWorld({half.x(), half.y()}), frame.ToWorld({-half.x(), half.y()})};
}

class ScenarioReader {
 public:
  ScenarioReader(const std::string& path, core::DiagnosticSink& sink)
      : path_(path), sink_(sink), file_(path, sink) {}

  Scenario Read() {
    sink_.ThrowIfAny();  // syntax error or no file: nothing more to say
    Scenario s;
    s.source_file = path_;
    s.sha256 = core::Sha256Hex(core::ReadFileBytes(path_));
    MapReader root = MapReader::Root(file_, &index_);
    s.name = root.String("name");
    if (!s.name.empty() && !IsIdentifier(s.name)) {
      const std::string rule = "a-z, 0-9, _; starting with a letter";
      root.Error("name", "must be a lower-case identifier (" + rule + "), got '" + s.name + "'");
    }
    s.description = root.String("description");
    s.seed =
        static_cast<std::uint32_t>(root.Integer("seed", 0, std::numeric_limits<int>::max(), 0));
    s.lighting = ReadLighting(root);
    ReadYard(root.Map("yard"));
    ReadMaterials(root, s);
    MapReader machine = root.Map("machine");
    ReadMachine(machine, s);

    const Frame2 yard_frame;
    for (auto& map : root.MapList("piles", /*required=*/false)) {
      ReadPile(map, yard_frame, nullptr, -1, s);
    }
    std::vector<MapReader> rows = root.MapList("bins", /*required=*/false);
    for (std::size_t r = 0; r < rows.size(); ++r) ReadBinRow(rows[r], static_cast<int>(r), s);
    for (auto& map : root.MapList("obstacles", /*required=*/false)) {
      ReadObstacle(map, yard_frame, s);
    }
    s.faults = ReadFaults(root);
    root.Finish();
    CheckStartPose(s);
    sink_.ThrowIfAny();
    Build(s);
    sink_.ThrowIfAny();
    return s;
  }

 private:
  Lighting ReadLighting(MapReader& root) {
    if (!root.Has("lighting")) {
      root.Raw("lighting", /*required=*/false);
      return Lighting::kNormal;
    }
    const std::string value = root.Enum("lighting", {"normal", "bright", "dim"});
    return value == "bright" ? Lighting::kBright
           : value == "dim"  ? Lighting::kDim
                             : Lighting::kNormal;
  }

  void ReadYard(MapReader yard) {
    const auto size = yard.Numbers<2>("size", NumberRule::Positive("m"));
    const auto origin = OptionalNumbers<2>(yard, "origin", NumberRule::Any("m"), {0.0, 0.0});
    const double resolution = yard.Number("resolution", NumberRule::Closed(0.01, 1, "m"), 0.05);
    yard_.floor_height = yard.Number("floor_height", NumberRule::Any("m"), 0.0);
    yard.Finish();
    if (!(std::isfinite(size[0]) && std::isfinite(size[1]) && std::isfinite(origin[0]) &&
          std::isfinite(origin[1]) && std::isfinite(resolution) &&
          std::isfinite(yard_.floor_height))) {
      return;
    }
    long long cells[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
      const double n = size[k] / resolution;
      if (n > static_cast<double>(kMaxCells)) {
        sink_.Add(Where("yard.size"), "yard.size",
                  "too many cells: " + Num(n) + " along " + (k == 0 ? "x" : "y") + " at " +
                      Num(resolution) + " m (at most " + std::to_string(kMaxCells) + " in all)");
        return;
      }
      cells[k] = std::llround(n);
      if (cells[k] < 1 || std::abs(n - static_cast<double>(cells[k])) > 1e-6 * std::max(1.0, n)) {
        sink_.Add(Where("yard.size"), "yard.size",
                  "must be a whole number of cells of " + Num(resolution) + " m, got " +
                      Num(size[k]) + " m along " + (k == 0 ? "x" : "y"));
        return;
      }
    }
    if (cells[0] * cells[1] > kMaxCells) {
      sink_.Add(Where("yard.size"), "yard.size",
                "too many cells: " + std::to_string(cells[0]) + " x " + std::to_string(cells[1]) +
                    " at " + Num(resolution) + " m (at most " + std::to_string(kMaxCells) + ")");
      return;
    }
    yard_.geometry.resolution = resolution;
    yard_.geometry.origin = {origin[0], origin[1]};
    yard_.geometry.nx = static_cast<int>(cells[0]);
    yard_.geometry.ny = static_cast<int>(cells[1]);
    yard_.min = yard_.geometry.origin;
    yard_.max = yard_.min + Eigen::Vector2d(size[0], size[1]);
    yard_.ok = true;
  }

  void ReadMaterials(MapReader& root, Scenario& s) {
    const fs::path dir = fs::path(path_).parent_path();
    const auto given = root.OptionalString("materials");
    fs::path materials = given ? fs::path(*given) : fs::path("..") / "materials";
    if (materials.is_relative()) materials = dir / materials;
    s.materials_dir = materials.lexically_normal().string();
    try {
      materials_ = model::LoadMaterials(s.materials_dir);
    } catch (const core::InputError& e) {
      for (const auto& d : e.diagnostics()) sink_.Add(d.where, d.key_path, d.message);
      return;
    }
    if (materials_.empty()) {
      std::error_code error;
      root.Error("materials",
                 (fs::is_directory(s.materials_dir, error) ? "no materials (*.yaml) in '"
                                                           : "no such folder: '") +
                     s.materials_dir + "'");
    }
    for (const auto& material : materials_) material_names_.push_back(material.name);
    // Where the machine named by the scenario is looked for: beside the materials, unless the
    // scenario names the models folder (a site's own materials with the shipped machines).
    const auto machines = root.OptionalString("machines");
    machines_dir_ =
        machines ? (fs::path(*machines).is_relative() ? dir / *machines : fs::path(*machines))
                       .lexically_normal()
                 : (materials / "..").lexically_normal();
  }

  void ReadMachine(MapReader& machine, Scenario& s) {
    s.machine = machine.String("name");
    MapReader start = machine.Map("start");
    s.start.x = start.Number("x", NumberRule::Any("m"));
    s.start.y = start.Number("y", NumberRule::Any("m"));
    s.start.heading = start.AngleDeg("heading_deg", NumberRule::Closed(-180, 180, "deg"));
    start.Finish();
    machine.Finish();
    if (s.machine.empty() || materials_.empty()) return;
    // Machines live next to the materials: <models>/materials, <models>/loaders/<name>.yaml,
    // <models>/excavators/<name>.yaml (models/README.md). Only those two folders are searched.
    fs::path models = machines_dir_;
    if (models.filename().empty()) models = models.parent_path();  // "models/" -> "models"
    std::vector<std::string> names;
    for (const char* kind : {"loaders", "excavators"}) {
      std::error_code error;
      for (const auto& entry : fs::directory_iterator(models / kind, error)) {
        if (entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
      }
    }
    std::sort(names.begin(), names.end());
    if (std::find(names.begin(), names.end(), s.machine) == names.end()) {
      machine.Error("name", "unknown machine '" + s.machine + "' (known under " + models.string() +
                                ": " + JoinNames(names) + ")" + Suggest(s.machine, names));
    }
  }

  int MaterialIndex(MapReader& map, const std::string& name) {
    if (name.empty()) return -1;
    for (std::size_t i = 0; i < materials_.size(); ++i) {
      if (materials_[i].name == name) return static_cast<int>(i);
    }
    if (!materials_.empty()) {
      map.Error("material", "unknown material '" + name + "' (known: " +
                                JoinNames(material_names_) + ")" + Suggest(name, material_names_));
    }
    return -1;
  }

  // Reads a pile; `bin` and `frame` place it (the bin frame, or the world for the open yard).
  void ReadPile(MapReader& map, const Frame2& frame, const Bin* bin, int bin_index, Scenario& s) {
    Pile p;
    p.name = map.String("name");
    const std::string shape = map.Enum("shape", kShapes);
    p.material = map.String("material");
    p.material_index = MaterialIndex(map, p.material);
    p.bin = bin_index;
    const auto center = map.Numbers<2>("center", NumberRule::Any("m"));
    const Eigen::Vector2d local(center[0], center[1]);
    p.center = frame.ToWorld(local);
    p.yaw = WrapAngle(frame.yaw + map.AngleDeg("yaw_deg", NumberRule::Closed(-180, 180, "deg"), 0));
    const double tan_repose =
        p.material_index >= 0 ? std::tan(materials_[p.material_index].angle_of_repose) : 0.0;
    const bool slope_known = tan_repose > 0;
    const auto repose_text = [&] {
      return "the angle of repose of " + p.material + " (" +
             Num(materials_[p.material_index].angle_of_repose / kDeg) + " deg)";
    };
    const auto steepness = [&](double slope) { return Num(std::atan(slope) / kDeg) + " deg"; };

    if (shape == "cone" || shape == "irregular") {
      p.shape = shape == "cone" ? PileShape::kCone : PileShape::kIrregular;
      const auto height = OptionalNumber(map, "height", kPileHeight);
      const auto radius = OptionalNumber(map, "base_radius", NumberRule::Positive("m"));
      const double fraction = shape == "cone" ? 1.0 : kIrregularSlopeFraction;
      if (!height && !radius) {
        map.Error("height", "a " + shape + " pile needs height, base_radius or both");
      } else if (height && radius) {
        p.height = *height;
        p.base_radius = *radius;
        p.slope = *height / *radius;
        if (slope_known && p.slope > tan_repose * (1 + 1e-9)) {
          map.Error("height", "height " + Num(*height) + " m on base_radius " + Num(*radius) +
                                  " m is a " + steepness(p.slope) + " slope, steeper than " +
                                  repose_text());
        }
      } else if (slope_known) {
        p.slope = fraction * tan_repose;
        p.height = height ? *height : *radius * p.slope;
        p.base_radius = radius ? *radius : *height / p.slope;
      }
      if (shape == "irregular") {
        const auto roughness = OptionalNumber(map, "roughness", NumberRule::NonNegative("m"));
        p.roughness = roughness ? *roughness : kIrregularRoughness * p.height;
        if (roughness && p.height > 0 && *roughness > 0.5 * p.height) {
          map.Error("roughness", "must be <= half the height (" + Num(0.5 * p.height) +
                                     " m), got " + Num(*roughness) + " m");
        }
        const int seed = map.Integer("seed", 0, std::numeric_limits<int>::max(), -1);
        p.seed = seed >= 0 ? static_cast<std::uint64_t>(seed) : DerivedSeed(s.seed, p.name);
      }
    } else if (shape == "low") {
      p.shape = PileShape::kLow;
      p.height =
          map.Number("height", NumberRule{0, NumberRule::Bound::kExclusive, kMaxLowPileHeight,
                                          NumberRule::Bound::kInclusive, "m"});
      p.length = map.Number("length", NumberRule::Positive("m"));
      p.width = map.Number("width", NumberRule::Positive("m"));
      p.slope = tan_repose;
      if (slope_known && p.height > 0) {
        const double flanks = 2 * p.height / tan_repose;
        for (const char* key : {"width", "length"}) {
          const double value = std::string(key) == "width" ? p.width : p.length;
          if (value < flanks) {
            map.Error(key, "must be >= " + Num(flanks) + " m: the two flanks of a " +
                               Num(p.height) + " m high pile at " + repose_text() +
                               " take that much, got " + Num(value) + " m");
          }
        }
      }
    } else if (shape == "ridge" || shape == "windrow") {
      p.shape = PileShape::kRidge;
      p.height = map.Number("height", kPileHeight);
      p.length = map.Number("length", NumberRule::Positive("m"));
      const auto width = OptionalNumber(map, "width", NumberRule::Positive("m"));
      if (slope_known && p.height > 0) {
        p.width = width ? *width : 2 * p.height / tan_repose;
        p.slope = 2 * p.height / p.width;
        if (width && p.slope > tan_repose * (1 + 1e-9)) {
          map.Error("width", "height " + Num(p.height) + " m on width " + Num(p.width) +
                                 " m is a " + steepness(p.slope) + " slope, steeper than " +
                                 repose_text());
        } else if (p.length < p.width) {
          map.Error("length", "a ridge is longer than wide: must be >= its base width " +
                                  Num(p.width) + " m, got " + Num(p.length) + " m");
        }
      }
    } else if (shape == "against_wall") {
      p.shape = PileShape::kAgainstWall;
      p.height = map.Number("height", kPileHeight);
      const auto radius = OptionalNumber(map, "base_radius", NumberRule::Positive("m"));
      p.length = map.Number("length", NumberRule::NonNegative("m"), 0.0);
      const auto wall_length = OptionalNumber(map, "wall_length", NumberRule::Positive("m"));
      const double wall_height = map.Number("wall_height", NumberRule::Positive("m"), 3.0);
      const double thickness = map.Number("wall_thickness", NumberRule::Positive("m"), 0.5);
      if (slope_known && p.height > 0) {
        p.base_radius = radius ? *radius : p.height / tan_repose;
        p.slope = p.height / p.base_radius;
        if (radius && p.slope > tan_repose * (1 + 1e-9)) {
          map.Error("height", "height " + Num(p.height) + " m on base_radius " +
                                  Num(p.base_radius) + " m is a " + steepness(p.slope) +
                                  " slope, steeper than " + repose_text());
        }
      }
      if (p.height > wall_height) {
        map.Error("height", "a pile against a wall must not be higher than the wall (" +
                                Num(wall_height) + " m), got " + Num(p.height) + " m");
      }
      CheckWallThickness(map, "wall_thickness", thickness);
      if (p.slope > 0 && std::isfinite(p.length) && std::isfinite(wall_height) &&
          std::isfinite(thickness)) {
        // The wall's face is the pile's local y axis; the pile lies on its +x side.
        const double length = wall_length ? *wall_length : p.length + 2 * p.base_radius + 1.0;
        OrientedBox wall;
        wall.name = p.name + "/wall";
        wall.yaw = p.yaw;
        const Eigen::Vector2d c = Frame2{p.center, p.yaw}.ToWorld({-0.5 * thickness, 0});
        wall.center = {c.x(), c.y(), yard_.floor_height + 0.5 * wall_height};
        wall.half_extents = {0.5 * thickness, 0.5 * length, 0.5 * wall_height};
        wall.semantic_class = SemanticClass::kWall;
        wall.reflectivity = kWallReflectivity;
        AddBox(wall, s);
        if (yard_.ok) {
          for (const auto& corner : Corners(c, {0.5 * thickness, 0.5 * length}, p.yaw)) {
            if (!yard_.Contains(corner)) {
              map.Error("center", "its wall (" + Num(length) + " m long, " + Num(thickness) +
                                      " m thick, behind the centre) reaches outside the yard " +
                                      yard_.Text());
              break;
            }
          }
        }
      }
    } else {
      for (const auto& key : kShapeKeys) map.Raw(key, /*required=*/false);
    }
    map.Finish();

    if (!p.name.empty()) {
      if (!pile_names_.insert(p.name).second) {
        map.Error("name", "duplicate pile name '" + p.name + "'");
      }
    }
    if (std::isfinite(center[0]) && std::isfinite(center[1])) {
      if (bin != nullptr) {
        if (!(std::abs(local.x()) <= 0.5 * bin->width && local.y() >= 0 &&
              local.y() <= bin->depth)) {
          map.Error("center", "must lie inside bin '" + bin->name + "': |u| <= " +
                                  Num(0.5 * bin->width) + " m and 0 <= v <= " + Num(bin->depth) +
                                  " m, got [" + Num(local.x()) + ", " + Num(local.y()) + "]");
        }
      } else if (yard_.ok && !yard_.Contains(p.center)) {
        map.Error("center", "must lie inside the yard " + yard_.Text() + ", got [" +
                                Num(p.center.x()) + ", " + Num(p.center.y()) + "]");
      }
    }
    pile_paths_.push_back(map.key_path());
    s.piles.push_back(p);
  }

  static std::uint64_t DerivedSeed(std::uint32_t scenario_seed, const std::string& name) {
    std::uint64_t hash = 1469598103934665603ULL;  // FNV-1a of the name
    for (const char ch : name) {
      hash = (hash ^ static_cast<unsigned char>(ch)) * 1099511628211ULL;
    }
    return hash ^ (static_cast<std::uint64_t>(scenario_seed) * 0x9e3779b97f4a7c15ULL);
  }

  // A wall must cover at least two cells across to hold material on one side only.
  void CheckWallThickness(MapReader& map, std::string_view key, double thickness) {
    if (yard_.ok && thickness < 2 * yard_.geometry.resolution) {
      map.Error(key, "must be >= 2 cells (" + Num(2 * yard_.geometry.resolution) +
                         " m) to hold material, got " + Num(thickness) + " m");
    }
  }

  // A row of bins: `n` bins side by side with n + 1 side walls and one back wall. Row frame:
  // origin at the front end of the first wall's outer face, x along the row, y into the bins.
  void ReadBinRow(MapReader& row, int row_index, Scenario& s) {
    const std::string row_name =
        row.OptionalString("name").value_or("row_" + std::to_string(row_index + 1));
    const auto origin = row.Numbers<2>("origin", NumberRule::Any("m"));
    const double yaw = row.AngleDeg("yaw_deg", NumberRule::Closed(-180, 180, "deg"), 0);
    const double w = row.Number("width", NumberRule::Positive("m"));
    const double depth = row.Number("depth", NumberRule::Positive("m"));
    const double height = row.Number("wall_height", NumberRule::Positive("m"));
    const double t = row.Number("wall_thickness", NumberRule::Positive("m"));
    CheckWallThickness(row, "wall_thickness", t);
    std::vector<MapReader> contents = row.MapList("contents", /*required=*/true);
    const bool geometry_ok = std::isfinite(origin[0]) && std::isfinite(origin[1]) &&
                             std::isfinite(w) && std::isfinite(depth) && std::isfinite(height) &&
                             std::isfinite(t);
    const Frame2 frame{{origin[0], origin[1]}, WrapAngle(yaw)};
    const int n = static_cast<int>(contents.size());
    if (geometry_ok && n > 0) {
      const auto wall = [&](const std::string& name, Eigen::Vector2d center, Eigen::Vector2d half) {
        OrientedBox box;
        box.name = row_name + "/" + name;
        const Eigen::Vector2d c = frame.ToWorld(center);
        box.center = {c.x(), c.y(), yard_.floor_height + 0.5 * height};
        box.half_extents = {half.x(), half.y(), 0.5 * height};
        box.yaw = frame.yaw;
        box.semantic_class = SemanticClass::kWall;
        box.reflectivity = kWallReflectivity;
        AddBox(box, s);
      };
      for (int i = 0; i <= n; ++i) {
        wall("side_wall_" + std::to_string(i), {i * (w + t) + 0.5 * t, 0.5 * depth},
             {0.5 * t, 0.5 * depth});
      }
      const double total = n * (w + t) + t;
      wall("back_wall", {0.5 * total, depth + 0.5 * t}, {0.5 * total, 0.5 * t});
      if (yard_.ok) {
        for (const auto& corner : Corners(frame.ToWorld({0.5 * total, 0.5 * (depth + t)}),
                                          {0.5 * total, 0.5 * (depth + t)}, frame.yaw)) {
          if (!yard_.Contains(corner)) {
            row.Error("origin", "the row of " + std::to_string(n) + " bins (" + Num(total) +
                                    " m x " + Num(depth + t) + " m) reaches outside the yard " +
                                    yard_.Text());
            break;
          }
        }
      }
    }
    for (int j = 0; j < n; ++j) {
      MapReader& content = contents[j];
      Bin bin;
      bin.name =
          content.OptionalString("name").value_or("bin_" + std::to_string(s.bins.size() + 1));
      if (!bin_names_.insert(bin.name).second) {
        content.Error("name", "duplicate bin name '" + bin.name + "'");
      }
      bin.yaw = frame.yaw;
      bin.width = w;
      bin.depth = depth;
      bin.front_center = frame.ToWorld({t + j * (w + t) + 0.5 * w, 0});
      const int bin_index = static_cast<int>(s.bins.size());
      s.bins.push_back(bin);
      const Frame2 bin_frame{bin.front_center, frame.yaw};
      std::vector<MapReader> piles = content.MapList("piles", /*required=*/false);
      std::vector<MapReader> obstacles = content.MapList("obstacles", /*required=*/false);
      for (auto& pile : piles) {
        if (geometry_ok) ReadPile(pile, bin_frame, &s.bins.back(), bin_index, s);
      }
      for (auto& obstacle : obstacles) {
        if (geometry_ok) ReadObstacle(obstacle, bin_frame, s);
      }
      content.Finish();
    }
    row.Finish();
  }

  void ReadObstacle(MapReader& map, const Frame2& frame, Scenario& s) {
    const std::string name = map.String("name");
    const std::string kind = map.Enum("kind", {"parked_loader", "fence", "debris", "person"});
    const auto center = map.Numbers<2>("center", NumberRule::Any("m"));
    const double yaw =
        WrapAngle(frame.yaw + map.AngleDeg("yaw_deg", NumberRule::Closed(-180, 180, "deg"), 0));
    std::array<double, 3> size{};
    double reflectivity = 0.3;
    SemanticClass semantic = SemanticClass::kOther;
    if (kind == "parked_loader") {
      size = OptionalNumbers<3>(map, "size", NumberRule::Positive("m"), {8.5, 3.0, 3.4});
      semantic = SemanticClass::kOtherLoader, reflectivity = 0.5;  // painted steel
    } else if (kind == "person") {
      size = OptionalNumbers<3>(map, "size", NumberRule::Positive("m"), {0.5, 0.5, 1.8});
      semantic = SemanticClass::kPerson, reflectivity = 0.3;
    } else if (kind == "fence" || kind == "debris") {
      size = map.Numbers<3>("size", NumberRule::Positive("m"));
      semantic = kind == "fence" ? SemanticClass::kWall : SemanticClass::kOther;
      reflectivity = kind == "fence" ? 0.4 : 0.3;
    } else {
      map.Raw("size", /*required=*/false);
    }
    reflectivity = map.Number("reflectivity", NumberRule::Closed(0, 1, ""), reflectivity);
    map.Finish();
    if (!name.empty() && !obstacle_names_.insert(name).second) {
      map.Error("name", "duplicate obstacle name '" + name + "'");
    }
    const Eigen::Vector2d xy = frame.ToWorld({center[0], center[1]});
    if (kind.empty() || !xy.allFinite() || !std::isfinite(size[0]) || !std::isfinite(size[1]) ||
        !std::isfinite(size[2]) || !std::isfinite(reflectivity)) {
      return;
    }
    if (yard_.ok) {
      for (const auto& corner : Corners(xy, {0.5 * size[0], 0.5 * size[1]}, yaw)) {
        if (!yard_.Contains(corner)) {
          map.Error("center", "the " + Num(size[0]) + " m x " + Num(size[1]) + " m footprint at [" +
                                  Num(xy.x()) + ", " + Num(xy.y()) + "] reaches outside the yard " +
                                  yard_.Text());
          break;
        }
      }
    }
    const auto box = [&](const std::string& box_name, double x, double length, double width,
                         double height) {
      OrientedBox b;
      b.name = box_name;
      const Eigen::Vector2d c = Frame2{xy, yaw}.ToWorld({x, 0});
      b.center = {c.x(), c.y(), yard_.floor_height + 0.5 * height};
      b.half_extents = {0.5 * length, 0.5 * width, 0.5 * height};
      b.yaw = yaw;
      b.semantic_class = semantic;
      b.reflectivity = reflectivity;
      AddBox(b, s);
    };
    if (kind == "parked_loader") {
      // Two boxes in one bounding box: the lowered bucket in front (full width), the body with
      // its cab behind (narrower, full height). Local x is the loader's forward direction.
      const double l = size[0];
      box(name + "/body", -0.08 * l, 0.84 * l, 0.87 * size[1], size[2]);
      box(name + "/bucket", 0.42 * l, 0.16 * l, size[1], 0.35 * size[2]);
    } else {
      box(name, 0, size[0], size[1], size[2]);
    }
  }

  static void AddBox(const OrientedBox& box, Scenario& s) { s.world.obstacles.push_back(box); }

  void CheckStartPose(const Scenario& s) {
    if (!yard_.ok || !std::isfinite(s.start.x) || !std::isfinite(s.start.y)) return;
    const Eigen::Vector2d xy(s.start.x, s.start.y);
    if (!yard_.Contains(xy)) {
      sink_.Add(Where("machine.start"), "machine.start",
                "must lie inside the yard " + yard_.Text() + ", got [" + Num(xy.x()) + ", " +
                    Num(xy.y()) + "]");
      return;
    }
    for (const OrientedBox& box : s.world.obstacles) {
      if (FootprintContains(box, xy)) {
        sink_.Add(Where("machine.start"), "machine.start",
                  "the start pose is inside obstacle '" + box.name + "'");
        return;
      }
    }
  }

  void Build(Scenario& s) {
    s.world.materials = materials_;
    s.world.terrain = Terrain(yard_.geometry, yard_.floor_height);
    const TerrainBuildReport report = BuildTerrain(s.world, s.piles, s.bins);
    for (const int i : report.outside_yard) {
      const std::string path = pile_paths_[i] + ".center";
      sink_.Add(Where(path), path,
                "pile '" + s.piles[i].name + "' reaches outside the yard " + yard_.Text() +
                    "; move it inwards or make it smaller");
    }
    for (const int i : report.hidden) {
      const std::string path = pile_paths_[i] + ".center";
      sink_.Add(Where(path), path,
                "pile '" + s.piles[i].name +
                    "' has no material left: it lies under other piles or walls");
    }
    int ix = 0, iy = 0;
    if (s.world.terrain.CellOf(s.start.x, s.start.y, ix, iy) &&
        s.world.terrain.depth(ix, iy) > kMaxStartDepth) {
      sink_.Add(
          Where("machine.start"), "machine.start",
          "the start pose stands on " + Num(s.world.terrain.depth(ix, iy)) + " m of pile material");
    }
  }

  // Location of a recorded key path, or of its nearest recorded parent.
  core::SourceLocation Where(std::string path) const {
    while (!path.empty()) {
      if (const auto it = index_.find(path); it != index_.end()) return it->second;
      const auto cut = path.find_last_of(".[");
      if (cut == std::string::npos) break;
      path.resize(cut);
    }
    return {path_, 1, 1};
  }

  std::string path_;
  core::DiagnosticSink& sink_;
  core::YamlFile file_;
  core::LocationIndex index_;
  Yard yard_;
  std::vector<model::Material> materials_;
  std::vector<std::string> material_names_;
  fs::path machines_dir_;  ///< holds loaders/ and excavators/ (see ReadMaterials)
  std::vector<std::string> pile_paths_;
  std::set<std::string> pile_names_, bin_names_, obstacle_names_;
};

}  // namespace

const Pile* Scenario::FindPile(const std::string& pile_name) const {
  for (const auto& pile : piles) {
    if (pile.name == pile_name) return &pile;
  }
  return nullptr;
}

Scenario LoadScenario(const std::string& path) {
  core::DiagnosticSink sink;
  return ScenarioReader(path, sink).Read();
}

std::vector<std::string> FindScenarios(const std::string& models_dir) {
  std::vector<std::string> files;
  const fs::path dir = fs::path(models_dir) / "scenarios";
  std::error_code error;
  if (!fs::is_directory(dir, error)) return files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file() && entry.path().extension() == ".yaml") {
      files.push_back(entry.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string ResolveScenario(const std::string& name_or_path, const std::string& models_dir) {
  std::error_code error;
  if (fs::is_regular_file(name_or_path, error)) return name_or_path;
  std::vector<std::string> names;
  for (const auto& file : FindScenarios(models_dir)) {
    const std::string stem = fs::path(file).stem().string();
    if (stem == name_or_path) return file;
    names.push_back(stem);
  }
  // A path that exists but is no file (a folder, a named pipe) is said so, not "no such file".
  // It is asked after the names: a folder called `truck_loading` in the working directory (a
  // run folder, a build tree's test folder) must not hide the scenario of that name.
  if (fs::exists(name_or_path, error)) {
    throw std::runtime_error(name_or_path + ": " + core::NotARegularFile(name_or_path));
  }
  std::string message = "unknown scenario '" + name_or_path + "' (no such file, and no " +
                        name_or_path + ".yaml under " + models_dir +
                        "/scenarios; known: " + JoinNames(names) + ")";
  if (const std::string near = core::NearestWord(name_or_path, names); !near.empty()) {
    message += "; did you mean '" + near + "'?";
  }
  throw std::runtime_error(message);
}

const char* ToString(PileShape shape) {
  switch (shape) {
    case PileShape::kIrregular:
      return "irregular";
    case PileShape::kLow:
      return "low";
    case PileShape::kRidge:
      return "ridge";
    case PileShape::kAgainstWall:
      return "against_wall";
    case PileShape::kCone:
      break;
  }
  return "cone";
}

bool FootprintContains(const OrientedBox& box, const Eigen::Vector2d& xy) {
  const double dx = xy.x() - box.center.x(), dy = xy.y() - box.center.y();
  const double c = std::cos(box.yaw), s = std::sin(box.yaw);
  return std::abs(c * dx + s * dy) <= box.half_extents.x() &&
         std::abs(-s * dx + c * dy) <= box.half_extents.y();
}

}  // namespace autoshovel::plant
