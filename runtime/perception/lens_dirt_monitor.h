// Dirt on the camera's lens (issue 9, fault "camera_lens_dirt"): mud or dust stuck on the glass
// shows as a dark, even patch that stays where it is in the image while the scene behind it
// moves. The monitor finds it from the images alone, so that the pixels under it stop feeding
// the semantic map (what a segmenter makes of a featureless blot, ground most likely, could
// hide a person) and so that the supervisor can stop the machine when too much of the view is
// lost.
//
// The image is cut into square tiles. A tile is a dirt candidate in a frame when its mean grey
// level is below `max_mean` (a lit yard's darkest surfaces, piles in shadow, read ≈ 100 of 255
// under normal lighting; a blot that stops the light reads ≈ 45), its spread is within
// `max_spread` (sensor noise only, no texture), and its mean moved by less than `max_change`
// since the previous frame although the camera moved by `min_motion` or turned by
// `min_turn` (the scene behind a clean tile would have shifted). A tile that is a candidate in
// `frames_to_confirm` such frames in a row is dirty; one frame that is not clears it again.
// Frames taken without enough motion confirm nothing, but clear a tile that shows texture or
// light again (a stopped machine must see its lens wiped). A blot's rim covers
// its tiles only in part (their spread is the scene's): the tiles next to a dirty one are
// masked with it, the safe side.
//
// Onset: a blot thrown on the lens (a splash of mud) turns a textured tile dark and even from
// one frame to the next. Such a tile is suspect at once, and suspect tiles are masked too (but
// do not count towards `dirty_fraction`): three frames of blot labelled as floor would already
// have eaten into a wall's obstacle evidence before the confirmation (the fault campaign's
// lens-dirt cells came within 0.31 m of a wall before this rule).
//
// Limit: under dim lighting (plant::Lighting::kDim) the whole yard reads below `max_mean`; an
// even, unlit floor seen while driving straight can then pass for dirt. The monitor then masks
// more than it must, the safe side.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "runtime/sensors/sensor_data.h"

namespace autoshovel::perception {

struct LensDirtConfig {
  int tile = 24;            ///< tile side [px]
  double max_mean = 70;     ///< grey level [0, 255]
  double max_spread = 6;    ///< standard deviation of the grey level within a tile
  double max_change = 1.5;  ///< of the tile's mean between frames
  double min_motion = 0.2;  ///< camera travel between judged frames [m]
  double min_turn = 0.03;   ///< camera turn between judged frames [rad]
  int frames_to_confirm = 3;
  double onset_spread = 15;  ///< a tile this textured in the last frame ...
  double onset_drop = 30;    ///< ... whose mean fell by this much, now dark and even: suspect
};

class LensDirtMonitor {
 public:
  explicit LensDirtMonitor(const LensDirtConfig& config = {}) : config_(config) {}

  /// Judges one frame taken with the camera at `T_world_camera`. Returns whether the camera had
  /// moved enough since the last such frame for its stillness to count.
  bool Observe(const sensors::CameraFrame& frame, const Eigen::Isometry3d& T_world_camera);

  /// Whether pixel (u, v) of a frame of the observed size lies in a dirty tile or next to one,
  /// or in a suspect tile.
  bool Masked(int u, int v) const;
  /// Fraction of the image masked [0, 1].
  double masked_fraction() const { return masked_fraction_; }
  /// Fraction of the image in confirmed dirty tiles and their neighbours [0, 1].
  double dirty_fraction() const { return dirty_fraction_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  LensDirtConfig config_;
  int width_ = 0, height_ = 0, tiles_x_ = 0, tiles_y_ = 0;
  bool have_previous_ = false;
  Eigen::Isometry3d T_world_previous_ = Eigen::Isometry3d::Identity();
  std::vector<double> previous_mean_;
  std::vector<int> candidate_run_;               ///< consecutive judged frames as a candidate
  std::vector<bool> masked_;                     ///< per tile
  std::vector<bool> suspect_;                    ///< per tile
  std::vector<double> last_mean_, last_spread_;  ///< of the last frame, judged or not
  bool have_last_ = false;
  double masked_fraction_ = 0, dirty_fraction_ = 0;
};

}  // namespace autoshovel::perception
