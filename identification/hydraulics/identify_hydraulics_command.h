// `autoshovel identify hydraulics LOG.csv... --machine M`: hydraulic delay identification
// (hydraulic_identification.h) from valve step and chirp logs, printed as a table with
// cross-validation by duty level, written as an overlay of the machine description
// (`hydraulics.actuators[]` dead_zone, transport_delay, spool_time_constant, rated_flow_lpm)
// and as a PNG of the fits and residuals. `--simulate DIR` writes plant logs to try it on.
//
// How each log is read (log_reader.h): with `--column-map` (if given) overridden by `--columns`,
// the unit options, `--header-lines` and `--actuator`. A sibling `X.columns.yaml` beside a log
// `X.csv` stands in for the column map of that log alone when neither `--columns` nor
// `--column-map` is given (the other options still override its fields); an explicit map
// beats it. Either case is noted on stderr in one line. An explicit map is checked against
// every log (names in the header, numbers within the row, one column per quantity). Every log
// is read and every actuator fitted before anything is written: a bad file leaves no overlay
// and no figure. Big logs report progress on stderr, one whole line per stage.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace autoshovel::identification {

struct IdentifyHydraulicsOptions {
  std::vector<std::string> logs;  ///< step / chirp logs, fitted jointly per actuator
  std::string machine;
  std::string models_dir;
  std::string actuator;        ///< name or joint; empty: named by each log (map or header)
  std::string columns;         ///< `time=t_s,command=cmd_pct,...`
  std::string column_map;      ///< YAML column map (log_reader.h)
  std::string command_units;   ///< unit | percent; empty: the map's, else unit
  std::string spool_units;     ///< unit | percent; empty: as the command
  std::string angle_units;     ///< rad | deg; empty: the map's, else rad
  std::string pressure_units;  ///< Pa | bar | MPa; empty: the map's, else Pa
  std::string time_units;      ///< s | ms; empty: the map's, else s
  int header_lines = -1;       ///< lines before the samples; -1: detected
  std::string overlay;         ///< empty: <first log>.overlay.yaml
  std::string png;             ///< empty: <first log>.residuals.png
  bool cross_validate = true;
  bool exclude_end_stops = true;
  /// "chain" (default): the valve chain of valve_chain_fit.h (pilot stage, flow
  /// characteristic, data-detected stalls); "linear": dead zone + linear flow through the
  /// description's kinematics (hydraulic_identification.h).
  std::string model = "chain";
  int bootstrap = 20;       ///< chain: resamples of the logs for the intervals
  double relief = 0;        ///< chain: stall pressure override, pressure units; 0: from each log
  std::string joint_range;  ///< chain: "MIN:MAX" in the angle units; empty: all
  std::string window;       ///< chain: "T0:T1" [s]; empty: all
  /// An overlay (as a fit writes): drive the plant of the description with it by the logs'
  /// commands and compare the joint angle (plant_replay.h) instead of fitting.
  std::string replay;
  std::string simulate;         ///< write simulated logs into this folder instead
  unsigned long long seed = 1;  ///< of the simulated noise
  /// Layout of the simulated logs: "plant" (steps and a chirp, plant_logs.h
  /// WriteSimulatedCampaign) or "controldesk" (an excavator's step tests with a known valve
  /// chain, WriteControlDeskCampaign: boom and arm unless --actuator names one).
  std::string simulate_format = "plant";
};

int RunIdentifyHydraulics(const IdentifyHydraulicsOptions& options, std::ostream& out,
                          std::ostream& err);

}  // namespace autoshovel::identification
