#include "runtime/plant/fault_spec.h"

#include <algorithm>
#include <numbers>

#include "runtime/core/diagnostics.h"
#include "runtime/core/yaml_reader.h"

namespace autoshovel::plant {

const char* ToString(FaultKind kind) {
  switch (kind) {
    case FaultKind::kLidarDropout:
      return "lidar_dropout";
    case FaultKind::kCameraBlackout:
      return "camera_blackout";
    case FaultKind::kLocalisationJump:
      return "localisation_jump";
    case FaultKind::kStuckValve:
      return "stuck_valve";
    case FaultKind::kMaterialMistyped:
      return "material_mistyped";
    case FaultKind::kPersonEntersPath:
      return "person_enters_path";
    case FaultKind::kLidarDeadSector:
      return "lidar_dead_sector";
    case FaultKind::kCameraLensDirt:
      return "camera_lens_dirt";
    case FaultKind::kImuBiasDrift:
      return "imu_bias_drift";
    case FaultKind::kImuStuck:
      return "imu_stuck";
    case FaultKind::kEncoderNoise:
      return "encoder_noise";
    case FaultKind::kHydraulicDelayDrift:
      return "hydraulic_delay_drift";
    case FaultKind::kTimestampsOutOfOrder:
      return "timestamps_out_of_order";
  }
  return "?";
}

bool FaultSpec::InCycle(int cycle) const {
  return cycles.empty() || std::find(cycles.begin(), cycles.end(), cycle) != cycles.end();
}

bool FaultSpec::ActiveAt(int cycle, double t) const {
  return InCycle(cycle) && t >= start_s && t < start_s + duration_s;
}

std::vector<FaultSpec> ReadFaults(core::MapReader& root) {
  std::vector<FaultSpec> faults;
  // In FaultKind order.
  const std::vector<std::string> kinds = {
      "lidar_dropout",          "camera_blackout",    "localisation_jump", "stuck_valve",
      "material_mistyped",      "person_enters_path", "lidar_dead_sector", "camera_lens_dirt",
      "imu_bias_drift",         "imu_stuck",          "encoder_noise",     "hydraulic_delay_drift",
      "timestamps_out_of_order"};
  for (core::MapReader& entry : root.MapList("faults", /*required=*/false)) {
    FaultSpec f;
    const core::SourceLocation at = entry.location();
    f.where = at.file + ":" + std::to_string(at.line);
    const std::string kind = entry.Enum("kind", kinds);
    for (std::size_t k = 0; k < kinds.size(); ++k) {
      if (kind == kinds[k]) f.kind = static_cast<FaultKind>(k);
    }
    f.start_s = entry.Number("start_s", core::NumberRule::NonNegative("s"), 0.0);
    if (entry.Has("duration_s")) {
      f.duration_s = entry.Number("duration_s", core::NumberRule::Positive("s"));
    }
    if (entry.Has("cycles")) {
      const std::optional<YAML::Node> list = entry.Raw("cycles", true);
      if (list && list->IsSequence()) {
        for (const YAML::Node& item : *list) {
          try {
            const int c = item.as<int>();
            if (c < 0) throw YAML::Exception(item.Mark(), "negative");
            f.cycles.push_back(c);
          } catch (const YAML::Exception&) {
            entry.Error("cycles", "must list cycle indices >= 0");
            break;
          }
        }
      } else {
        entry.Error("cycles", "must be a list of cycle indices, e.g. [0, 2]");
      }
    }
    switch (f.kind) {
      case FaultKind::kLocalisationJump: {
        const auto offset = entry.Numbers<2>("offset_m", core::NumberRule::Any("m"));
        f.offset_m = {offset[0], offset[1]};
        f.heading_rad =
            entry.AngleDeg("heading_deg", core::NumberRule::Closed(-180, 180, "deg"), 0.0);
        break;
      }
      case FaultKind::kStuckValve:
        f.joint = entry.Enum("joint", {"boom", "bucket"});
        break;
      case FaultKind::kMaterialMistyped:
        f.reported = entry.String("reported");
        break;
      case FaultKind::kPersonEntersPath:
        f.ahead_m = entry.Number("ahead_m", core::NumberRule::Positive("m"));
        break;
      case FaultKind::kLidarDeadSector: {
        f.lidar = entry.String("lidar");
        const auto sector =
            entry.Numbers<2>("sector_deg", core::NumberRule::Closed(-180, 180, "deg"));
        f.sector_rad = {sector[0] * std::numbers::pi / 180, sector[1] * std::numbers::pi / 180};
        if (!(sector[0] < sector[1]))
          entry.Error("sector_deg", "must be [from, to] with from < to");
        break;
      }
      case FaultKind::kCameraLensDirt: {
        const auto center = entry.Numbers<2>("center", core::NumberRule::Closed(0, 1, "-"));
        f.center = {center[0], center[1]};
        f.radius = entry.Number("radius", core::NumberRule::Closed(0, 1, "-"));
        break;
      }
      case FaultKind::kImuBiasDrift:
        f.joint = entry.Enum("joint", {"boom", "bucket"});
        f.rate_rad_s = entry.AngleDeg("rate_deg_s", core::NumberRule::Closed(-10, 10, "deg/s"));
        break;
      case FaultKind::kImuStuck:
        f.joint = entry.Enum("joint", {"boom", "bucket"});
        break;
      case FaultKind::kEncoderNoise:
        f.sigma_rad = entry.AngleDeg("sigma_deg", core::NumberRule::Closed(0, 10, "deg"));
        break;
      case FaultKind::kHydraulicDelayDrift:
        f.factor = entry.Number("factor", core::NumberRule::Closed(0.1, 10, "-"));
        break;
      case FaultKind::kTimestampsOutOfOrder:
        f.sensor = entry.Enum("sensor", {"lidar", "camera"});
        f.lag_s = entry.Number("lag_s", core::NumberRule::Positive("s"));
        break;
      case FaultKind::kLidarDropout:
      case FaultKind::kCameraBlackout:
        break;
    }
    entry.Finish();
    faults.push_back(f);
  }
  return faults;
}

std::vector<FaultSpec> LoadFaults(const std::string& path) {
  core::DiagnosticSink sink;
  const core::YamlFile file(path, sink);
  std::vector<FaultSpec> faults;
  if (file.ok()) {
    core::MapReader root = core::MapReader::Root(file, nullptr);
    if (!root.Has("faults")) root.Error("faults", "the file must hold a 'faults' list");
    faults = ReadFaults(root);
    root.Finish();
  }
  sink.ThrowIfAny();
  return faults;
}

}  // namespace autoshovel::plant
