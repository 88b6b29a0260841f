// Scanning the truck from the excavator (excavator seed §2, §4.1, §4.3): one scanning laser
// rangefinder on the upper structure fires its pulses into the simulated yard while the upper
// structure swings and the scanner head pans; the trailing-edge ranges (§3: the detector that
// sees through dust) become world-frame scanlines, one per mirror revolution; truck recognition
// (§4.1) turns them into the bed's pose and size, and the returns inside the recognised bed
// become the dump planner's 15 cm bed height map (§4.3).
//
// Two uses, after §2 (Fig. 4):
// - recognition, on the first pass of each truck: "while the excavator digs its first bucket,
//   the left scanner pans left from the dig face across the truck": the swing holds at the dig
//   and the head pans (PanAcross); where the truck reaches past the pan range the scan carries
//   on while the upper structure swings to the truck (FirstPassScan);
// - bed measurement, on every pass: "the excavator swings back to the next dig point. During
//   this swing, the left scanner pans across the truck to measure the soil distribution": the
//   swing turns and the head counter-pans so that the scan plane crosses the bed at a rate the
//   scanline spacing allows (SwingWithCounterPan).
//
// Scan-plane azimuth. A level scanner's beams at pan p lie in the vertical plane at world
// azimuth heading + swing + p through the scanner: the swing and the pan add. What recognition
// needs is the change of that azimuth per mirror revolution: at most about 1° (tests of truck
// recognition: reliable at 0.6° and 1.0°, 66–96 % found at 1.5°), i.e. 20°/s at the 20 rev/s
// mirror. A swing at working speed (≈ 60°/s) with the head held would space the scanlines 3°
// apart; PanAcross and SwingWithCounterPan choose the pan so that the sum stays in bounds.
//
// Mounts. The description (models/excavators/*.yaml, sensors.lidars) gives each scanner as a
// one-line spinning LiDAR: its z axis the axis the mirror spins about, its x axis the beam at
// the start of the circle. The rangefinder's scanner frame (scanner_geometry.h) has z along the
// pan axis and its mirror circle in the x–z plane, i.e. spinning about −y; so T_cab_scanner =
// T_cab_lidar · Rx(−90°). The shipped excavator_25t's scanners (rpy 90°, 0, 0) are level heads
// at (0.4, ±0.8, 2.6) m. The pan axis and the pan range are not in the description: the pan
// range, rates and active arc are the rangefinder library's (ScannerConfig's defaults).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/model/description.h"
#include "runtime/perception/truck/scanline.h"
#include "runtime/perception/truck/truck_recognition.h"
#include "runtime/planning/dump/bed_height_map.h"
#include "runtime/sensors/rangefinder/dust_monitor.h"
#include "runtime/sensors/rangefinder/rangefinder_scene.h"
#include "runtime/sensors/rangefinder/scanning_rangefinder.h"
#include "runtime/sensors/rng.h"

namespace autoshovel::app {

/// The rangefinder scanner named `lidar_name` in the description (sensors.lidars), with the
/// rangefinder library's timing, active arc and pan range. Throws std::invalid_argument when
/// there is no such LiDAR.
sensors::ScannerConfig ScannerConfigFromDescription(const model::MachineDescription& machine,
                                                    std::string_view lidar_name);

/// The upper structure's swing: hold `start_angle` until `start_time`, turn towards `end_angle`
/// at `rate`, hold `end_angle`. Acceleration phases (a few tenths of a second on a 25 t machine)
/// are not modelled: what matters here is the azimuth swept per mirror revolution at speed.
struct SwingSweep {
  double start_time = 0;   ///< [s]
  double start_angle = 0;  ///< [rad]
  double end_angle = 0;    ///< [rad]
  double rate = 0;         ///< speed, ≥ 0 [rad/s]; 0 only when start == end
};

/// The swing held at `angle`.
SwingSweep HoldSwing(double angle);
/// Swing angle at time t [rad]. Throws std::invalid_argument for a non-finite field, a negative
/// rate, or a zero rate between different angles.
double SwingAt(const SwingSweep& swing, double t);

/// The scan plane's azimuth relative to the base (swing + pan) moving linearly from `from` at
/// the phase's start to `to` at its end: the head servoes its pan against the swing, as the
/// seed's sensor motion planner "controls the panning for both scanners to coordinate scanner
/// and excavator motion" (§2).
struct AzimuthRamp {
  double from = 0;  ///< [rad]
  double to = 0;    ///< [rad]
};

/// What the machine does during one phase of a scan, and when the phase runs.
struct TruckScanMotion {
  SwingSweep swing;
  /// When set, the swing angle at time t [rad] (e.g. the plant's swing joint as it moved);
  /// replaces `swing`.
  std::function<double(double)> swing_profile;
  /// The head's pan, unless `azimuth` is set.
  sensors::PanSweep pan;
  /// When set, pan(t) = azimuth(t) − swing(t), checked pulse by pulse against the scanner's pan
  /// range and rate limit; `pan` is not used.
  std::optional<AzimuthRamp> azimuth;
  double start_time = 0;  ///< first pulse at or after [s]
  double end_time = 0;    ///< pulses strictly before [s]
};

/// The swing held at `swing`, the head panning from `pan_from` to `pan_to` (cab-frame angles
/// about the pan axis [rad]) at `pan_step` per mirror revolution, from `start_time`; the scan
/// ends one revolution after the pan does. Throws std::invalid_argument when the pan leaves the
/// scanner's range, `pan_step` is not positive, or the rate exceeds the pan rate limit.
TruckScanMotion PanAcross(const sensors::ScannerConfig& scanner, double swing, double pan_from,
                          double pan_to, double pan_step, double start_time = 0.0);

/// The swing turning from `swing_from` to `swing_to` at `swing_rate` from `start_time`, while
/// the head pans so that the scan plane's azimuth relative to the base moves from
/// `azimuth_from` to `azimuth_to` over the same time (an AzimuthRamp; with the constant-rate
/// swing the pan runs from azimuth_from − swing_from to azimuth_to − swing_to at a constant
/// rate). The scan covers the swing. Throws std::invalid_argument when the pan leaves the
/// scanner's range or exceeds its rate limit, or the swing rate is not positive. To follow the
/// machine's real swing, set `swing_profile` on the result: the pan then follows it.
TruckScanMotion SwingWithCounterPan(const sensors::ScannerConfig& scanner, double swing_from,
                                    double swing_to, double swing_rate, double azimuth_from,
                                    double azimuth_to, double start_time = 0.0);

/// Largest change of the scan plane's azimuth per mirror revolution for which truck recognition
/// was measured reliable (docs/truck_recognition.md: all trucks found at 0.6° and 1.0°) [rad].
inline constexpr double kMaxRecognitionPanStep = 1.0 * std::numbers::pi / 180.0;

/// The first pass's recognition scan in the seed's order (§2, Fig. 4; §4.1), two phases:
/// 1. while the first bucket is dug (swing held at `dig_swing`), the head pans from the dig face
///    (pan 0) towards the truck's side to the end of its pan range (±120°) at `pan_step` per
///    revolution;
/// 2. while the upper structure swings to the truck (`dig_swing` → `truck_swing` at
///    `swing_rate`), the head counter-pans so that the scan plane carries on from there to
///    `final_azimuth_offset` from the dig swing (AzimuthRamp): the swing does the rest of the
///    sweep that the pan range cannot.
/// Why the second phase: from the left scanner at (0.4, 0.8, 2.6) m a truck abeam of the swing
/// axis reaches past 120° (its near wall's rear end at 134° for the 20 t tipper centred abeam,
/// 141° 1 m aft of it), and recognition then takes the last scanline for the bed's end. With
/// 155°, all three truck classes centred from 1 m aft of abeam to 1.5 m ahead (cab forward or
/// back, turned by 10°) were recognised (docs/truck_scan.md).
/// Throws std::invalid_argument as PanAcross and SwingWithCounterPan do, and when the second
/// phase would sweep more than kMaxRecognitionPanStep per revolution (swing slower).
std::vector<TruckScanMotion> FirstPassScan(const sensors::ScannerConfig& scanner, double dig_swing,
                                           double truck_swing, double swing_rate,
                                           double final_azimuth_offset = 155.0 * std::numbers::pi /
                                                                         180.0,
                                           double pan_step = 0.8 * std::numbers::pi / 180.0,
                                           double start_time = 0.0);

/// The scanlines of one scan, in the world frame.
struct TruckScan {
  std::vector<perception::Scanline> scanlines;
  /// World azimuth of each scanline's scan plane at its middle pulse [rad], unwrapped.
  std::vector<double> scanline_azimuths;
  std::int64_t pulses_fired = 0;   ///< inside the active arc: each one a simulated waveform
  std::int64_t points = 0;         ///< pulses with a trailing-edge range
  std::int64_t dust_evidence = 0;  ///< pulses with multiple or extended returns (§3)
  double max_azimuth_step = 0;     ///< largest |Δ azimuth| between consecutive scanlines [rad]
  /// §3's dust warning over the scan (sensors::DustMonitor fed every fired pulse): whether it
  /// came on, and the smallest speed scale it recommended (1: clear air throughout).
  bool dust_warning = false;
  double min_speed_scale = 1.0;
};

/// Whether the scan swept past every corner of the recognised body: for each corner of the
/// opening pushed `outset` outwards along both bed axes (the walls' outer ends), some scanline
/// passed it by more than `margin` on either side (bearing from that scanline's beam origin,
/// against its scan plane's azimuth). A truck reaching beyond the pan range is otherwise
/// "recognised" with its far end at the last scanline: measured 1.1–1.3 m short on the 20 t
/// and 38 t bodies 1 m aft of abeam. `why`, when given, names the first corner not covered.
bool BedCoveredByScan(const perception::TruckRecognitionResult& truck, const TruckScan& scan,
                      double outset = 0.1, double margin = 1.0 * std::numbers::pi / 180.0,
                      std::string* why = nullptr);

/// The bed map of a recognised truck from the returns of a scan (§4.3): every usable return is
/// binned by BedHeightMap::FromWorldPoints in the bed-corner frame (origin at the rear-right
/// inside corner on the rim, z up: heights are negative below the rim, −wall_height on an empty
/// floor). Unless `config` says otherwise, returns more than 0.3 m below the deepest possible
/// floor (a wall height under the rim, or the model's 2 m where the floor was not seen) or more
/// than 1 m above the rim (the headboard's cab guard, the boom) are dropped. Throws
/// std::invalid_argument when `truck.found` is false.
planning::BedHeightMap BedMapFromScan(const perception::TruckRecognitionResult& truck,
                                      const std::vector<perception::Scanline>& scanlines,
                                      std::optional<planning::BedHeightMapConfig> config = {});

/// Where the truck's ground lies relative to the ground the excavator stands on.
///
/// Truck recognition takes the level region with the most returns for the ground the truck
/// stands on (planar_regions.h: "the scan circle hits it in every scanline"). That holds when
/// truck and excavator share the ground. In the seed's setting (§1: the excavator "sits atop a
/// bench and loads material into trucks" parked below it) the bench top between the machine
/// and the crest is hit in every scanline instead, and the haul road is seen only beyond the
/// truck, far and sparse: measured on the 20 t tipper 2 m below the bench, the bench gave
/// 11 479 returns, the road 765 + 723 in two regions, and the rim came out 0.7 m "above the
/// ground", outside the model's 1.2–4.8 m, so no truck was found. Below the bench, the returns
/// of level surfaces at the machine's own standing level are therefore withheld from
/// recognition (WithoutStandingLevel); the bed map still uses every return.
enum class TruckGround {
  kMachineLevel,  ///< the truck stands on the excavator's ground: every return is used
  kBelowMachine,  ///< the truck stands below the excavator's bench
  kEither,        ///< try kMachineLevel, then kBelowMachine
};

/// The scanlines without the returns on level ground at the machine's standing level: returns
/// within `tolerance` of the base frame's z = 0 plane whose neighbours in the scanline lie level
/// with them (rising less than 10° from them; neighbours more than 1 m away, across a range
/// jump, are not asked). Wall returns crossing that height are kept: their neighbours lie above
/// and below them. Withheld returns stay
/// in the scanline as invalid readings, so the mirror order is kept.
std::vector<perception::Scanline> WithoutStandingLevel(
    const std::vector<perception::Scanline>& scanlines, const Eigen::Isometry3d& T_world_base,
    double tolerance = 0.15);

/// The scanner's detection settings and the recogniser's parameters.
struct TruckScannerConfig {
  sensors::ScannerConfig scanner;
  sensors::WaveformConfig waveform;
  sensors::ExitWindow window = sensors::CleanWindow();
  double threshold_snr = 6.0;  ///< detection threshold over the smoothed noise σ
  perception::TruckRecognitionParams recognition;
  TruckGround truck_ground = TruckGround::kEither;
  double standing_level_tolerance = 0.15;  ///< see WithoutStandingLevel [m]
  double bed_cell_size = 0.15;             ///< §4.3 [m]
  sensors::DustMonitorConfig dust;         ///< §3's warning (TruckScan::dust_warning)
};

/// Everything one recognition scan produced.
struct TruckScanReport {
  TruckScan scan;
  perception::TruckRecognitionResult recognition;
  /// Whether the recognised truck was found with the standing level withheld (TruckGround).
  bool truck_below_machine = false;
  /// The bed map of the recognised bed from the same scan; empty when nothing was found.
  std::optional<planning::BedHeightMap> bed_map;
};

class TruckScanner {
 public:
  /// Throws std::invalid_argument for invalid scanner, waveform, detector or recognition
  /// parameters.
  explicit TruckScanner(const TruckScannerConfig& config);

  /// Fires every pulse of `phases` (in time order, not overlapping) with the machine's base at
  /// T_world_base (the upper structure at T_world_base · Rz(swing)): one scanline per mirror
  /// revolution, also across phase boundaries; the trailing-edge returns as world points,
  /// misses kept as invalid points. Throws std::invalid_argument for no phase or an invalid one
  /// (pan out of range or too fast, end before start, phases out of order, non-finite values).
  TruckScan Scan(const sensors::RangefinderScene& scene, const Eigen::Isometry3d& T_world_base,
                 std::span<const TruckScanMotion> phases, sensors::Rng& rng) const;
  TruckScan Scan(const sensors::RangefinderScene& scene, const Eigen::Isometry3d& T_world_base,
                 const TruckScanMotion& motion, sensors::Rng& rng) const;

  /// Scan, recognise (§4.1) and map the recognised bed (§4.3). A bed that is not covered by
  /// the scan (BedCoveredByScan) is not reported: its far end would be the last scanline.
  TruckScanReport ScanAndRecognize(const sensors::RangefinderScene& scene,
                                   const Eigen::Isometry3d& T_world_base,
                                   std::span<const TruckScanMotion> phases,
                                   sensors::Rng& rng) const;
  TruckScanReport ScanAndRecognize(const sensors::RangefinderScene& scene,
                                   const Eigen::Isometry3d& T_world_base,
                                   const TruckScanMotion& motion, sensors::Rng& rng) const;

  /// Recognition (§4.1) and the bed map (§4.3) of a scan already made: what ScanAndRecognize
  /// does after Scan. A recorded scan replays through this (autoshovel replay).
  TruckScanReport Recognize(TruckScan scan, const Eigen::Isometry3d& T_world_base) const;

  /// The bed map (§4.3) of a recognised truck from a scan already made. Throws
  /// std::invalid_argument when `truck.found` is false.
  planning::BedHeightMap BedMap(const TruckScan& scan,
                                const perception::TruckRecognitionResult& truck) const;

  /// The bed map of an already recognised truck from a new scan (the swing back of each pass).
  /// `scan`, when given, receives the scan itself (its dust warning, for one).
  planning::BedHeightMap MeasureBed(const sensors::RangefinderScene& scene,
                                    const Eigen::Isometry3d& T_world_base,
                                    const TruckScanMotion& motion,
                                    const perception::TruckRecognitionResult& truck,
                                    sensors::Rng& rng, TruckScan* scan = nullptr) const;

  const sensors::ScanningRangefinder& rangefinder() const { return rangefinder_; }
  const perception::TruckRecognizer& recognizer() const { return recognizer_; }
  const TruckScannerConfig& config() const { return config_; }

 private:
  TruckScannerConfig config_;
  sensors::ScanningRangefinder rangefinder_;
  perception::TruckRecognizer recognizer_;
};

}  // namespace autoshovel::app
