// The recording of the truck-loading job (docs/recording_format.md, "Truck loading"): the scans
// its rangefinder made, as truck recognition (excavator seed §4.1) and the dump planner's bed map
// (§4.3) took them, so that `autoshovel replay` reruns both without the plant.
//
//   recording.yaml        format, version, job: truck_loading, machine, scanner, base pose, scans
//   <machine>.yaml        the machine description, byte for byte
//   scans.csv             one row per scan: kind (recognition | bed), pass, its counters
//   scanlines.csv         one row per mirror revolution: the beam origin, the scan plane azimuth
//   scan_points.csv       one row per reading, in mirror order; a miss is kept (valid 0, nan)
//   reference/truck.csv   what the machine recognised from the recognition scan
//   reference/bed_maps.csv  the bed map the machine planned its dumps on after each scan
//
// Points are in the world frame the scans were taken in (scanline.h): the recogniser needs no
// machine state, only where the machine's base stood (`base_pose`), for the standing level.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "runtime/perception/truck/scanline.h"

namespace autoshovel::recording {

inline constexpr char kTruckLoadingJob[] = "truck_loading";
inline constexpr char kScansHeader[] =
    "scan,kind,pass,pulses_fired,points,dust_evidence,max_azimuth_step,dust_warning,"
    "min_speed_scale";
inline constexpr char kScanlinesHeader[] = "scan,scanline,sensor_x,sensor_y,sensor_z,azimuth";
inline constexpr char kScanPointsHeader[] = "scan,scanline,x,y,z,valid";
inline constexpr char kTruckReferenceHeader[] =
    "found,below_machine,x,y,z,yaw,length,width,wall_height,floor_height,rim_height,score,"
    "support_points";
inline constexpr char kBedMapReferenceHeader[] = "scan,cells_x,cells_y,known,mean_height,digest";

/// What a scan was for.
enum class ScanKind { kRecognition, kBed };

/// One scan: what scans.csv says of it, and its scanlines.
struct RecordedScan {
  int scan = 0;  ///< 0, 1, 2 … in the order they were made
  ScanKind kind = ScanKind::kBed;
  int pass = 0;  ///< the pass it was made in (0-based)
  long long pulses_fired = 0, points = 0, dust_evidence = 0;
  double max_azimuth_step = 0;  ///< [rad]
  bool dust_warning = false;
  double min_speed_scale = 1;
  std::vector<perception::Scanline> scanlines;
  std::vector<double> scanline_azimuths;  ///< [rad], one per scanline
};

/// recording.yaml of a truck-loading recording.
struct ScanManifest {
  int version = 1;
  std::string machine_file;  ///< the description's file name in the folder
  std::string scanner;       ///< the rangefinder's name in the description (sensors.lidars)
  Eigen::Isometry3d T_world_base = Eigen::Isometry3d::Identity();
  int scans = 0;
};

}  // namespace autoshovel::recording
