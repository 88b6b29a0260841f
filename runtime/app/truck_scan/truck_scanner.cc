#include "runtime/app/truck_scan/truck_scanner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include "runtime/sensors/rangefinder/pulse_detection.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::app {
namespace {

constexpr double kPi = std::numbers::pi;

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

std::string Deg(double angle) {
  std::ostringstream out;
  out << angle * 180.0 / kPi << "°";
  return out.str();
}

double WrapToPi(double a) { return std::remainder(a, 2.0 * kPi); }

// Azimuth of R·v in the horizontal plane [rad].
double YawOf(const Eigen::Matrix3d& R, const Eigen::Vector3d& v) {
  const Eigen::Vector3d d = R * v;
  return std::atan2(d.y(), d.x());
}

// The dump planner's bed-map settings for a recognised truck: §4.3's cells, returns from just
// below the deepest possible floor to 1 m above the rim.
planning::BedHeightMapConfig BedMapConfigFor(const perception::TruckRecognitionResult& truck,
                                             double max_wall_height, double cell_size) {
  planning::BedHeightMapConfig config;
  config.cell_size_m = cell_size;
  const double depth =
      std::isfinite(truck.dimensions.wall_height) ? truck.dimensions.wall_height : max_wall_height;
  config.min_height_m = -depth - 0.3;
  config.max_height_m = 1.0;
  return config;
}

// The step from one return to its neighbour in the scanline: a jump (more than 1 m: another
// surface, says nothing), level (rising less than 10°) or steep.
enum class Step { kJump, kLevel, kSteep };
Step Classify(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  if ((b - a).norm() > 1.0) return Step::kJump;
  const double horizontal = (b - a).head<2>().norm();
  return std::abs(b.z() - a.z()) <= std::tan(10.0 * kPi / 180.0) * horizontal ? Step::kLevel
                                                                              : Step::kSteep;
}

}  // namespace

std::vector<perception::Scanline> WithoutStandingLevel(
    const std::vector<perception::Scanline>& scanlines, const Eigen::Isometry3d& T_world_base,
    double tolerance) {
  Require(std::isfinite(tolerance) && tolerance > 0,
          "WithoutStandingLevel: tolerance must be finite and positive");
  Require(T_world_base.matrix().allFinite(), "WithoutStandingLevel: T_world_base must be finite");
  const Eigen::Isometry3d T_base_world = T_world_base.inverse();
  std::vector<perception::Scanline> out = scanlines;
  for (std::size_t l = 0; l < scanlines.size(); ++l) {
    const std::vector<perception::ScanPoint>& in = scanlines[l].points;
    for (std::size_t i = 0; i < in.size(); ++i) {
      if (!perception::IsUsable(in[i])) continue;
      if (std::abs((T_base_world * in[i].p_world).z()) >= tolerance) continue;
      // Every near neighbour must lie level with it, and there must be one.
      int level = 0, steep = 0;
      for (const std::size_t j : {i - 1, i + 1}) {
        if (j >= in.size() || !perception::IsUsable(in[j])) continue;
        const Step step = Classify(in[i].p_world, in[j].p_world);
        if (step == Step::kLevel) ++level;
        if (step == Step::kSteep) ++steep;
      }
      if (level > 0 && steep == 0) out[l].points[i].valid = false;
    }
  }
  return out;
}

sensors::ScannerConfig ScannerConfigFromDescription(const model::MachineDescription& machine,
                                                    std::string_view lidar_name) {
  if (const model::Lidar* lidar = machine.FindLidar(lidar_name)) {
    sensors::ScannerConfig config;  // timing, active arc, pan range: the library's
    // The LiDAR spins about its z; the rangefinder's mirror circle lies in its scanner frame's
    // x–z plane (spinning about −y, z the pan axis): scanner = lidar turned by −90° about x.
    config.T_cab_scanner = sensors::PoseToIsometry(lidar->pose) *
                           Eigen::AngleAxisd(-0.5 * kPi, Eigen::Vector3d::UnitX());
    return config;
  }
  std::string names;
  for (const model::Lidar& lidar : machine.sensors.lidars) names += " '" + lidar.name + "'";
  throw std::invalid_argument("ScannerConfigFromDescription: machine '" + machine.name +
                              "' has no LiDAR named '" + std::string(lidar_name) +
                              "'; it has:" + (names.empty() ? std::string(" none") : names));
}

SwingSweep HoldSwing(double angle) { return SwingSweep{0.0, angle, angle, 0.0}; }

double SwingAt(const SwingSweep& swing, double t) {
  Require(std::isfinite(swing.start_time) && std::isfinite(swing.start_angle) &&
              std::isfinite(swing.end_angle) && std::isfinite(swing.rate) && std::isfinite(t),
          "SwingSweep: every field and the time must be finite");
  Require(swing.rate >= 0, "SwingSweep: rate must be >= 0, got " + Deg(swing.rate) + "/s");
  Require(swing.rate > 0 || swing.start_angle == swing.end_angle,
          "SwingSweep: a swing between different angles needs a rate > 0");
  if (t <= swing.start_time || swing.start_angle == swing.end_angle) return swing.start_angle;
  const double span = swing.end_angle - swing.start_angle;
  const double travelled = swing.rate * (t - swing.start_time);
  if (travelled >= std::abs(span)) return swing.end_angle;
  return swing.start_angle + std::copysign(travelled, span);
}

TruckScanMotion PanAcross(const sensors::ScannerConfig& scanner, double swing, double pan_from,
                          double pan_to, double pan_step, double start_time) {
  Require(std::isfinite(pan_step) && pan_step > 0,
          "PanAcross: pan_step must be finite and positive, got " + Deg(pan_step));
  Require(std::isfinite(start_time), "PanAcross: start_time must be finite");
  TruckScanMotion motion;
  motion.swing = HoldSwing(swing);
  motion.pan = {start_time, pan_from, pan_to, pan_step * scanner.mirror_rate};
  sensors::ScannerGeometry(scanner).Validate(motion.pan);  // range and rate limit
  motion.start_time = start_time;
  motion.end_time =
      start_time + std::abs(pan_to - pan_from) / motion.pan.rate + 1.0 / scanner.mirror_rate;
  return motion;
}

TruckScanMotion SwingWithCounterPan(const sensors::ScannerConfig& scanner, double swing_from,
                                    double swing_to, double swing_rate, double azimuth_from,
                                    double azimuth_to, double start_time) {
  Require(
      std::isfinite(swing_rate) && swing_rate > 0,
      "SwingWithCounterPan: swing_rate must be finite and positive, got " + Deg(swing_rate) + "/s");
  Require(swing_from != swing_to, "SwingWithCounterPan: the swing must turn");
  const double duration = std::abs(swing_to - swing_from) / swing_rate;
  TruckScanMotion motion;
  motion.swing = {start_time, swing_from, swing_to, swing_rate};
  const double pan_from = azimuth_from - swing_from;
  const double pan_to = azimuth_to - swing_to;
  // The same pan as a sweep, for its range and rate check.
  motion.pan = {start_time, pan_from, pan_to, std::abs(pan_to - pan_from) / duration};
  sensors::ScannerGeometry(scanner).Validate(motion.pan);
  motion.azimuth = AzimuthRamp{azimuth_from, azimuth_to};
  motion.start_time = start_time;
  motion.end_time = start_time + duration;
  return motion;
}

std::vector<TruckScanMotion> FirstPassScan(const sensors::ScannerConfig& scanner, double dig_swing,
                                           double truck_swing, double swing_rate,
                                           double final_azimuth_offset, double pan_step,
                                           double start_time) {
  Require(std::isfinite(dig_swing) && std::isfinite(truck_swing) && truck_swing != dig_swing,
          "FirstPassScan: the truck must lie at another swing angle than the dig");
  Require(std::isfinite(final_azimuth_offset) && final_azimuth_offset > 0,
          "FirstPassScan: final_azimuth_offset must be finite and positive");
  const double side = truck_swing > dig_swing ? 1.0 : -1.0;
  const double pan_end = side > 0 ? scanner.pan_max : scanner.pan_min;
  std::vector<TruckScanMotion> phases{
      PanAcross(scanner, dig_swing, 0.0, pan_end, pan_step, start_time)};
  const double azimuth_from = dig_swing + pan_end;
  const double azimuth_to = dig_swing + side * final_azimuth_offset;
  if (side * (azimuth_to - azimuth_from) <= 0) return phases;
  TruckScanMotion swing = SwingWithCounterPan(scanner, dig_swing, truck_swing, swing_rate,
                                              azimuth_from, azimuth_to, phases[0].end_time);
  const double step = std::abs(azimuth_to - azimuth_from) / (swing.end_time - swing.start_time) /
                      scanner.mirror_rate;
  Require(step <= kMaxRecognitionPanStep * 1.0001,
          "FirstPassScan: during the swing the scan plane would move " + Deg(step) +
              " per revolution, more than " + Deg(kMaxRecognitionPanStep) + ": swing slower than " +
              Deg(swing_rate) + "/s");
  phases.push_back(std::move(swing));
  return phases;
}

bool BedCoveredByScan(const perception::TruckRecognitionResult& truck, const TruckScan& scan,
                      double outset, double margin, std::string* why) {
  Require(std::isfinite(outset) && outset >= 0 && std::isfinite(margin) && margin >= 0,
          "BedCoveredByScan: outset and margin must be finite and >= 0");
  Require(scan.scanline_azimuths.size() == scan.scanlines.size(),
          "BedCoveredByScan: the scan's azimuths do not match its scanlines");
  if (!truck.found) return false;
  static constexpr const char* kCornerNames[4] = {"front-left", "front-right", "rear-right",
                                                  "rear-left"};
  static constexpr double kSigns[4][2] = {{1, 1}, {1, -1}, {-1, -1}, {-1, 1}};
  const Eigen::Matrix3d R = truck.T_world_bed.linear();
  for (int c = 0; c < 4; ++c) {
    const Eigen::Vector3d p = truck.p_world_corners[c] +
                              R * Eigen::Vector3d(kSigns[c][0] * outset, kSigns[c][1] * outset, 0);
    bool left = false, right = false;
    for (std::size_t l = 0; l < scan.scanlines.size() && !(left && right); ++l) {
      const Eigen::Vector2d d = (p - scan.scanlines[l].p_world_sensor).head<2>();
      const double bearing = WrapToPi(std::atan2(d.y(), d.x()) - scan.scanline_azimuths[l]);
      if (std::abs(bearing) > 0.5 * kPi) continue;  // behind this scan plane's beam
      if (bearing > margin) left = true;
      if (bearing < -margin) right = true;
    }
    if (!(left && right)) {
      if (why != nullptr) {
        *why = std::string("the bed's ") + kCornerNames[c] +
               " corner lies at the edge of the scan: the pan must sweep past it";
      }
      return false;
    }
  }
  return true;
}

planning::BedHeightMap BedMapFromScan(const perception::TruckRecognitionResult& truck,
                                      const std::vector<perception::Scanline>& scanlines,
                                      std::optional<planning::BedHeightMapConfig> config) {
  Require(truck.found, "BedMapFromScan: no truck was recognised (" + truck.reason + ")");
  if (!config) {
    config = BedMapConfigFor(truck, perception::TruckBedModel{}.wall_height.max,
                             planning::BedHeightMapConfig{}.cell_size_m);
  }
  std::vector<Eigen::Vector3d> p_world;
  for (const perception::Scanline& line : scanlines) {
    for (const perception::ScanPoint& point : line.points) {
      if (perception::IsUsable(point)) p_world.push_back(point.p_world);
    }
  }
  const planning::BedGeometry bed{truck.dimensions.length, truck.dimensions.width};
  return planning::BedHeightMap::FromWorldPoints(bed, truck.T_world_bed_corner(), p_world, *config);
}

TruckScanner::TruckScanner(const TruckScannerConfig& config)
    : config_(config),
      rangefinder_(config.scanner, config.waveform,
                   sensors::MakeDetectorConfig(config.waveform, config.threshold_snr),
                   config.window),
      recognizer_(config.recognition) {
  sensors::DustMonitor check_dust_config(config.dust);  // throws on a bad dust configuration
  Require(std::isfinite(config.bed_cell_size) && config.bed_cell_size > 0,
          "TruckScannerConfig: bed_cell_size must be finite and positive");
  Require(std::isfinite(config.standing_level_tolerance) && config.standing_level_tolerance > 0,
          "TruckScannerConfig: standing_level_tolerance must be finite and positive");
}

TruckScan TruckScanner::Scan(const sensors::RangefinderScene& scene,
                             const Eigen::Isometry3d& T_world_base, const TruckScanMotion& motion,
                             sensors::Rng& rng) const {
  return Scan(scene, T_world_base, std::span<const TruckScanMotion>(&motion, 1), rng);
}

TruckScan TruckScanner::Scan(const sensors::RangefinderScene& scene,
                             const Eigen::Isometry3d& T_world_base,
                             std::span<const TruckScanMotion> phases, sensors::Rng& rng) const {
  Require(T_world_base.matrix().allFinite(), "TruckScanner::Scan: T_world_base must be finite");
  Require(!phases.empty(), "TruckScanner::Scan: no phase to scan");
  const sensors::ScannerGeometry& geometry = rangefinder_.geometry();
  for (std::size_t i = 0; i < phases.size(); ++i) {
    const TruckScanMotion& m = phases[i];
    Require(std::isfinite(m.start_time) && std::isfinite(m.end_time) && m.end_time > m.start_time,
            "TruckScanner::Scan: phase " + std::to_string(i) + " must end after it starts");
    Require(i == 0 || m.start_time >= phases[i - 1].end_time,
            "TruckScanner::Scan: phase " + std::to_string(i) + " starts before phase " +
                std::to_string(i - 1) + " ends");
    if (!m.azimuth) geometry.Validate(m.pan);
    Require(!m.azimuth || (std::isfinite(m.azimuth->from) && std::isfinite(m.azimuth->to)),
            "TruckScanner::Scan: phase " + std::to_string(i) + ": the azimuth must be finite");
    if (!m.swing_profile) SwingAt(m.swing, m.start_time);  // validates the swing
  }

  const sensors::ScannerConfig& sc = geometry.config();
  // Mirror revolution of time t: the circle wraps at elevation ±π (straight behind), so the
  // active arc, which lies in front, never straddles two revolutions.
  const auto revolution = [&](double t) {
    return static_cast<std::int64_t>(
        std::floor(sc.mirror_rate * t + (sc.mirror_phase + kPi) / (2.0 * kPi)));
  };

  TruckScan scan;
  sensors::DustMonitor dust(config_.dust);
  std::int64_t current_revolution = 0;
  bool open = false;
  Eigen::Vector3d origin_sum = Eigen::Vector3d::Zero();
  std::vector<double> azimuths;  // of the current scanline's pulses
  const auto close = [&]() {
    if (!open) return;
    perception::Scanline& line = scan.scanlines.back();
    line.p_world_sensor = origin_sum / static_cast<double>(line.points.size());
    scan.scanline_azimuths.push_back(azimuths[azimuths.size() / 2]);
    open = false;
  };

  // The previous fired pulse's pan, for the rate check.
  double last_pan = 0, last_pan_time = -std::numeric_limits<double>::infinity();
  for (const TruckScanMotion& motion : phases) {
    for (std::int64_t k = geometry.FirstPulseAtOrAfter(motion.start_time);; ++k) {
      const double t = geometry.PulseTime(k);
      if (t >= motion.end_time) break;
      if (!geometry.InActiveArc(geometry.ElevationAt(t))) continue;
      const double swing =
          motion.swing_profile ? motion.swing_profile(t) : SwingAt(motion.swing, t);
      Require(std::isfinite(swing),
              "TruckScanner::Scan: the swing profile gave a non-finite "
              "angle at t = " +
                  std::to_string(t) + " s");
      sensors::PanSweep pan = motion.pan;
      double p = 0;
      if (motion.azimuth) {
        const double s = (t - motion.start_time) / (motion.end_time - motion.start_time);
        p = motion.azimuth->from + s * (motion.azimuth->to - motion.azimuth->from) - swing;
        Require(p >= sc.pan_min && p <= sc.pan_max,
                "TruckScanner::Scan: the pan that holds the azimuth, " + Deg(p) +
                    " at t = " + std::to_string(t) + " s, is outside the pan range [" +
                    Deg(sc.pan_min) + ", " + Deg(sc.pan_max) + "]");
        pan = sensors::HoldPan(p);
      } else {
        p = geometry.PanAt(motion.pan, t);
      }
      // Within a sweep the rate is checked by Validate; this also catches a servoed pan that
      // cannot keep up and a jump between phases.
      Require(std::abs(p - last_pan) <= sc.pan_rate_limit * (t - last_pan_time) * 1.001 + 1e-9,
              "TruckScanner::Scan: the pan moves at " +
                  Deg(std::abs(p - last_pan) / (t - last_pan_time)) + "/s at t = " +
                  std::to_string(t) + " s, above the limit " + Deg(sc.pan_rate_limit) + "/s");
      last_pan = p;
      last_pan_time = t;
      const Eigen::Isometry3d T_world_cab =
          T_world_base * Eigen::AngleAxisd(swing, Eigen::Vector3d::UnitZ());
      const std::optional<sensors::ScanPulse> pulse =
          rangefinder_.Fire(k, pan, T_world_cab, scene, rng);
      if (!pulse) continue;
      ++scan.pulses_fired;
      const std::int64_t rev = revolution(t);
      if (!open || rev != current_revolution) {
        close();
        scan.scanlines.emplace_back();
        origin_sum.setZero();
        azimuths.clear();
        current_revolution = rev;
        open = true;
      }
      perception::ScanPoint point;
      if (pulse->p_cab_trailing) {
        point.p_world = T_world_cab * *pulse->p_cab_trailing;
        point.valid = true;
        ++scan.points;
      }
      if (pulse->detection.DustEvidence()) ++scan.dust_evidence;
      dust.Add(t, pulse->detection);
      scan.dust_warning = scan.dust_warning || dust.warning();
      scan.min_speed_scale = std::min(scan.min_speed_scale, dust.speed_scale());
      scan.scanlines.back().points.push_back(point);
      origin_sum += T_world_cab * pulse->ray.origin_cab;
      // The scan plane's azimuth: the horizontal direction of the beam at elevation 0.
      azimuths.push_back(
          YawOf(T_world_cab.linear() * sc.T_cab_scanner.linear(),
                Eigen::Vector3d(std::cos(pulse->ray.pan), std::sin(pulse->ray.pan), 0.0)));
    }
  }
  close();

  // Unwrap the azimuths so that steps are differences.
  for (std::size_t i = 1; i < scan.scanline_azimuths.size(); ++i) {
    const double step = WrapToPi(scan.scanline_azimuths[i] - scan.scanline_azimuths[i - 1]);
    scan.scanline_azimuths[i] = scan.scanline_azimuths[i - 1] + step;
    scan.max_azimuth_step = std::max(scan.max_azimuth_step, std::abs(step));
  }
  return scan;
}

TruckScanReport TruckScanner::ScanAndRecognize(const sensors::RangefinderScene& scene,
                                               const Eigen::Isometry3d& T_world_base,
                                               const TruckScanMotion& motion,
                                               sensors::Rng& rng) const {
  return ScanAndRecognize(scene, T_world_base, std::span<const TruckScanMotion>(&motion, 1), rng);
}

TruckScanReport TruckScanner::ScanAndRecognize(const sensors::RangefinderScene& scene,
                                               const Eigen::Isometry3d& T_world_base,
                                               std::span<const TruckScanMotion> phases,
                                               sensors::Rng& rng) const {
  return Recognize(Scan(scene, T_world_base, phases, rng), T_world_base);
}

TruckScanReport TruckScanner::Recognize(TruckScan scan,
                                        const Eigen::Isometry3d& T_world_base) const {
  TruckScanReport report;
  report.scan = std::move(scan);
  if (config_.truck_ground != TruckGround::kBelowMachine) {
    report.recognition = recognizer_.Recognize(report.scan.scanlines);
  }
  if (!report.recognition.found && config_.truck_ground != TruckGround::kMachineLevel) {
    perception::TruckRecognitionResult below = recognizer_.Recognize(WithoutStandingLevel(
        report.scan.scanlines, T_world_base, config_.standing_level_tolerance));
    if (below.found || config_.truck_ground == TruckGround::kBelowMachine) {
      report.recognition = std::move(below);
      report.truck_below_machine = report.recognition.found;
    }
  }
  std::string why;
  if (report.recognition.found &&
      !BedCoveredByScan(report.recognition, report.scan, 0.1, 1.0 * kPi / 180.0, &why)) {
    report.recognition.found = false;
    report.recognition.reason = why;
    report.truck_below_machine = false;
  }
  if (report.recognition.found) report.bed_map = BedMap(report.scan, report.recognition);
  return report;
}

planning::BedHeightMap TruckScanner::MeasureBed(const sensors::RangefinderScene& scene,
                                                const Eigen::Isometry3d& T_world_base,
                                                const TruckScanMotion& motion,
                                                const perception::TruckRecognitionResult& truck,
                                                sensors::Rng& rng, TruckScan* scan_out) const {
  Require(truck.found, "TruckScanner::MeasureBed: no truck was recognised (" + truck.reason + ")");
  TruckScan scan = Scan(scene, T_world_base, motion, rng);
  planning::BedHeightMap map = BedMap(scan, truck);
  if (scan_out) *scan_out = std::move(scan);
  return map;
}

planning::BedHeightMap TruckScanner::BedMap(const TruckScan& scan,
                                            const perception::TruckRecognitionResult& truck) const {
  Require(truck.found, "TruckScanner::BedMap: no truck was recognised (" + truck.reason + ")");
  return BedMapFromScan(
      truck, scan.scanlines,
      BedMapConfigFor(truck, config_.recognition.model.wall_height.max, config_.bed_cell_size));
}

}  // namespace autoshovel::app
