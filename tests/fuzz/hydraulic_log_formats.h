// The ways the hydraulic log fuzz target reads every input, shared with the regression test so
// that a kept input is read exactly as when it was found.
#pragma once

#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "identification/hydraulics/log_reader.h"
#include "runtime/core/diagnostics.h"

namespace autoshovel::fuzz {

/// Whether `bytes` look like a ControlDesk export: a line opens with `trace_names` or
/// `trace_values` (controldesk_header.h).
inline bool LooksLikeControlDesk(std::string_view bytes) {
  for (const std::string_view marker : {"trace_names", "trace_values"}) {
    if (bytes.starts_with(marker)) return true;
    for (std::size_t at = bytes.find(marker); at != std::string_view::npos;
         at = bytes.find(marker, at + 1)) {
      if (bytes[at - 1] == '\n') return true;
    }
  }
  return false;
}

/// The column map of a first line `# columns: SPEC` (a comment to the reader), if any: so that
/// expressions, quoted names and numbers are fuzzed against the header they name.
inline std::optional<std::string> ColumnsSpecOf(std::string_view bytes) {
  constexpr std::string_view kTag = "# columns: ";
  if (!bytes.starts_with(kTag)) return std::nullopt;
  const std::string_view line = bytes.substr(kTag.size(), bytes.find('\n') - kTag.size());
  return std::string(line);
}

/// An ordinary log is read with the default column names of `autoshovel plant step` (SI
/// units), with a column map by position in logger units (ms, percent, deg, bar), and with
/// expressions over the plant-step names (negation, scale, offset, a sum, a quoted name).
/// A ControlDesk export (the seeds' channels: time, Lift_Cap_P 3, Lift_Rod_P 4, Lift_up_duty 5,
/// Lift_dn_duty 6, Lift_Up_pilot_P 7, Lift_Dn_pilot_P 8, Lift_ang 9, Lift_up_FB 10) is read by
/// trace name, path and path part in expressions, and by number. Every way of finding columns,
/// every unit conversion. A `# columns:` line adds its map, in SI units, when ParseColumnsSpec
/// takes it.
inline std::vector<identification::LogFormat> HydraulicLogFormats(std::string_view bytes) {
  using namespace identification;
  const auto logger_units = [](LogFormat format) {
    format.time_units = TimeUnits::kMilliseconds;
    format.command_units = format.spool_units = CommandUnits::kPercent;
    format.angle_units = AngleUnits::kDegrees;
    format.pressure_units = PressureUnits::kBar;
    return format;
  };
  static const std::vector<LogFormat> controldesk = [&] {
    LogFormat by_name = logger_units(
        ParseColumnsSpec("time=time,command=Lift_up_duty - Lift_dn_duty,joint_angle=-Lift_ang + 90,"
                         "pressure_a=0.1*Lift_Cap_P,pressure_b='Root/Pressures/Lift_Rod_P',"
                         "pilot_pressure=Lift_Up_pilot_P + $8,spool=Lift_up_FB"));
    by_name.time_units = TimeUnits::kSeconds;
    LogFormat by_number = logger_units(
        ParseColumnsSpec("time=2,command=$6 - $5,joint_angle=9,pressure_a=$3,pressure_b=4"));
    return std::vector<LogFormat>{by_name, by_number};
  }();
  static const std::vector<LogFormat> ordinary = [&] {
    const LogFormat by_position =
        logger_units(ParseColumnsSpec("time=1,command=2,spool=3,pressure_a=4,joint_angle=5"));
    const LogFormat expressions = ParseColumnsSpec(
        "time=t,command=-command,spool=0.5*spool,joint_angle=joint_angle + 0.1,"
        "pressure_a=pressure - $5,pilot_pressure='pressure'");
    return std::vector<LogFormat>{LogFormat{}, by_position, expressions};
  }();
  std::vector<LogFormat> formats = LooksLikeControlDesk(bytes) ? controldesk : ordinary;
  if (const std::optional<std::string> spec = ColumnsSpecOf(bytes)) {
    try {
      formats.push_back(ParseColumnsSpec(*spec));
    } catch (const core::InputError&) {
      // Refused before any log is read; the fuzz target checks the refusal itself.
    }
  }
  return formats;
}

/// The formats for the file at `path`, as the fuzz target chose them for its bytes.
inline std::vector<identification::LogFormat> HydraulicLogFormatsOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes(std::istreambuf_iterator<char>(in), {});
  return HydraulicLogFormats(bytes);
}

}  // namespace autoshovel::fuzz
