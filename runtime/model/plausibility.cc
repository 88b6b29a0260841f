#include "runtime/model/plausibility.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "runtime/core/strings.h"

namespace autoshovel::model {
namespace {

constexpr double kBar = 1e5;                   // [Pa]
constexpr double kLitrePerMinute = 1e-3 / 60;  // [m³/s]

struct Mistake {
  double factor;  ///< multiplies the value given into the expected unit
  const char* given_in;
};

// Likely mistakes per unit, most likely first; the first whose conversion lands in the range is
// named.
std::vector<Mistake> MistakesFor(const std::string& unit) {
  if (unit == "m") return {{1e-3, "mm"}, {1e-2, "cm"}, {0.0254, "inches"}, {0.3048, "feet"}};
  if (unit == "kg") return {{1e3, "tonnes"}, {0.45359237, "pounds"}};
  if (unit == "bar") return {{10, "MPa"}, {1e-5, "Pa"}, {1e-2, "kPa"}, {0.0689476, "psi"}};
  if (unit == "l/min") return {{6e4, "m^3/s"}, {60, "l/s"}, {3.78541, "US gal/min"}};
  if (unit == "m^3") return {{1e-3, "litres"}};
  if (unit == "m/s") return {{1 / 3.6, "km/h"}};
  return {};
}

std::string Number(double value) {
  // Four significant digits: enough to recognise the value, no float noise, and no exponent
  // for the magnitudes a description holds (16800 kg, not 1.68e+04).
  char text[32];
  const double magnitude = std::abs(value);
  if (magnitude >= 1 && magnitude < 1e7) {
    const int decimals = std::max(0, 3 - static_cast<int>(std::floor(std::log10(magnitude))));
    std::snprintf(text, sizeof text, "%.*f", decimals, value);
    std::string s = text;
    if (s.find('.') != std::string::npos) {
      while (s.back() == '0') s.pop_back();
      if (s.back() == '.') s.pop_back();
    }
    return s;
  }
  std::snprintf(text, sizeof text, "%.4g", value);
  return text;
}

class Checker {
 public:
  explicit Checker(const MachineDescription& m) : m_(m) {}

  void Check(const std::string& key_path, double value, const PlausibleRange& range) {
    const auto dot = key_path.find_last_of('.');
    const std::string key = dot == std::string::npos ? key_path : key_path.substr(dot + 1);
    bool impossible = false;
    const std::string message = PlausibilityMessage(key, value, range, impossible);
    if (message.empty()) return;
    core::Diagnostic d{m_.LocationOf(key_path), key_path, message,
                       impossible ? core::Severity::kError : core::Severity::kWarning};
    (impossible ? findings_.errors : findings_.warnings).push_back(std::move(d));
    if (impossible) flagged_.push_back(key_path);
  }

  bool Flagged(const std::string& key_path) const {
    for (const auto& path : flagged_) {
      if (path == key_path) return true;
    }
    return false;
  }

  void Error(const std::string& key_path, const std::string& message) {
    findings_.errors.push_back({m_.LocationOf(key_path), key_path, message});
  }

  PlausibilityFindings findings_;

 private:
  const MachineDescription& m_;
  std::vector<std::string> flagged_;
};

}  // namespace

std::string PlausibilityMessage(const std::string& key, double value, const PlausibleRange& range,
                                bool& impossible) {
  impossible = false;
  const bool low = range.low > 0 && value < range.low;
  const bool high = value > range.high;
  if (!low && !high) return "";
  impossible = (low && value < range.low / kImpossibleFactor) ||
               (high && value > range.high * kImpossibleFactor);
  const std::string unit = range.unit;
  std::string message = key + " " + Number(value) + (unit.empty() ? "" : " " + unit) + " is " +
                        (impossible ? "impossible" : "implausible") + " for " + range.what + " (" +
                        Number(range.low) + "–" + Number(range.high) + " " + unit + ")";
  for (const Mistake& mistake : MistakesFor(unit)) {
    const double converted = value * mistake.factor;
    if (converted >= range.low && converted <= range.high) {
      return message + ": given in " + mistake.given_in + "? " + Number(converted) + " " + unit;
    }
  }
  return message;
}

PlausibilityFindings CheckPlausibility(const MachineDescription& m) {
  Checker c(m);
  const Chassis& ch = m.chassis;
  c.Check("chassis.operating_mass", ch.operating_mass,
          {500, 1e6, "kg", "an earthmover's operating mass"});
  if (m.kind == MachineKind::kWheelLoader) {
    c.Check("chassis.hinge_to_front_axle", ch.hinge_to_front_axle,
            {0.3, 6, "m", "a hinge-to-axle distance"});
    c.Check("chassis.hinge_to_rear_axle", ch.hinge_to_rear_axle,
            {0.3, 6, "m", "a hinge-to-axle distance"});
    c.Check("chassis.track_width", ch.track_width, {0.8, 6, "m", "a loader's track width"});
    c.Check("chassis.wheel_radius", ch.wheel_radius, {0.2, 2.0, "m", "a loader's wheel radius"});
    c.Check("chassis.max_speed", ch.max_speed, {0.5, 25, "m/s", "a loader's top speed"});
  } else {
    c.Check("chassis.track_gauge", ch.track_gauge, {0.8, 8, "m", "a track gauge"});
    c.Check("chassis.track_length", ch.track_length, {1, 12, "m", "a track length"});
    c.Check("chassis.track_shoe_width", ch.track_shoe_width, {0.2, 2, "m", "a track shoe width"});
  }
  double arm_mass = 0;
  for (std::size_t k = 0; k < m.links.size(); ++k) {
    const std::string path = "arm.links[" + std::to_string(k) + "]";
    c.Check(path + ".length", m.links[k].length, {0.1, 20, "m", "an arm link"});
    c.Check(path + ".mass", m.links[k].mass, {5, 1e5, "kg", "an arm link's mass"});
    arm_mass += m.links[k].mass;
  }
  const Hydraulics& h = m.hydraulics;
  c.Check("hydraulics.pump_pressure_bar", h.pump_pressure / kBar,
          {50, 500, "bar", "a pump pressure"});
  c.Check("hydraulics.tank_pressure_bar", h.tank_pressure / kBar,
          {0, 30, "bar", "a tank (return) pressure"});
  c.Check("hydraulics.oil_bulk_modulus_bar", h.bulk_modulus / kBar,
          {1000, 25000, "bar", "an oil bulk modulus"});
  if (h.pump_max_flow > 0) {
    c.Check("hydraulics.pump_max_flow_lpm", h.pump_max_flow * 60000,
            {10, 3000, "l/min", "a working pump's delivery"});
  }
  for (std::size_t i = 0; i < h.actuators.size(); ++i) {
    const Actuator& a = h.actuators[i];
    const std::string path = "hydraulics.actuators[" + std::to_string(i) + "]";
    if (a.kind == ActuatorKind::kCylinder) {
      c.Check(path + ".bore", a.bore, {0.02, 0.6, "m", "a cylinder bore"});
      c.Check(path + ".rod", a.rod, {0.01, 0.5, "m", "a cylinder rod"});
      c.Check(path + ".stroke", a.stroke, {0.05, 5, "m", "a cylinder stroke"});
      c.Check(path + ".retracted_length", a.retracted_length,
              {0.1, 8, "m", "a cylinder's retracted length"});
      c.Check(path + ".dead_volume", a.dead_volume, {1e-5, 0.2, "m^3", "a chamber's dead volume"});
    }
    c.Check(path + ".relief_pressure_bar", a.relief_pressure / kBar,
            {50, 550, "bar", "a relief pressure"});
    c.Check(path + ".valve.rated_flow_lpm", a.valve.rated_flow / kLitrePerMinute,
            {5, 5000, "l/min", "a valve's rated flow"});
    c.Check(path + ".valve.rated_pressure_drop_bar", a.valve.rated_pressure_drop / kBar,
            {1, 100, "bar", "a valve's rated pressure drop"});
  }
  c.Check("bucket.width", m.bucket.width, {0.3, 8, "m", "a bucket's width"});
  c.Check("bucket.rated_capacity", m.bucket.rated_capacity,
          {0.02, 60, "m^3", "a bucket's capacity"});
  c.Check("bucket.rated_load", m.bucket.rated_load, {20, 1.2e5, "kg", "a bucket's rated load"});
  // The links are part of the operating mass: a machine lighter than its own arm is impossible.
  if (!c.Flagged("chassis.operating_mass") && arm_mass >= ch.operating_mass) {
    c.Error("chassis.operating_mass",
            "operating_mass " + Number(ch.operating_mass) + " kg is less than the arm's links (" +
                Number(arm_mass) + " kg), which are part of it" +
                (arm_mass < ch.operating_mass * 1e3
                     ? ": given in tonnes? " + Number(ch.operating_mass * 1e3) + " kg"
                     : ""));
  }
  return c.findings_;
}

}  // namespace autoshovel::model
