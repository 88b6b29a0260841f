// The recording folder (docs/recording_format.md): what a machine's sensors delivered at each map
// update, in files any tool reads (binary PCD, PNG, CSV, YAML), so that perception and shovel
// point selection can run on it without the machine (`autoshovel replay DIR`). A simulated run
// writes one with `autoshovel run … --record DIR`; a real machine's logger writes the same.
//
//   DIR/recording.yaml          the manifest (format, machine, map grid, selection, cycles)
//   DIR/machine.yaml            the machine description, byte for byte
//   DIR/updates.csv             one row per map update: stamp, machine outline, selection pose
//   DIR/frames.csv              one row per sensor frame: update, sensor, stamp, file, pose
//   DIR/lidar/<sensor>/*.pcd    LiDAR frames in the sensor frame (x y z intensity ring
//                               time_offset)
//   DIR/camera/*.png            camera images (8-bit BGR); *_labels.png per-pixel classes
//   DIR/reference/              what the recording machine computed (map digests, selections),
//                               for a replay to be checked against
//
// Numbers are written with the shortest text that reads back to the same double, so a replay
// sees bit for bit what the recorder saw.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "runtime/planning/shovel_point_selection.h"

namespace autoshovel::recording {

inline constexpr const char* kFormatName = "autoshovel-recording";
inline constexpr int kFormatVersion = 1;

/// Where a cycle's piles count as its work (the site): a bin's rectangle, or discs round the
/// open yard's stockpiles.
struct WorkArea {
  enum class Kind { kRectangle, kDiscs };
  Kind kind = Kind::kRectangle;
  // kRectangle: the bin's open front edge centred at `front_center`, its depth running to the
  // left of the edge's direction `yaw` (half a metre of apron in front counts).
  Eigen::Vector2d front_center = Eigen::Vector2d::Zero();
  double yaw = 0, width = 0, depth = 0;
  /// kDiscs: (x, y, radius) [m].
  std::vector<Eigen::Vector3d> discs;

  bool Contains(const Eigen::Vector2d& p) const;
};

/// The scoop a cycle made, as its volume prediction (seed §6.1) saw it: what `replay` needs to
/// predict V1 and V2 again at each recorded decision.
struct ScoopInfo {
  std::string material;      ///< the material the machine was told it digs
  double target_volume = 0;  ///< V_t [m³]
  double bucket_max = 0;     ///< the bucket's curl limit the prediction's scoop curls to [rad]
  double boom_lift = 0;      ///< the boom lift the prediction's scoop ends with [rad]
};

struct CycleInfo {
  int index = 0;     ///< the run's cycle number (its results row's `cycle`)
  std::string site;  ///< bin name or "open yard"
  WorkArea area;
  std::optional<ScoopInfo> scoop;  ///< none: the cycle did not reach its scoop
};

/// recording.yaml.
struct Manifest {
  std::string machine_file = "machine.yaml";  ///< relative to the folder
  /// Identification overlays applied on top of the description, in order (model::LoadOptions::
  /// overlays), each a file in the folder: what the machine ran with after calibration.
  std::vector<std::string> overlays;
  std::string source;  ///< who wrote it, free text
  // The elevation map's grid (perception::ElevationMapConfig; the rest at its defaults).
  double map_resolution = 0.3;
  Eigen::Vector2d map_length = Eigen::Vector2d::Zero();
  Eigen::Vector2d map_center = Eigen::Vector2d::Zero();
  // The selection as the machine ran it (app::ShovelPointTask).
  planning::ShovelPointConfig selection;
  double min_planned_clearance = 0;  ///< [m]
  bool chen2024 = false;
  /// How the recording machine labelled its camera frames (optional in the file): the
  /// simulator's labels or the network, and the network's scale. `replay` takes these unless
  /// told otherwise, so that it reproduces the machine's maps.
  std::optional<bool> truth_labels;
  double segmentation_scale = 1.0;
  std::vector<CycleInfo> cycles;
};

/// updates.csv: one map update.
struct UpdateRow {
  long update = 0;   ///< 0, 1, 2, … in order
  int cycle = 0;     ///< a Manifest::cycles index
  double stamp = 0;  ///< [s]
  // The machine's outline at the update (perception::LoaderFootprint): localisation, the
  // articulation encoder, the bucket tip's horizontal reach from the hinge (arm sensors).
  Eigen::Vector2d hinge_xy = Eigen::Vector2d::Zero();
  double heading = 0, articulation = 0, tip_reach = 0;
  /// Whether shovel point selection ran after this update, and the localisation it planned from.
  bool select = false;
  Eigen::Vector2d select_xy = Eigen::Vector2d::Zero();
  double select_heading = 0;
  int line = 0;  ///< where the row is in updates.csv (for messages)
};

/// frames.csv: one sensor frame.
struct FrameRow {
  enum class Kind { kLidar, kCamera };
  long update = 0;
  Kind kind = Kind::kLidar;
  std::string sensor;         ///< the description's LiDAR or camera name
  double stamp = 0;           ///< [s]
  std::string file;           ///< relative to the folder
  std::string labels_file;    ///< camera only, optional: per-pixel classes (simulator truth)
  bool health_check = false;  ///< LiDAR: check this frame for blind sectors
  Eigen::Isometry3d T_world_sensor = Eigen::Isometry3d::Identity();
  int line = 0;  ///< where the row is in frames.csv (for messages)
};

/// scoop.csv: one decision of a scoop's trigger (20 Hz from the approach on), the machine's state
/// as the decision saw it.
struct DecisionRow {
  int cycle = 0;
  double time = 0;  ///< [s]
  Eigen::Vector2d hinge_xy = Eigen::Vector2d::Zero();
  double heading = 0, speed = 0;    ///< [rad], [m/s]
  double q_boom = 0, q_bucket = 0;  ///< the state estimate's joint angles [rad]
  long path_points = 0;             ///< the cycle's tip path points (tip_path.csv) so far
  bool predict = false;             ///< the decision predicted V2
  int line = 0;
};

/// tip_path.csv: the bucket tip's path while digging, per cycle, world [m].
struct TipPoint {
  int cycle = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  int line = 0;
};

inline constexpr const char* kScoopHeader =
    "cycle,time,hinge_x,hinge_y,heading,speed,q_boom,q_bucket,path_points,predict";
inline constexpr const char* kTipPathHeader = "cycle,x,y,z";

inline constexpr const char* kUpdatesHeader =
    "update,cycle,stamp,hinge_x,hinge_y,heading,articulation,tip_reach,select,select_x,select_y,"
    "select_heading";
inline constexpr const char* kFramesHeader =
    "update,kind,sensor,stamp,file,labels_file,health_check,x,y,z,r00,r01,r02,r10,r11,r12,r20,"
    "r21,r22";

}  // namespace autoshovel::recording
