#include "runtime/sensors/rangefinder/scanning_rangefinder.h"

#include <cmath>
#include <stdexcept>

namespace autoshovel::sensors {

ScanningRangefinder::ScanningRangefinder(const ScannerConfig& scanner,
                                         const WaveformConfig& waveform,
                                         const DetectorConfig& detector, const ExitWindow& window)
    : geometry_(scanner), waveform_(waveform), detector_(waveform, detector) {
  set_window(window);
}

void ScanningRangefinder::set_window(const ExitWindow& window) {
  ValidateExitWindow(window);
  window_ = window;
}

std::optional<ScanPulse> ScanningRangefinder::Fire(std::int64_t k, const PanSweep& pan,
                                                   const Eigen::Isometry3d& T_scene_cab,
                                                   const RangefinderScene& scene, Rng& rng) const {
  if (!T_scene_cab.matrix().allFinite()) {
    throw std::invalid_argument("ScanningRangefinder::Fire: T_scene_cab must be finite");
  }
  ScanPulse pulse;
  pulse.ray = geometry_.Ray(k, pan);
  if (!pulse.ray.active) return std::nullopt;
  const Eigen::Vector3d origin = T_scene_cab * pulse.ray.origin_cab;
  const Eigen::Vector3d direction = T_scene_cab.linear() * pulse.ray.direction_cab;
  const RayProfile profile = scene.Trace(origin, direction, waveform_.config().max_range);
  pulse.detection = detector_.Detect(waveform_.Simulate(profile, window_, rng));
  auto point = [&](const std::optional<double>& range) -> std::optional<Eigen::Vector3d> {
    if (!range) return std::nullopt;
    return pulse.ray.origin_cab + *range * pulse.ray.direction_cab;
  };
  pulse.p_cab_first = point(pulse.detection.first_pulse_range);
  pulse.p_cab_last = point(pulse.detection.last_pulse_range);
  pulse.p_cab_trailing = point(pulse.detection.trailing_edge_range);
  return pulse;
}

}  // namespace autoshovel::sensors
