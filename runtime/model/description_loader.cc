// Reading and validating machine descriptions and materials (models/README.md is the schema).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <set>

#include "runtime/core/input_file.h"
#include "runtime/core/sha256.h"
#include "runtime/core/strings.h"
#include "runtime/core/yaml_reader.h"
#include "runtime/model/description.h"
#include "runtime/model/interpreted_model.h"
#include "runtime/model/plausibility.h"

namespace autoshovel::model {
namespace {

using core::MapReader;
using core::NumberRule;

constexpr double kBar = 1e5;                   // [Pa]
constexpr double kLitrePerMinute = 1e-3 / 60;  // [m³/s]
constexpr double kRpm = 2 * std::numbers::pi / 60;

Eigen::Vector2d Point(MapReader& map, std::string_view key) {
  const auto v = map.Numbers<2>(key, NumberRule::Any("m"));
  return {v[0], v[1]};
}

Pose3 ReadPose(MapReader map) {
  Pose3 pose;
  const auto xyz = map.Numbers<3>("xyz", NumberRule::Any("m"));
  const auto rpy = map.Numbers<3>("rpy_deg", NumberRule::Closed(-180, 180, "deg"));
  pose.xyz = {xyz[0], xyz[1], xyz[2]};
  pose.rpy = Eigen::Vector3d(rpy[0], rpy[1], rpy[2]) * std::numbers::pi / 180.0;
  map.Finish();
  return pose;
}

Mount ReadMount(MapReader map) {
  Mount mount;
  mount.body = map.String("body");
  mount.point = Point(map, "point");
  map.Finish();
  return mount;
}

Chassis ReadChassis(MapReader map, MachineKind kind) {
  Chassis c;
  c.operating_mass = map.Number("operating_mass", NumberRule::Positive("kg"));
  if (kind == MachineKind::kWheelLoader) {
    c.hinge_to_front_axle = map.Number("hinge_to_front_axle", NumberRule::Positive("m"));
    c.hinge_to_rear_axle = map.Number("hinge_to_rear_axle", NumberRule::Positive("m"));
    c.track_width = map.Number("track_width", NumberRule::Positive("m"));
    c.wheel_radius = map.Number("wheel_radius", NumberRule::Positive("m"));
    c.front_axle_load_fraction = map.Number("front_axle_load_fraction", NumberRule::Open(0, 1, ""));
    c.max_articulation = map.AngleDeg("max_articulation_deg", NumberRule::Open(0, 60, "deg"));
    c.max_articulation_rate =
        map.AngleDeg("max_articulation_rate_deg_s", NumberRule::Positive("deg/s"));
    c.rolling_resistance = map.Number("rolling_resistance", NumberRule::Open(0, 0.5, ""), 0.03);
    c.traction_coefficient = map.Number("traction_coefficient", NumberRule::Open(0, 1.5, ""), 0.6);
    c.max_speed = map.Number("max_speed", NumberRule::Positive("m/s"));
  } else {
    c.track_gauge = map.Number("track_gauge", NumberRule::Positive("m"));
    c.track_length = map.Number("track_length", NumberRule::Positive("m"));
    c.track_shoe_width = map.Number("track_shoe_width", NumberRule::Positive("m"));
  }
  map.Finish();
  return c;
}

FourBarLinkage ReadLinkage(MapReader map) {
  FourBarLinkage bar;
  bar.rocker_pivot = Point(map, "rocker_pivot");
  bar.rocker_length = map.Number("rocker_length", NumberRule::Positive("m"));
  bar.child_coupler_point = Point(map, "child_coupler_point");
  bar.coupler_length = map.Number("coupler_length", NumberRule::Positive("m"));
  bar.assembly_branch = map.Integer("assembly_branch", -1, 1, 1);
  if (bar.assembly_branch == 0) map.Error("assembly_branch", "must be +1 or -1, got 0");
  bar.rocker_mass = map.Number("rocker_mass", NumberRule::NonNegative("kg"), 0.0);
  if (map.Has("rocker_center_of_mass")) {
    bar.rocker_center_of_mass = Point(map, "rocker_center_of_mass");
  } else {
    bar.rocker_center_of_mass = {bar.rocker_length / 2, 0.0};  // a straight bar
  }
  bar.rocker_inertia = map.Number("rocker_inertia", NumberRule::NonNegative("kg m^2"), 0.0);
  bar.coupler_mass = map.Number("coupler_mass", NumberRule::NonNegative("kg"), 0.0);
  bar.coupler_inertia = map.Number("coupler_inertia", NumberRule::NonNegative("kg m^2"), 0.0);
  map.Finish();
  return bar;
}

Link ReadLink(MapReader map) {
  Link link;
  link.name = map.String("name");
  link.length = map.Number("length", NumberRule::Positive("m"));
  link.imu_offset = map.AngleDeg("imu_offset_deg", NumberRule::Open(-180, 180, "deg"), 0.0);
  link.joint_min = map.AngleDeg("joint_min_deg", NumberRule::Closed(-180, 180, "deg"));
  link.joint_max = map.AngleDeg("joint_max_deg", NumberRule::Closed(-180, 180, "deg"));
  link.mass = map.Number("mass", NumberRule::Positive("kg"));
  link.center_of_mass = Point(map, "center_of_mass");
  link.inertia = map.Number("inertia", NumberRule::NonNegative("kg m^2"));
  link.viscous_friction = map.Number("viscous_friction", NumberRule::NonNegative("N m s/rad"));
  if (auto linkage = map.OptionalMap("linkage")) link.linkage = ReadLinkage(*linkage);
  map.Finish();
  return link;
}

// An opening curve `[[duty, opening], ...]` of a valve (models/README.md): at least two points,
// duty and opening fractions in [0, 1], the first opening 0 (the dead band lies below the first
// duty where the opening leaves 0), duty strictly increasing, opening non-decreasing and not
// all 0. Each bad point is reported at its own location. Absent: empty.
std::vector<OpeningPoint> ReadOpeningCurve(MapReader& map, std::string_view key,
                                           core::DiagnosticSink& sink) {
  std::vector<OpeningPoint> curve;
  const std::optional<YAML::Node> node = map.Raw(key, /*required=*/false);
  if (!node) return curve;
  const std::string file = map.location().file;
  const std::string path = map.PathOf(key);
  auto fail = [&](const YAML::Node& at, const std::string& where, const std::string& message) {
    sink.Add(core::LocationOf(file, at), where, message);
  };
  if (!node->IsSequence() || node->size() < 2) {
    fail(*node, path,
         "expected a list of at least 2 points [duty, opening] (fractions of full command and "
         "full opening, in [0, 1])");
    return curve;
  }
  bool ok = true;
  for (std::size_t i = 0; i < node->size(); ++i) {
    const YAML::Node p = (*node)[i];
    const std::string where = path + "[" + std::to_string(i) + "]";
    double duty = 0, opening = 0;
    if (!p.IsSequence() || p.size() != 2 || !YAML::convert<double>::decode(p[0], duty) ||
        !YAML::convert<double>::decode(p[1], opening) || !std::isfinite(duty) ||
        !std::isfinite(opening)) {
      fail(p, where, "expected a point [duty, opening] (fractions in [0, 1])");
      ok = false;
      continue;
    }
    const std::string text =
        "[" + core::FormatNumber(duty) + ", " + core::FormatNumber(opening) + "]";
    if (duty < 0 || duty > 1 || opening < 0 || opening > 1) {
      fail(p, where, "duty and opening are fractions in [0, 1], got " + text);
      ok = false;
      continue;
    }
    if (curve.empty() && opening != 0) {
      fail(p, where,
           "the first point's opening must be 0 (the valve is closed up to where the curve "
           "leaves 0: its dead band), got " +
               text);
      ok = false;
    } else if (!curve.empty() && duty <= curve.back().duty) {
      fail(p, where,
           "duty must increase strictly along the curve, got " + text + " after duty " +
               core::FormatNumber(curve.back().duty));
      ok = false;
    } else if (!curve.empty() && opening < curve.back().opening) {
      fail(p, where,
           "opening must not decrease along the curve (a valve opens monotonically), got " + text +
               " after opening " + core::FormatNumber(curve.back().opening));
      ok = false;
    }
    curve.push_back({duty, opening});
  }
  if (ok && curve.back().opening <= 0) {
    fail(*node, path, "the valve never opens: the last point's opening must be > 0");
    ok = false;
  }
  if (!ok) curve.clear();
  return curve;
}

// With both opening curves given the dead zone applies to no direction: a non-zero one would be
// silently ignored, so it is refused (at `key`, the value that made the conflict).
void CheckDeadZoneAgainstCurves(const MapReader& map, std::string_view key, const Valve& v) {
  if (v.opening_curve_extend.empty() || v.opening_curve_retract.empty() || v.dead_zone == 0) {
    return;
  }
  map.Error(key, "dead_zone " + core::FormatNumber(v.dead_zone) +
                     " has no effect when both opening_curve_extend and opening_curve_retract "
                     "are given (each curve holds its own dead band): set dead_zone to 0 or "
                     "drop a curve");
}

Valve ReadValve(MapReader map, core::DiagnosticSink& sink) {
  Valve v;
  v.dead_zone = map.Number("dead_zone", NumberRule{0, NumberRule::Bound::kInclusive, 0.5,
                                                   NumberRule::Bound::kExclusive, ""});
  v.transport_delay = map.Number("transport_delay", NumberRule::Closed(0, 5, "s"));
  v.spool_time_constant = map.Number("spool_time_constant", NumberRule::Open(0, 5, "s"));
  v.rated_flow = map.Number("rated_flow_lpm", NumberRule::Positive("l/min")) * kLitrePerMinute;
  v.rated_pressure_drop = map.Number("rated_pressure_drop_bar", NumberRule::Positive("bar")) * kBar;
  v.flow_gain = v.rated_flow / std::sqrt(v.rated_pressure_drop);
  // The pilot stage and the opening curves (optional; absent: no stage, dead zone + linear law).
  v.pilot_delay = map.Number("pilot_delay", NumberRule::Closed(0, 5, "s"), 0.0);
  v.pilot_time_constant = map.Number("pilot_time_constant", NumberRule::Closed(0, 5, "s"), 0.0);
  v.opening_curve_extend = ReadOpeningCurve(map, "opening_curve_extend", sink);
  v.opening_curve_retract = ReadOpeningCurve(map, "opening_curve_retract", sink);
  CheckDeadZoneAgainstCurves(map, "dead_zone", v);
  map.Finish();
  return v;
}

Actuator ReadActuator(MapReader map, core::DiagnosticSink& sink) {
  Actuator a;
  a.name = map.String("name");
  const std::string type = map.Enum("type", {"cylinder", "motor"});
  a.kind = type == "motor" ? ActuatorKind::kMotor : ActuatorKind::kCylinder;
  a.joint = map.String("joint");
  a.count = map.Integer("count", 1, 8, 1);
  if (type == "motor") {
    a.displacement = map.Number("displacement", NumberRule::Positive("m^3/rad"));
    a.line_volume = map.Number("line_volume", NumberRule::Positive("m^3"));
  } else {
    a.bore = map.Number("bore", NumberRule::Positive("m"));
    a.rod = map.Number("rod", NumberRule::Positive("m"));
    a.stroke = map.Number("stroke", NumberRule::Positive("m"));
    a.retracted_length = map.Number("retracted_length", NumberRule::Positive("m"));
    a.base_mount = ReadMount(map.Map("base_mount"));
    a.rod_mount = ReadMount(map.Map("rod_mount"));
    a.dead_volume = map.Number("dead_volume", NumberRule::Positive("m^3"));
    a.barrel_mass = map.Number("barrel_mass", NumberRule::NonNegative("kg"), 0.0);
    a.barrel_center =
        map.Number("barrel_center", NumberRule::NonNegative("m"), a.retracted_length / 2);
    a.rod_mass = map.Number("rod_mass", NumberRule::NonNegative("kg"), 0.0);
    a.rod_center = map.Number("rod_center", NumberRule::NonNegative("m"), a.retracted_length / 2);
  }
  a.relief_pressure = map.Number("relief_pressure_bar", NumberRule::Positive("bar")) * kBar;
  a.valve = ReadValve(map.Map("valve"), sink);
  map.Finish();
  return a;
}

Hydraulics ReadHydraulics(MapReader map, core::DiagnosticSink& sink) {
  Hydraulics h;
  h.pump_pressure = map.Number("pump_pressure_bar", NumberRule::Positive("bar")) * kBar;
  h.tank_pressure = map.Number("tank_pressure_bar", NumberRule::NonNegative("bar"), 2.0) * kBar;
  h.bulk_modulus = map.Number("oil_bulk_modulus_bar", NumberRule::Positive("bar")) * kBar;
  h.pump_efficiency = map.Number("pump_efficiency", NumberRule{0, NumberRule::Bound::kExclusive, 1,
                                                               NumberRule::Bound::kInclusive, ""});
  h.pump_max_flow = map.Number("pump_max_flow_lpm", NumberRule::NonNegative("l/min"), 0.0) / 60000;
  for (auto& actuator : map.MapList("actuators", true))
    h.actuators.push_back(ReadActuator(actuator, sink));
  map.Finish();
  return h;
}

Bucket ReadBucket(MapReader map, const core::YamlFile& file, core::DiagnosticSink& sink) {
  Bucket b;
  b.width = map.Number("width", NumberRule::Positive("m"));
  b.rated_capacity = map.Number("rated_capacity", NumberRule::Positive("m^3"));
  b.rated_load = map.Number("rated_load", NumberRule::Positive("kg"));
  b.design_material = map.String("design_material");
  // The profile is a list of [x, z] points of any length: read the raw node.
  if (const auto profile = map.Raw("profile", /*required=*/true)) {
    if (!profile->IsSequence() || profile->size() < 3) {
      sink.Add(core::LocationOf(file.file(), *profile), "bucket.profile",
               "expected a list of at least 3 points [x, z] (the cross-section polygon)");
    } else {
      for (std::size_t i = 0; i < profile->size(); ++i) {
        const YAML::Node p = (*profile)[i];
        double x = 0, z = 0;
        if (!p.IsSequence() || p.size() != 2 || !YAML::convert<double>::decode(p[0], x) ||
            !YAML::convert<double>::decode(p[1], z) || !std::isfinite(x) || !std::isfinite(z)) {
          sink.Add(core::LocationOf(file.file(), p), "bucket.profile[" + std::to_string(i) + "]",
                   "expected a point [x, z] in m");
          continue;
        }
        b.profile.emplace_back(x, z);
      }
    }
  }
  map.Finish();
  return b;
}

Sensors ReadSensors(MapReader map) {
  Sensors s;
  {
    MapReader cam = map.Map("camera");
    s.camera.width_px = cam.Integer("width_px", 1, 100000, 480);
    s.camera.height_px = cam.Integer("height_px", 1, 100000, 383);
    s.camera.fx = cam.Number("fx", NumberRule::Positive("px"));
    s.camera.fy = cam.Number("fy", NumberRule::Positive("px"));
    s.camera.cx = cam.Number("cx", NumberRule::Any("px"));
    s.camera.cy = cam.Number("cy", NumberRule::Any("px"));
    s.camera.pose = ReadPose(cam.Map("pose"));
    cam.Finish();
  }
  for (auto& item : map.MapList("lidars", true)) {
    Lidar l;
    l.name = item.String("name");
    l.model = item.Enum("model", {"spinning", "non_repetitive"});
    l.lines = l.model == "spinning" ? item.Integer("lines", 1, 256) : 0;
    l.horizontal_fov = item.AngleDeg("horizontal_fov_deg", NumberRule::Closed(1, 360, "deg"));
    l.vertical_fov = item.AngleDeg("vertical_fov_deg", NumberRule::Closed(1, 180, "deg"));
    l.rate = item.Number("rate_hz", NumberRule::Positive("Hz"));
    l.points_per_second = item.Number("points_per_second", NumberRule::Positive("1/s"));
    l.max_range = item.Number("max_range", NumberRule::Positive("m"));
    l.range_noise = item.Number("range_noise", NumberRule::NonNegative("m"));
    l.pose = ReadPose(item.Map("pose"));
    item.Finish();
    s.lidars.push_back(l);
  }
  for (auto& item : map.MapList("imus", true)) {
    Imu imu;
    imu.name = item.String("name");
    imu.body = item.String("body");
    imu.angle_noise = item.AngleDeg("angle_noise_deg", NumberRule::NonNegative("deg"));
    imu.bias = item.AngleDeg("bias_deg", NumberRule::Closed(-10, 10, "deg"), 0.0);
    item.Finish();
    s.imus.push_back(imu);
  }
  map.Finish();
  return s;
}

std::string DegText(double radians) {
  return core::FormatNumber(std::round(radians * 180.0 / std::numbers::pi * 1e4) / 1e4) + " deg";
}

// ---- Semantic checks: everything that needs more than one value. ----

class Validator {
 public:
  Validator(MachineDescription& machine, core::DiagnosticSink& sink) : m_(machine), sink_(sink) {}

  void Run() {
    CheckName();
    CheckKind();
    CheckLinks();
    CheckActuators();
    CheckBucket();
    CheckSensors();
    CheckEstimated();
    if (sink_.empty()) CheckCylinderReach();
  }

 private:
  void Error(const std::string& key_path, const std::string& message) {
    sink_.Add(m_.LocationOf(key_path), key_path, message);
  }

  std::vector<std::string> BodyNames() const {
    std::vector<std::string> names{"chassis", "rocker"};
    for (const auto& link : m_.links) names.push_back(link.name);
    return names;
  }

  std::string Suggest(const std::string& word, const std::vector<std::string>& options) const {
    const std::string near = core::NearestWord(word, options);
    return near.empty() ? "" : " (did you mean '" + near + "'?)";
  }

  // The name becomes a C++ namespace and a folder of generated/.
  void CheckName() {
    const std::string& name = m_.name;
    bool ok = !name.empty() && name.size() <= 64 && name[0] >= 'a' && name[0] <= 'z';
    for (const char ch : name) {
      ok = ok && ((ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_');
    }
    if (!ok) {
      Error("name", "must be a lower-case identifier (a-z, 0-9, _; starting with a letter), got '" +
                        name + "'");
    }
  }

  void CheckKind() {
    const bool loader = m_.kind == MachineKind::kWheelLoader;
    const std::size_t expected = loader ? 2 : 3;
    if (m_.links.size() != expected) {
      Error("arm.links", std::string("a ") + ToString(m_.kind) + " has " +
                             std::to_string(expected) + " links (" +
                             (loader ? "boom, bucket" : "boom, stick, bucket") + "), got " +
                             std::to_string(m_.links.size()));
    }
  }

  void CheckLinks() {
    std::set<std::string> seen;
    for (std::size_t k = 0; k < m_.links.size(); ++k) {
      const Link& link = m_.links[k];
      const std::string path = "arm.links[" + std::to_string(k) + "]";
      if (link.name == "chassis" || link.name == "rocker" || link.name == "swing") {
        Error(path + ".name", "'" + link.name + "' is reserved");
      }
      if (!seen.insert(link.name).second) {
        Error(path + ".name", "duplicate link name '" + link.name + "'");
      }
      if (link.joint_min >= link.joint_max) {
        Error(path + ".joint_max_deg", "joint limits: joint_min_deg (" + DegText(link.joint_min) +
                                           ") must be < joint_max_deg (" + DegText(link.joint_max) +
                                           ")");
      }
      if (link.linkage && k == 0) {
        Error(path + ".linkage", "the first link has no parent link to carry a rocker");
      }
    }
    if (m_.swing && m_.swing->joint_min >= m_.swing->joint_max) {
      Error("arm.swing.joint_max_deg",
            "joint limits: joint_min_deg (" + DegText(m_.swing->joint_min) +
                ") must be < joint_max_deg (" + DegText(m_.swing->joint_max) + ")");
    }
  }

  void CheckActuators() {
    std::vector<std::string> joints;
    for (const auto& link : m_.links) joints.push_back(link.name);
    if (m_.swing) joints.push_back("swing");
    std::vector<int> drivers(joints.size(), 0);
    bool all_joints_known = true;  // else "no actuator drives" would repeat the same mistake
    std::set<std::string> seen;
    for (std::size_t i = 0; i < m_.hydraulics.actuators.size(); ++i) {
      const Actuator& a = m_.hydraulics.actuators[i];
      const std::string path = "hydraulics.actuators[" + std::to_string(i) + "]";
      if (!seen.insert(a.name).second) Error(path + ".name", "duplicate actuator '" + a.name + "'");
      const auto it = std::find(joints.begin(), joints.end(), a.joint);
      if (it == joints.end()) {
        Error(path + ".joint", "unknown joint '" + a.joint + "', expected one of the links" +
                                   std::string(m_.swing ? " or 'swing'" : "") +
                                   Suggest(a.joint, joints));
        all_joints_known = false;
        continue;
      }
      const std::size_t joint = static_cast<std::size_t>(it - joints.begin());
      ++drivers[joint];
      const bool swing = a.joint == "swing";
      if (swing && a.kind != ActuatorKind::kMotor) {
        Error(path + ".type", "the swing joint is driven by a motor, got a cylinder");
        continue;
      }
      if (!swing && a.kind != ActuatorKind::kCylinder) {
        Error(path + ".type", "link '" + a.joint + "' is driven by a cylinder, got a motor");
        continue;
      }
      if (swing) continue;
      if (a.rod >= a.bore) {
        Error(path + ".rod", "rod diameter (" + core::FormatNumber(a.rod) + " m) must be < bore (" +
                                 core::FormatNumber(a.bore) + " m)");
      }
      CheckMounts(a, path, static_cast<int>(joint));
    }
    for (std::size_t j = 0; j < joints.size() && all_joints_known; ++j) {
      if (drivers[j] == 0) {
        Error("hydraulics.actuators", "no actuator drives joint '" + joints[j] + "'");
      } else if (drivers[j] > 1) {
        Error("hydraulics.actuators",
              "joint '" + joints[j] + "' is driven by " + std::to_string(drivers[j]) +
                  " actuator entries; describe identical parallel cylinders with `count`");
      }
    }
  }

  // A cylinder may connect any two bodies (issue 39): the chassis, a link, or the rocker of
  // the driven link's four-bar. Its length must move with the joint it drives (one end on the
  // driven link or its rocker) and may also move with joints before it (a Z-bar's tilt cylinder
  // pinned to the front frame moves with the boom too); it may not ride on a link after the
  // joint it drives, which would make the drive depend on the joints it positions.
  void CheckMounts(const Actuator& a, const std::string& path, int joint) {
    const std::vector<std::string> bodies = BodyNames();
    const Link& link = m_.links[joint];
    const Mount* mounts[2] = {&a.base_mount, &a.rod_mount};
    const char* keys[2] = {".base_mount.body", ".rod_mount.body"};
    bool known = true;
    for (int e = 0; e < 2; ++e) {
      const std::string& body = mounts[e]->body;
      if (std::find(bodies.begin(), bodies.end(), body) == bodies.end()) {
        Error(path + keys[e], "unknown body '" + body +
                                  "', expected 'chassis', 'rocker' or a link name" +
                                  Suggest(body, bodies));
        known = false;
      } else if (body == "rocker" && !link.linkage) {
        Error(path + keys[e], "body 'rocker' needs arm.links[" + std::to_string(joint) +
                                  "].linkage ('" + link.name + "' has no four-bar)");
        known = false;
      } else if (const int k = m_.LinkIndex(body); k > joint) {
        Error(path + keys[e], "a cylinder driving '" + link.name + "' cannot be pinned to '" +
                                  body + "', which comes after it in the chain");
        known = false;
      }
    }
    if (!known) return;
    if (a.base_mount.body == a.rod_mount.body) {
      Error(path + ".rod_mount.body",
            "both ends are pinned to '" + a.base_mount.body + "': the cylinder cannot move");
      return;
    }
    const std::string child = link.linkage ? "rocker" : link.name;
    if (a.base_mount.body != child && a.rod_mount.body != child) {
      Error(path + ".rod_mount.body", "a cylinder driving '" + link.name + "' needs one end on '" +
                                          child + "', got '" + a.base_mount.body + "' and '" +
                                          a.rod_mount.body + "'");
    }
  }

  void CheckBucket() {
    if (m_.bucket.profile.size() >= 3) {
      double twice_area = 0;
      const auto& p = m_.bucket.profile;
      for (std::size_t i = 0; i < p.size(); ++i) {
        const auto& a = p[i];
        const auto& b = p[(i + 1) % p.size()];
        twice_area += a.x() * b.y() - b.x() * a.y();
      }
      if (std::abs(twice_area) < 1e-4) {
        Error("bucket.profile", "the cross-section polygon has (almost) zero area");
      }
    }
    if (!m_.bucket.design_material.empty() && !m_.FindMaterial(m_.bucket.design_material)) {
      std::vector<std::string> names;
      for (const auto& material : m_.materials) names.push_back(material.name);
      std::string list;
      for (const auto& name : names) list += (list.empty() ? "" : ", ") + name;
      std::string searched;
      for (const auto& folder : m_.materials_searched) {
        std::error_code error;
        searched += (searched.empty() ? "" : ", ") + folder +
                    (std::filesystem::is_directory(folder, error) ? "" : " (no such folder)");
      }
      Error("bucket.design_material",
            "unknown material '" + m_.bucket.design_material + "' (known: " +
                (list.empty() ? "none" : list) + ")" + Suggest(m_.bucket.design_material, names) +
                "; searched " + searched + " (--materials DIR names another folder)");
    }
  }

  void CheckSensors() {
    std::vector<std::string> bodies{"chassis"};
    for (const auto& link : m_.links) bodies.push_back(link.name);
    std::vector<int> count(bodies.size(), 0);
    bool all_bodies_known = true;
    for (std::size_t i = 0; i < m_.sensors.imus.size(); ++i) {
      const Imu& imu = m_.sensors.imus[i];
      const auto it = std::find(bodies.begin(), bodies.end(), imu.body);
      if (it == bodies.end()) {
        Error("sensors.imus[" + std::to_string(i) + "].body",
              "unknown body '" + imu.body + "', expected 'chassis' or a link name" +
                  Suggest(imu.body, bodies));
        all_bodies_known = false;
        continue;
      }
      ++count[it - bodies.begin()];
    }
    for (std::size_t b = 0; b < bodies.size() && all_bodies_known; ++b) {
      if (count[b] != 1) {
        Error("sensors.imus", "Eq. (1) needs exactly one IMU on '" + bodies[b] + "', got " +
                                  std::to_string(count[b]));
      }
    }
  }

  void CheckEstimated() {
    std::vector<std::string> paths;
    for (const auto& [path, where] : m_.locations) paths.push_back(path);
    for (std::size_t i = 0; i < m_.estimated.size(); ++i) {
      const std::string& path = m_.estimated[i];
      if (m_.locations.count(path) == 0) {
        Error("estimated[" + std::to_string(i) + "]",
              "no value at key path '" + path + "'" + Suggest(path, paths));
      }
    }
  }

  // Over the whole joint range the cylinder must stay within [retracted, retracted + stroke],
  // its linkage must close, and its lever arm must keep one sign (no dead centre): otherwise the
  // cylinder cannot drive the joint through the range the description claims.
  void CheckCylinderReach() {
    const InterpretedModel model(m_);
    const int J = model.sizes().num_joints;
    for (std::size_t i = 0; i < m_.hydraulics.actuators.size(); ++i) {
      const Actuator& a = m_.hydraulics.actuators[i];
      if (a.kind != ActuatorKind::kCylinder) continue;
      const int joint = m_.LinkIndex(a.joint);
      const Link& link = m_.links[joint];
      const std::string path = "hydraulics.actuators[" + std::to_string(i) + "]";
      if (const int first = FirstJointMoving(a); first < joint) {
        CheckCoupledReach(static_cast<int>(i), first, joint, model);
        continue;
      }
      std::vector<double> q(J, 0.0);
      constexpr int kSamples = 721;
      double min_length = 1e300, max_length = -1e300, min_lever = 1e300, max_lever = -1e300;
      double length_at_min = 0, length_at_max = 0;
      for (int s = 0; s < kSamples; ++s) {
        q[joint] = link.joint_min + (link.joint_max - link.joint_min) * s / (kSamples - 1);
        const double length = model.CylinderLength(static_cast<int>(i), q.data());
        if (!std::isfinite(length)) {
          Error("arm.links[" + std::to_string(joint) + "].linkage",
                "the four-bar of '" + link.name + "' cannot close at joint angle " +
                    DegText(q[joint]) + " (coupler or rocker too short)");
          return;
        }
        const double lever = model.LeverArms(static_cast<int>(i), q.data())[joint];
        if (s == 0) length_at_min = length;
        if (s == kSamples - 1) length_at_max = length;
        min_length = std::min(min_length, length);
        max_length = std::max(max_length, length);
        min_lever = std::min(min_lever, lever);
        max_lever = std::max(max_lever, lever);
      }
      const double tolerance = 1e-6;
      const double shortest = a.retracted_length, longest = a.retracted_length + a.stroke;
      if (min_length < shortest - tolerance || max_length > longest + tolerance) {
        Error(path + ".stroke",
              "cylinder cannot reach the joint range of '" + link.name + "' [" +
                  DegText(link.joint_min) + ", " + DegText(link.joint_max) + "]: it needs " +
                  core::FormatNumber(std::round(min_length * 1e4) / 1e4) + " to " +
                  core::FormatNumber(std::round(max_length * 1e4) / 1e4) +
                  " m pin to pin (at the limits " +
                  core::FormatNumber(std::round(length_at_min * 1e4) / 1e4) + " and " +
                  core::FormatNumber(std::round(length_at_max * 1e4) / 1e4) + " m), but spans " +
                  core::FormatNumber(shortest) + " to " + core::FormatNumber(longest) + " m");
        continue;
      }
      constexpr double kMinLever = 0.02;  // [m/rad]: below this the cylinder is near dead centre
      if (!(min_lever > kMinLever || max_lever < -kMinLever)) {
        Error(path + ".rod_mount.point",
              "cylinder passes (near) dead centre over the joint range of '" + link.name +
                  "': lever arm dL/dq goes from " + core::FormatNumber(min_lever) + " to " +
                  core::FormatNumber(max_lever) + " m/rad");
      } else {
        CheckLoaderValveSense(path, link, max_lever);
      }
    }
  }

  // Joints are numbered along the chain; a body rides on every joint up to its depth (the
  // chassis on none, link k on joints 0..k, the rocker of link k on 0..k through the closure).
  // A cylinder's length moves with the joints between the depths of its two ends.
  int BodyDepth(const Mount& mount, int driven_joint) const {
    if (mount.body == "chassis") return 0;
    if (mount.body == "rocker") return driven_joint + 1;
    return m_.LinkIndex(mount.body) + 1;
  }
  int FirstJointMoving(const Actuator& a) const {
    const int joint = m_.LinkIndex(a.joint);
    return std::min(BodyDepth(a.base_mount, joint), BodyDepth(a.rod_mount, joint));
  }

  // A cylinder whose length also moves with joints before the one it drives (a frame-mounted
  // Z-bar tilt cylinder): its stroke limits the driven joint to a window that slides with the
  // others, as on the real machine (self-levelling). Over a grid of the other joints' ranges,
  // the window must never be empty, together the windows must reach both joint limits, and the
  // lever arm on the driven joint must keep one sign wherever the cylinder reaches.
  void CheckCoupledReach(int actuator, int first, int joint, const InterpretedModel& model) {
    const Actuator& a = m_.hydraulics.actuators[actuator];
    const Link& link = m_.links[joint];
    const std::string path = "hydraulics.actuators[" + std::to_string(actuator) + "]";
    const int J = model.sizes().num_joints;
    const int others = joint - first;
    constexpr int kOtherSamples = 25, kOwnSamples = 361;
    constexpr double kTolerance = 1e-6, kMinLever = 0.02;
    const double shortest = a.retracted_length, longest = a.retracted_length + a.stroke;
    double reach_min = 1e300, reach_max = -1e300, min_lever = 1e300, max_lever = -1e300;
    int grid = 1;
    for (int k = 0; k < others; ++k) grid *= kOtherSamples;
    std::vector<double> q(J, 0.0);
    for (int cell = 0; cell < grid; ++cell) {
      int rest = cell;
      for (int k = first; k < joint; ++k) {
        const int s = rest % kOtherSamples;
        rest /= kOtherSamples;
        q[k] = m_.links[k].joint_min +
               (m_.links[k].joint_max - m_.links[k].joint_min) * s / (kOtherSamples - 1);
      }
      bool any = false;
      for (int s = 0; s < kOwnSamples; ++s) {
        q[joint] = link.joint_min + (link.joint_max - link.joint_min) * s / (kOwnSamples - 1);
        const double length = model.CylinderLength(actuator, q.data());
        if (!std::isfinite(length)) {
          Error("arm.links[" + std::to_string(joint) + "].linkage",
                "the four-bar of '" + link.name + "' cannot close at joint angle " +
                    DegText(q[joint]) + " (coupler or rocker too short)");
          return;
        }
        if (length < shortest - kTolerance || length > longest + kTolerance) continue;
        any = true;
        reach_min = std::min(reach_min, q[joint]);
        reach_max = std::max(reach_max, q[joint]);
        const double lever = model.LeverArms(actuator, q.data())[joint];
        min_lever = std::min(min_lever, lever);
        max_lever = std::max(max_lever, lever);
      }
      if (!any) {
        std::string where;
        for (int k = first; k < joint; ++k) {
          where += (where.empty() ? "" : ", ") + m_.links[k].name + " at " + DegText(q[k]);
        }
        Error(path + ".stroke", "with " + where + " the cylinder (" + core::FormatNumber(shortest) +
                                    " to " + core::FormatNumber(longest) +
                                    " m pin to pin) reaches no angle of '" + link.name + "' in [" +
                                    DegText(link.joint_min) + ", " + DegText(link.joint_max) + "]");
        return;
      }
    }
    const double step = (link.joint_max - link.joint_min) / (kOwnSamples - 1);
    if (reach_min > link.joint_min + step || reach_max < link.joint_max - step) {
      Error(path + ".stroke", "over the range of the joints before it the cylinder reaches '" +
                                  link.name + "' from " + DegText(reach_min) + " to " +
                                  DegText(reach_max) + ", not its limits [" +
                                  DegText(link.joint_min) + ", " + DegText(link.joint_max) + "]");
      return;
    }
    if (!(min_lever > kMinLever || max_lever < -kMinLever)) {
      Error(path + ".rod_mount.point", "cylinder passes (near) dead centre where it reaches '" +
                                           link.name + "': lever arm dL/dq goes from " +
                                           core::FormatNumber(min_lever) + " to " +
                                           core::FormatNumber(max_lever) + " m/rad");
    } else {
      CheckLoaderValveSense(path, link, max_lever);
    }
  }

  // The loader's controllers (runtime/control) command each valve in its joint's direction and
  // the plant feeds the cap side for a positive command: a loader cylinder must extend to raise
  // the boom and to rack the bucket back. A linkage that racks back by retracting drives the
  // wrong way under them (found with a parallel-lift design in issue 39), so it is refused here
  // rather than run into a stuck-valve stop. The excavator's servo reads the lever's sign.
  void CheckLoaderValveSense(const std::string& path, const Link& link, double max_lever) {
    if (m_.kind != MachineKind::kWheelLoader || max_lever > 0) return;
    Error(path + ".rod_mount.point",
          "this cylinder retracts to raise '" + link.name +
              "' (dL/dq < 0); the loader runtime commands valves in the joint's direction with "
              "extension raising the boom and racking the bucket back: mount it so that it "
              "extends (e.g. the bell crank's cylinder pin on the other side of its pivot)");
  }

  MachineDescription& m_;
  core::DiagnosticSink& sink_;
};

}  // namespace

const char* ToString(MachineKind kind) {
  return kind == MachineKind::kWheelLoader ? "wheel_loader" : "excavator";
}
const char* ToString(DriveKind drive) {
  return drive == DriveKind::kElectric ? "electric" : "diesel";
}

int MachineDescription::LinkIndex(const std::string& link_name) const {
  for (std::size_t k = 0; k < links.size(); ++k) {
    if (links[k].name == link_name) return static_cast<int>(k);
  }
  return -1;
}

int MachineDescription::ActuatorOfJoint(std::size_t joint_index) const {
  const std::string joint = joint_index < links.size() ? links[joint_index].name : "swing";
  for (std::size_t i = 0; i < hydraulics.actuators.size(); ++i) {
    if (hydraulics.actuators[i].joint == joint) return static_cast<int>(i);
  }
  return -1;
}

const Lidar* MachineDescription::FindLidar(std::string_view lidar_name) const {
  for (const Lidar& lidar : sensors.lidars) {
    if (lidar.name == lidar_name) return &lidar;
  }
  return nullptr;
}

const Material* MachineDescription::FindMaterial(const std::string& material_name) const {
  for (const auto& material : materials) {
    if (material.name == material_name) return &material;
  }
  return nullptr;
}

core::SourceLocation MachineDescription::LocationOf(const std::string& key_path) const {
  // Fall back to the nearest recorded parent path, then to the file.
  std::string path = key_path;
  while (!path.empty()) {
    if (const auto it = locations.find(path); it != locations.end()) return it->second;
    const auto cut = path.find_last_of(".[");
    if (cut == std::string::npos) break;
    path.resize(cut);
  }
  return {source_file, 1, 1};
}

std::vector<std::string> FindMachineDescriptions(const std::string& models_dir) {
  namespace fs = std::filesystem;
  std::vector<std::string> files;
  std::error_code error;
  if (!fs::is_directory(models_dir, error)) return files;
  for (auto it = fs::recursive_directory_iterator(models_dir);
       it != fs::recursive_directory_iterator(); ++it) {
    const std::string name = it->path().filename().string();
    if (it->is_directory() && (name == "materials" || name == "scenarios")) {
      it.disable_recursion_pending();
      continue;
    }
    // `<stem>.meta.yaml` is a trained model's provenance (prediction/model_provenance.h).
    if (it->is_regular_file() && it->path().extension() == ".yaml" &&
        !name.ends_with(".meta.yaml")) {
      files.push_back(it->path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string ResolveMachineDescription(const std::string& name_or_path,
                                      const std::string& models_dir) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (fs::is_regular_file(name_or_path, error)) return name_or_path;
  std::vector<std::string> names;
  for (const auto& file : FindMachineDescriptions(models_dir)) {
    const std::string stem = fs::path(file).stem().string();
    if (stem == name_or_path) return file;
    names.push_back(stem);
  }
  // A path that exists but is no file (a folder, a named pipe) is said so, not "no such file".
  // It is asked after the names: a folder called `xcmg_968ev` in the working directory (a run
  // folder named after the machine) must not hide the description of that name.
  if (fs::exists(name_or_path, error)) {
    throw std::runtime_error(name_or_path + ": " + core::NotARegularFile(name_or_path));
  }
  std::string list;
  for (const auto& name : names) list += (list.empty() ? "" : ", ") + name;
  std::string message = "unknown machine '" + name_or_path + "' (no such file, and no " +
                        name_or_path + ".yaml under " + models_dir + "; known: " + list + ")";
  if (const std::string near = core::NearestWord(name_or_path, names); !near.empty()) {
    message += "; did you mean '" + near + "'?";
  }
  throw std::runtime_error(message);
}

Material LoadMaterial(const std::string& path) {
  core::DiagnosticSink sink;
  const core::YamlFile file(path, sink);
  MapReader root = MapReader::Root(file, nullptr);
  Material m;
  m.source_file = path;
  m.name = root.String("name");
  m.density = root.Number("density", NumberRule::Closed(100, 5000, "kg/m^3"));
  m.friction_angle = root.AngleDeg("friction_angle_deg", NumberRule::Open(0, 60, "deg"));
  m.interface_friction_angle =
      root.AngleDeg("interface_friction_angle_deg", NumberRule::Open(0, 60, "deg"));
  m.cohesion = root.Number("cohesion", NumberRule::NonNegative("Pa"));
  m.angle_of_repose = root.AngleDeg("angle_of_repose_deg", NumberRule::Open(0, 60, "deg"));
  m.difficult = root.Enum("difficulty", {"easy", "difficult"}) == "difficult";
  m.reflectivity = root.Number("reflectivity", NumberRule::Closed(0, 1, ""));
  root.Finish();
  const std::string stem = std::filesystem::path(path).stem().string();
  if (sink.empty() && m.name != stem) {
    sink.Add(root.LocationOf("name"), "name",
             "must match the file name '" + stem + "', got '" + m.name + "'");
  }
  sink.ThrowIfAny();
  return m;
}

std::vector<Material> LoadMaterials(const std::string& directory) {
  std::vector<std::filesystem::path> files;
  std::error_code error;
  if (std::filesystem::is_directory(directory, error)) {
    for (const auto& entry : std::filesystem::directory_iterator(directory)) {
      if (entry.path().extension() == ".yaml") files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  std::vector<Material> materials;
  std::vector<core::Diagnostic> problems;
  for (const auto& file : files) {
    try {
      materials.push_back(LoadMaterial(file.string()));
    } catch (const core::InputError& e) {
      problems.insert(problems.end(), e.diagnostics().begin(), e.diagnostics().end());
    }
  }
  if (!problems.empty()) throw core::InputError(problems);
  return materials;
}

namespace {

// Index of `name` among `names`, or -1 after a located error suggesting the nearest name.
int FindOverlayTarget(MapReader& item, const std::string& name,
                      const std::vector<std::string>& names, const std::string& what,
                      const std::string& machine) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it != names.end()) return static_cast<int>(it - names.begin());
  std::string message = "no " + what + " '" + name + "' in " + machine;
  if (const std::string near = core::NearestWord(name, names); !near.empty()) {
    message += "; did you mean '" + near + "'?";
  }
  item.Error("name", message);
  return -1;
}

// Identified values on top of a description (LoadOptions::overlays).
void ApplyOverlay(MachineDescription& m, const std::string& path, core::DiagnosticSink& sink) {
  const core::YamlFile file(path, sink);
  if (!file.ok()) return;
  MapReader root = MapReader::Root(file, nullptr);
  const std::string machine = root.String("machine");
  if (!machine.empty() && machine != m.name) {
    root.Error("machine", "this overlay is for '" + machine + "', the description is '" + m.name +
                              "' (" + m.source_file + ")");
  }
  if (root.Has("base_sha256")) {
    const std::string sha = root.String("base_sha256");
    if (!sha.empty() && sha != m.sha256) {
      root.Error("base_sha256", "identified against another version of " + m.source_file +
                                    " (its SHA-256 is now " + m.sha256 +
                                    "): identify again, or delete this line to apply anyway");
    }
  }
  if (std::optional<MapReader> arm = root.OptionalMap("arm")) {
    for (MapReader& link : arm->MapList("links", false)) {
      const std::string name = link.String("name");
      std::vector<std::string> names;
      for (const Link& l : m.links) names.push_back(l.name);
      const int k = FindOverlayTarget(link, name, names, "link", m.name);
      if (k < 0) continue;
      if (link.Has("length")) {
        m.links[k].length = link.Number("length", NumberRule::Positive("m"));
      }
      if (link.Has("imu_offset_deg")) {
        m.links[k].imu_offset = link.AngleDeg("imu_offset_deg", NumberRule::Open(-180, 180, "deg"));
      }
      link.Finish();
    }
    arm->Finish();
  }
  // Valve dynamics identified from step/chirp logs (`autoshovel identify hydraulics`). The
  // rules are those of the description itself (ReadValve).
  if (std::optional<MapReader> hydraulics = root.OptionalMap("hydraulics")) {
    for (MapReader& item : hydraulics->MapList("actuators", false)) {
      const std::string name = item.String("name");
      std::vector<std::string> names;
      for (const Actuator& a : m.hydraulics.actuators) names.push_back(a.name);
      const int k = FindOverlayTarget(item, name, names, "actuator", m.name);
      if (k < 0) continue;
      Valve& valve = m.hydraulics.actuators[k].valve;
      if (item.Has("dead_zone")) {
        valve.dead_zone = item.Number("dead_zone", NumberRule{0, NumberRule::Bound::kInclusive, 0.5,
                                                              NumberRule::Bound::kExclusive, ""});
      }
      if (item.Has("transport_delay")) {
        valve.transport_delay = item.Number("transport_delay", NumberRule::Closed(0, 5, "s"));
      }
      for (const char* compiled : {"spool_time_constant", "rated_flow_lpm"}) {
        if (item.Has(compiled)) {
          m.overlay_code_keys.push_back(path + ": hydraulics.actuators[" + name + "]." + compiled);
        }
      }
      if (item.Has("spool_time_constant")) {
        valve.spool_time_constant = item.Number("spool_time_constant", NumberRule::Open(0, 5, "s"));
      }
      if (item.Has("rated_flow_lpm")) {
        valve.rated_flow =
            item.Number("rated_flow_lpm", NumberRule::Positive("l/min")) * kLitrePerMinute;
        valve.flow_gain = valve.rated_flow / std::sqrt(valve.rated_pressure_drop);
      }
      if (item.Has("pilot_delay")) {
        valve.pilot_delay = item.Number("pilot_delay", NumberRule::Closed(0, 5, "s"));
      }
      if (item.Has("pilot_time_constant")) {
        valve.pilot_time_constant =
            item.Number("pilot_time_constant", NumberRule::Closed(0, 5, "s"));
      }
      for (const char* key : {"opening_curve_extend", "opening_curve_retract"}) {
        if (!item.Has(key)) continue;
        std::vector<OpeningPoint> curve = ReadOpeningCurve(item, key, sink);
        (std::string(key) == "opening_curve_extend" ? valve.opening_curve_extend
                                                    : valve.opening_curve_retract) =
            std::move(curve);
      }
      // Blamed on what this overlay gave: its curves (the dead zone may be the description's).
      CheckDeadZoneAgainstCurves(item,
                                 item.Has("dead_zone")               ? "dead_zone"
                                 : item.Has("opening_curve_retract") ? "opening_curve_retract"
                                                                     : "opening_curve_extend",
                                 valve);
      item.Finish();
    }
    hydraulics->Finish();
  }
  // Sensor mounting poses (`autoshovel calibrate camera-lidar`), vehicle frame as in the
  // description.
  if (std::optional<MapReader> sensors = root.OptionalMap("sensors")) {
    if (std::optional<MapReader> camera = sensors->OptionalMap("camera")) {
      if (camera->Has("pose")) m.sensors.camera.pose = ReadPose(camera->Map("pose"));
      camera->Finish();
    }
    for (MapReader& item : sensors->MapList("lidars", false)) {
      const std::string name = item.String("name");
      std::vector<std::string> names;
      for (const Lidar& l : m.sensors.lidars) names.push_back(l.name);
      const int k = FindOverlayTarget(item, name, names, "lidar", m.name);
      if (k < 0) continue;
      if (item.Has("pose")) m.sensors.lidars[k].pose = ReadPose(item.Map("pose"));
      item.Finish();
    }
    sensors->Finish();
  }
  root.Finish();
  m.overlays.push_back(path);
}

}  // namespace

MachineDescription LoadMachineDescription(const std::string& path, const LoadOptions& options) {
  core::DiagnosticSink sink;
  MachineDescription m;
  m.source_file = path;
  const core::YamlFile file(path, sink);
  sink.ThrowIfAny();
  m.sha256 = core::Sha256Hex(core::ReadFileBytes(path));
  core::LocationIndex* index = &m.locations;
  MapReader root = MapReader::Root(file, index);

  m.name = root.String("name");
  const std::string kind = root.Enum("kind", {"wheel_loader", "excavator"});
  m.kind = kind == "excavator" ? MachineKind::kExcavator : MachineKind::kWheelLoader;
  const std::string drive = root.Enum("drive", {"electric", "diesel"});
  m.drive = drive == "electric" ? DriveKind::kElectric : DriveKind::kDiesel;
  m.notes = root.OptionalString("notes").value_or("");
  m.estimated = root.Strings("estimated", /*required=*/false);
  m.chassis = ReadChassis(root.Map("chassis"), m.kind);
  if (m.drive == DriveKind::kElectric) {
    MapReader motor = root.Map("electric_motor");
    ElectricMotor e;
    e.max_torque = motor.Number("max_torque", NumberRule::Positive("N m"));
    e.max_power = motor.Number("max_power", NumberRule::Positive("W"));
    e.gear_ratio = motor.Number("gear_ratio", NumberRule::Positive(""));
    e.efficiency = motor.Number("efficiency", NumberRule{0, NumberRule::Bound::kExclusive, 1,
                                                         NumberRule::Bound::kInclusive, ""});
    motor.Finish();
    m.electric_motor = e;
  } else {
    MapReader engine = root.Map("diesel_engine");
    DieselEngine d;
    d.rated_power = engine.Number("rated_power", NumberRule::Positive("W"));
    d.max_torque = engine.Number("max_torque", NumberRule::Positive("N m"));
    d.rated_speed = engine.Number("rated_speed_rpm", NumberRule::Positive("rpm")) * kRpm;
    d.throttle_time_constant =
        engine.Number("throttle_time_constant", NumberRule::Open(0, 10, "s"));
    d.gear_ratio = engine.Number("gear_ratio", NumberRule::Positive(""));
    d.efficiency = engine.Number("efficiency", NumberRule{0, NumberRule::Bound::kExclusive, 1,
                                                          NumberRule::Bound::kInclusive, ""});
    engine.Finish();
    m.diesel_engine = d;
  }
  {
    MapReader arm = root.Map("arm");
    m.arm_pivot = Point(arm, "pivot");
    for (auto& link : arm.MapList("links", true)) m.links.push_back(ReadLink(link));
    if (m.kind == MachineKind::kExcavator) {
      MapReader swing = arm.Map("swing");
      Swing s;
      s.joint_min = swing.AngleDeg("joint_min_deg", NumberRule::Closed(-360, 360, "deg"));
      s.joint_max = swing.AngleDeg("joint_max_deg", NumberRule::Closed(-360, 360, "deg"));
      s.inertia = swing.Number("inertia", NumberRule::Positive("kg m^2"));
      s.viscous_friction = swing.Number("viscous_friction", NumberRule::NonNegative("N m s/rad"));
      swing.Finish();
      m.swing = s;
    }
    arm.Finish();
  }
  m.hydraulics = ReadHydraulics(root.Map("hydraulics"), sink);
  m.bucket = ReadBucket(root.Map("bucket"), file, sink);
  m.sensors = ReadSensors(root.Map("sensors"));
  root.Finish();
  if (sink.empty()) {
    for (const std::string& overlay : options.overlays) ApplyOverlay(m, overlay, sink);
  }

  // Materials: a name is taken from the first folder searched that has it.
  m.materials_searched = MaterialFolders(path, options);
  for (const std::string& folder : m.materials_searched) {
    try {
      for (Material& material : LoadMaterials(folder)) {
        if (!m.FindMaterial(material.name)) m.materials.push_back(std::move(material));
      }
    } catch (const core::InputError& e) {
      for (const auto& d : e.diagnostics()) sink.Add(d.where, d.key_path, d.message);
    }
  }
  // Values outside physical ranges (a bore in mm, a mass in tonnes): impossible ones refuse the
  // file before the geometry is checked on them, implausible ones are warnings.
  if (sink.empty()) {
    PlausibilityFindings plausibility = CheckPlausibility(m);
    for (auto& d : plausibility.errors) sink.Add(d.where, d.key_path, d.message);
    m.warnings = std::move(plausibility.warnings);
  }
  if (sink.empty()) Validator(m, sink).Run();
  sink.ThrowIfAny();
  core::ReportWarnings(m.warnings);
  return m;
}

}  // namespace autoshovel::model
