#include "runtime/recording/recording_tables.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include "runtime/core/diagnostics.h"
#include "runtime/core/yaml_reader.h"
#include "runtime/recording/csv_rows.h"
#include "runtime/recording/folder_checks.h"

namespace autoshovel::recording {

namespace {

// A file named in frames.csv: relative, inside the folder, plain characters.
void CheckRelativePath(const std::string& source, int line, const Field& f, const char* name) {
  const std::string& p = f.text;
  auto bad = [&](const std::string& why) {
    Refuse(source, line, f.column, std::string(name) + " '" + p.substr(0, 80) + "': " + why);
  };
  if (p.empty()) bad("empty");
  if (p.size() > 255) bad("longer than 255 characters");
  if (p.front() == '/') bad("must be relative to the recording folder");
  for (const char c : p) {
    const bool ok =
        std::isalnum(static_cast<unsigned char>(c)) || c == '/' || c == '_' || c == '-' || c == '.';
    if (!ok) bad("only letters, digits, '/', '_', '-' and '.' are allowed");
  }
  std::istringstream parts(p);
  std::string part;
  while (std::getline(parts, part, '/')) {
    // "." and ".." leave the folder or go nowhere; "..." is a name, but no recorder writes one
    // and a reader of the table would take it for "..".
    if (part.empty() || part.find_first_not_of('.') == std::string::npos) {
      bad("a part made only of dots ('.', '..') or an empty one ('//')");
    }
  }
}

// Numbers of a YAML sequence under `key` (exactly `size` of them unless size is 0).
std::vector<double> NumberSequence(core::MapReader& reader, const YAML::Node& node,
                                   const std::string& key, std::size_t size) {
  std::vector<double> out;
  if (!node.IsSequence() || (size > 0 && node.size() != size)) {
    reader.Error(key, size > 0 ? "expected a list of " + std::to_string(size) + " numbers"
                               : "expected a list of numbers");
    return out;
  }
  for (const YAML::Node& item : node) {
    const std::string text = item.IsScalar() ? item.Scalar() : "";
    char* stop = nullptr;
    const double v = std::strtod(text.c_str(), &stop);
    if (text.empty() || stop != text.c_str() + text.size() || !std::isfinite(v)) {
      reader.Error(key, "expected finite numbers, got '" + text.substr(0, 40) + "'");
      return {};
    }
    out.push_back(v);
  }
  return out;
}

void ReadSelection(core::MapReader s, Manifest& m) {
  using core::NumberRule;
  planning::ShovelPointConfig& c = m.selection;
  m.chen2024 = s.Enum("method", {"ours", "chen2024"}) == "chen2024";
  m.min_planned_clearance = s.Number("min_planned_clearance", NumberRule::NonNegative("m"));
  const NumberRule weight = NumberRule::NonNegative("");
  c.k_t = s.Number("k_t", weight);
  c.k_s = s.Number("k_s", weight);
  c.k_c = s.Number("k_c", weight);
  c.k_e = s.Number("k_e", weight);
  c.k_a = s.Number("k_a", weight);
  c.torque_threshold = s.Number("torque_threshold", NumberRule::Any("m^4"));
  c.safety_distance = s.Number("safety_distance", NumberRule::NonNegative("m"));
  c.max_curvature = s.Number("max_curvature", NumberRule::Any("1/m"));
  c.candidate_spacing = s.Number("candidate_spacing", NumberRule::Positive("m"));
  if (const auto offsets = s.Raw("entry_angle_offsets", true)) {
    c.entry_angle_offsets = NumberSequence(s, *offsets, "entry_angle_offsets", 0);
    if (c.entry_angle_offsets.empty()) s.Error("entry_angle_offsets", "needs at least one angle");
  }
  c.normal_radius = s.Number("normal_radius", NumberRule::Positive("m"));
  c.penetration_length = s.Number("penetration_length", NumberRule::Positive("m"));
  c.scoop_advance = s.Number("scoop_advance", NumberRule::NonNegative("m"));
  c.crowd_stop_distance = s.Number("crowd_stop_distance", NumberRule::NonNegative("m"));
  c.concavity_tolerance = s.Number("concavity_tolerance", NumberRule::NonNegative(""));
  c.entry_window = s.Number("entry_window", NumberRule::Positive("m"));
  c.path_spacing = s.Number("path_spacing", NumberRule::Positive("m"));
  c.max_drive_over_height = s.Number("max_drive_over_height", NumberRule::NonNegative("m"));
  s.Finish();
}

CycleInfo ReadCycle(core::MapReader c) {
  using core::NumberRule;
  CycleInfo cycle;
  cycle.index = c.Integer("index", 0, 1'000'000);
  cycle.site = c.String("site");
  if (auto r = c.OptionalMap("rectangle")) {
    cycle.area.kind = WorkArea::Kind::kRectangle;
    const auto center = r->Numbers<2>("front_center", NumberRule::Any("m"));
    cycle.area.front_center = {center[0], center[1]};
    cycle.area.yaw = r->Number("yaw", NumberRule::Any("rad"));
    cycle.area.width = r->Number("width", NumberRule::Positive("m"));
    cycle.area.depth = r->Number("depth", NumberRule::Positive("m"));
    r->Finish();
  } else if (const auto discs = c.Raw("discs", false)) {
    cycle.area.kind = WorkArea::Kind::kDiscs;
    if (!discs->IsSequence() || discs->size() == 0) {
      c.Error("discs", "expected a list of [x, y, radius]");
    } else {
      for (const YAML::Node& d : *discs) {
        const std::vector<double> v = NumberSequence(c, d, "discs", 3);
        if (v.size() != 3) break;
        if (!(v[2] > 0)) {
          c.Error("discs", "a disc's radius must be > 0 m");
          break;
        }
        cycle.area.discs.emplace_back(v[0], v[1], v[2]);
      }
    }
  } else {
    c.Error("site", "a cycle needs its work area: 'rectangle' or 'discs'");
  }
  if (auto s = c.OptionalMap("scoop")) {
    ScoopInfo scoop;
    scoop.material = s->String("material");
    scoop.target_volume = s->Number("target_volume", NumberRule::Positive("m^3"));
    scoop.bucket_max = s->Number("bucket_max", NumberRule::Closed(-7, 7, "rad"));
    scoop.boom_lift = s->Number("boom_lift", NumberRule::Closed(-7, 7, "rad"));
    s->Finish();
    cycle.scoop = scoop;
  }
  c.Finish();
  return cycle;
}

}  // namespace

bool WorkArea::Contains(const Eigen::Vector2d& p) const {
  if (kind == Kind::kRectangle) {
    const Eigen::Vector2d u(std::cos(yaw), std::sin(yaw)), v(-u.y(), u.x());
    const Eigen::Vector2d d = p - front_center;
    return std::abs(d.dot(u)) <= width / 2 && d.dot(v) >= -0.5 && d.dot(v) <= depth;
  }
  for (const Eigen::Vector3d& disc : discs) {
    if ((p - disc.head<2>()).norm() <= disc.z()) return true;
  }
  return false;
}

std::vector<UpdateRow> ParseUpdatesCsv(const std::string& text, const std::string& source) {
  std::vector<UpdateRow> updates;
  for (const auto& [line, f] : CsvRows(text, source, kUpdatesHeader)) {
    UpdateRow u;
    u.line = line;
    u.update = Integer(source, line, f[0], "update", 0, 1'000'000'000);
    if (u.update != static_cast<long>(updates.size())) {
      Refuse(source, line, f[0].column,
             "update: expected " + std::to_string(updates.size()) +
                 " (updates are numbered 0, 1, 2, … in order), got " + f[0].text.substr(0, 20));
    }
    u.cycle = static_cast<int>(Integer(source, line, f[1], "cycle", 0, 1'000'000));
    u.stamp = Finite(source, line, f[2], "stamp");
    if (!updates.empty() && u.stamp < updates.back().stamp) {
      Refuse(source, line, f[2].column,
             "stamp: goes back in time (" + f[2].text.substr(0, 30) + " after " +
                 std::to_string(updates.back().stamp) + ")");
    }
    u.hinge_xy = {Finite(source, line, f[3], "hinge_x"), Finite(source, line, f[4], "hinge_y")};
    u.heading = Finite(source, line, f[5], "heading");
    u.articulation = Finite(source, line, f[6], "articulation");
    if (std::abs(u.articulation) > 1.2) {
      Refuse(source, line, f[6].column,
             "articulation: " + f[6].text.substr(0, 30) +
                 " rad is beyond any loader's hinge "
                 "(|γ| ≤ 1.2 rad; given in degrees?)");
    }
    u.tip_reach = Finite(source, line, f[7], "tip_reach");
    if (!(u.tip_reach >= 0 && u.tip_reach <= 50)) {
      Refuse(source, line, f[7].column, "tip_reach: must be in [0, 50] m");
    }
    u.select = Flag(source, line, f[8], "select");
    if (u.select) {
      u.select_xy = {Finite(source, line, f[9], "select_x"),
                     Finite(source, line, f[10], "select_y")};
      u.select_heading = Finite(source, line, f[11], "select_heading");
    } else {
      for (int k = 9; k <= 11; ++k) {
        if (!f[k].text.empty()) {
          Refuse(source, line, f[k].column, "a row with select 0 leaves the selection pose empty");
        }
      }
    }
    updates.push_back(u);
  }
  if (updates.empty()) Refuse(source, 0, 0, "no updates (rows after the header)");
  return updates;
}

std::vector<FrameRow> ParseFramesCsv(const std::string& text, const std::string& source) {
  std::vector<FrameRow> frames;
  for (const auto& [line, f] : CsvRows(text, source, kFramesHeader)) {
    FrameRow r;
    r.line = line;
    r.update = Integer(source, line, f[0], "update", 0, 1'000'000'000);
    if (!frames.empty() && r.update < frames.back().update) {
      Refuse(source, line, f[0].column, "update: frames must come in update order");
    }
    if (f[1].text == "lidar") {
      r.kind = FrameRow::Kind::kLidar;
    } else if (f[1].text == "camera") {
      r.kind = FrameRow::Kind::kCamera;
    } else {
      Refuse(source, line, f[1].column,
             "kind: expected 'lidar' or 'camera', got '" + f[1].text.substr(0, 40) + "'");
    }
    r.sensor = f[2].text;
    if (r.sensor.empty() || r.sensor.size() > 64) {
      Refuse(source, line, f[2].column, "sensor: expected the description's sensor name");
    }
    r.stamp = Finite(source, line, f[3], "stamp");
    CheckRelativePath(source, line, f[4], "file");
    r.file = f[4].text;
    if (!f[5].text.empty()) {
      if (r.kind != FrameRow::Kind::kCamera) {
        Refuse(source, line, f[5].column, "labels_file: only a camera frame has labels");
      }
      CheckRelativePath(source, line, f[5], "labels_file");
      r.labels_file = f[5].text;
    }
    r.health_check = Flag(source, line, f[6], "health_check");
    if (r.health_check && r.kind != FrameRow::Kind::kLidar) {
      Refuse(source, line, f[6].column, "health_check: only a LiDAR frame is checked");
    }
    Eigen::Vector3d t;
    for (int i = 0; i < 3; ++i) t[i] = Finite(source, line, f[7 + i], "translation");
    Eigen::Matrix3d R;
    for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = Finite(source, line, f[10 + i], "rotation");
    if (!((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6) ||
        !(std::abs(R.determinant() - 1) < 1e-6)) {
      Refuse(source, line, f[10].column,
             "r00..r22: not a rotation matrix (R^T R = I and det R = 1 within 1e-6)");
    }
    if (t.cwiseAbs().maxCoeff() > 1e7) {
      Refuse(source, line, f[7].column, "x, y, z: farther than 10000 km from the origin");
    }
    r.T_world_sensor.linear() = R;
    r.T_world_sensor.translation() = t;
    frames.push_back(std::move(r));
  }
  return frames;
}

std::vector<DecisionRow> ParseScoopCsv(const std::string& text, const std::string& source) {
  std::vector<DecisionRow> rows;
  for (const auto& [line, f] : CsvRows(text, source, kScoopHeader)) {
    DecisionRow d;
    d.line = line;
    d.cycle = static_cast<int>(Integer(source, line, f[0], "cycle", 0, 1'000'000));
    d.time = Finite(source, line, f[1], "time");
    if (!rows.empty() && rows.back().cycle == d.cycle && d.time < rows.back().time) {
      Refuse(source, line, f[1].column, "time: goes back within cycle " + f[0].text);
    }
    d.hinge_xy = {Finite(source, line, f[2], "hinge_x"), Finite(source, line, f[3], "hinge_y")};
    d.heading = Finite(source, line, f[4], "heading");
    d.speed = Finite(source, line, f[5], "speed");
    if (std::abs(d.speed) > 30) {
      Refuse(source, line, f[5].column, "speed: beyond any loader (|v| <= 30 m/s; km/h?)");
    }
    d.q_boom = Finite(source, line, f[6], "q_boom");
    d.q_bucket = Finite(source, line, f[7], "q_bucket");
    if (std::abs(d.q_boom) > 7 || std::abs(d.q_bucket) > 7) {
      Refuse(source, line, f[6].column, "q_boom, q_bucket: beyond a turn (radians?)");
    }
    d.path_points = Integer(source, line, f[8], "path_points", 1, 100'000'000);
    d.predict = Flag(source, line, f[9], "predict");
    rows.push_back(d);
  }
  return rows;
}

std::vector<TipPoint> ParseTipPathCsv(const std::string& text, const std::string& source) {
  std::vector<TipPoint> points;
  for (const auto& [line, f] : CsvRows(text, source, kTipPathHeader)) {
    TipPoint t;
    t.line = line;
    t.cycle = static_cast<int>(Integer(source, line, f[0], "cycle", 0, 1'000'000));
    if (!points.empty() && t.cycle < points.back().cycle) {
      Refuse(source, line, f[0].column, "cycle: points must come grouped by cycle, in order");
    }
    t.p = {Finite(source, line, f[1], "x"), Finite(source, line, f[2], "y"),
           Finite(source, line, f[3], "z")};
    points.push_back(t);
  }
  return points;
}

Manifest ReadManifest(const std::filesystem::path& path) {
  core::DiagnosticSink sink;
  const core::YamlFile file(path, sink);
  Manifest m;
  if (file.ok()) {
    using core::NumberRule;
    core::MapReader root = core::MapReader::Root(file, nullptr);
    CheckFormatAndVersion(root, sink);
    m.machine_file = root.String("machine");
    if (root.Has("overlays")) m.overlays = root.Strings("overlays", false);
    m.source = root.OptionalString("source").value_or("");
    {
      core::MapReader map = root.Map("map");
      m.map_resolution = map.Number("resolution", NumberRule::Closed(0.01, 10, "m"));
      const auto length = map.Numbers<2>("length", NumberRule::Closed(1, 10000, "m"));
      const auto center = map.Numbers<2>("center", NumberRule::Any("m"));
      m.map_length = {length[0], length[1]};
      m.map_center = {center[0], center[1]};
      map.Finish();
      if (sink.empty() &&
          m.map_length.x() * m.map_length.y() / (m.map_resolution * m.map_resolution) > 1e8) {
        map.Error("resolution", "more than 100 million cells");
      }
    }
    if (auto p = root.OptionalMap("perception")) {
      m.truth_labels = p->Enum("semantics", {"labels", "network"}) == "labels";
      m.segmentation_scale = p->Number("segmentation_scale", NumberRule::Closed(0.1, 1, ""), 1.0);
      p->Finish();
    }
    ReadSelection(root.Map("selection"), m);
    std::set<int> indices;
    for (core::MapReader& c : root.MapList("cycles", true)) {
      CycleInfo cycle = ReadCycle(c);
      if (!indices.insert(cycle.index).second) {
        c.Error("index", "cycle " + std::to_string(cycle.index) + " given twice");
      }
      m.cycles.push_back(std::move(cycle));
    }
    root.Finish();
    auto inside = [](const std::string& name) {
      return !name.empty() && name.find("..") == std::string::npos && name.front() != '/';
    };
    if (sink.empty() && !inside(m.machine_file)) {
      root.Error("machine", "must name a file inside the recording folder");
    }
    for (const std::string& overlay : m.overlays) {
      if (sink.empty() && !inside(overlay)) {
        root.Error("overlays", "'" + overlay + "' must name a file inside the recording folder");
      }
    }
  }
  sink.ThrowIfAny();
  return m;
}

}  // namespace autoshovel::recording
