// `autoshovel calibrate camera-lidar`: the two steps of seed Algorithm 1 on recorded (or
// simulated) data, printing a short summary and writing an overlay of the camera pose, a
// before/after projection PNG (Fig. 12) and a PNG of the score surface and board residuals.
//
// Data layout (what `--simulate DIR` writes):
//   DIR/intrinsics.yaml        ROS camera_info (K, D)
//   DIR/board/board.yaml       board geometry {side, hole_side, hole_offset} [m]
//   DIR/board/NAME.png|jpg + NAME.pcd|bin   board views (step 1)
//   DIR/frames/NAME.png|jpg + NAME.pcd|bin  scene views (step 2)
//   DIR/masks/NAME/0.png …     SAM binary masks of frame NAME (or masks/NAME.png label image,
//                              or masks/NAME.json COCO RLE); none: the built-in segmenter
// Errors in any input are reported as `file:line:column: message` and nothing is written.
#pragma once

#include <cstddef>
#include <iosfwd>
#include <string>
#include <vector>

namespace autoshovel::identification {

/// The fewest finite points a scene frame needs to be scored: 1000. A LiDAR frame has 10^4 to
/// 10^5; a cloud with fewer finite points saw almost nothing (an organised cloud of NaN "no
/// returns", a covered sensor) and would only pull the consistency score towards noise. Such a
/// frame is skipped with a warning naming its file and counts; none left is an error.
inline constexpr std::size_t kMinFramePoints = 1000;

struct CalibrateCameraLidarOptions {
  std::string machine;     ///< machine name or description path; empty: a standalone rig
  std::string models_dir;  ///< where machine names and scenarios are looked up
  std::string lidar = "front_solid_state";  ///< the description's LiDAR next to the camera
  std::string frames;              ///< folder of scene frames (image + cloud with the same stem)
  std::vector<std::string> pairs;  ///< or explicit "IMAGE,CLOUD" pairs
  /// Or CalibAnything-style scene folders: one image and one cloud, masks/ (binary PNGs), and
  /// optionally calib.txt (the first scene's gives intrinsics and start unless given).
  std::vector<std::string> scenes;
  std::string calib;       ///< calib.txt (K, D, and T as the start); see rig_files.h
  std::string intrinsics;  ///< camera_info YAML; empty: <frames>/../intrinsics.yaml, else
                           ///< the description's pinhole
  std::string masks;       ///< folder with one entry per frame stem; "none": built-in segmenter;
                           ///< empty: <frames>/../masks when it exists, else built-in
  std::string board;       ///< folder of board views (step 1); empty: no step 1
  std::vector<double> initial;   ///< T_lidar_camera x y z [m] roll pitch yaw [deg]; empty: board
                                 ///< result, else the description's nominal mounting
  std::string initial_matrix;    ///< start as a 3×4/4×4 LiDAR→optical matrix file
  std::string correspondences;   ///< `u v x y z` file (or IMAGE,LIDAR files): PnP start
  std::vector<double> perturb;   ///< roll pitch yaw [deg] x y z [m] applied to the start
                                 ///< (T · ΔT, rig_files.h), the published test protocol
  std::string reference;         ///< extrinsic file to report errors against
  std::string extrinsic_out;     ///< the result as a 4×4 LiDAR→optical matrix
  std::string slices_png;        ///< per-term score slices around the start (a study)
  bool evaluate_only = false;    ///< score the start (and its slices); no optimisation
  bool protocol = false;         ///< run perturbation_protocol.h around the reference instead
  double protocol_rotation = 3;  ///< ± per axis [deg]
  double protocol_translation = 0.1;  ///< ± per axis [m]
  std::string lock;                   ///< "", "rotation" or "translation"
  std::size_t max_points = 200000;    ///< per frame read, bounds memory on dense clouds
  std::string overlay;                ///< empty: <frames>/../camera_lidar.overlay.yaml
  std::string png;                    ///< before/after projection; empty: next to the overlay
  std::string residuals_png;          ///< score surface + board residuals; empty: next to it
  std::string simulate;               ///< write a simulated data set here instead
  unsigned long long seed = 1;        ///< of --simulate
};

int RunCalibrateCameraLidar(const CalibrateCameraLidarOptions& options, std::ostream& out,
                            std::ostream& err);

}  // namespace autoshovel::identification
