// Dirt on the camera's lens (issue 9, fault "camera_lens_dirt"): mud or dust stuck on the glass
// shows as a dark, even patch that stays where it is in the image while the scene behind it
// moves. The monitor finds it from the images alone, so that the pixels under it stop feeding
// the semantic map (what a segmenter makes of a featureless blot, ground most likely, could
// hide a person) and so that the supervisor can stop the machine when too much of the view is
// lost.
//
// The image is cut into square tiles. A tile is dark and even when its mean grey level is below
// `max_mean` (a lit yard's darkest surfaces, piles in shadow, read ≈ 100 of 255 under normal
// lighting; a blot that stops the light reads ≈ 45) or below `relative_dark` of its last clean
// look (in glare the lens flare lifts a blot to ≈ 108), and its spread within `max_spread` (sensor
// noise only, no texture). It has fallen when it is dark and even and `onset_drop` darker than
// its last clean look (the last frame in which it was not dark and even): a blot darkens what
// the tile showed before, while a dim yard's floor, dark from the start, never falls (without
// this rule the dim yard of low_pile had a quarter of its image "dirty"). A fallen tile is
// suspect and masked at once (a splash must not feed the map even one frame: the first fault
// campaign's lens-dirt cycles came within 0.31 m of a wall while a blot read as floor wore down
// its obstacle evidence). It is a candidate when its mean also moved by less than `max_change`
// since the previous judged frame although the camera moved by `min_motion` or turned by
// `min_turn` (the scene behind a clean tile would have shifted); `frames_to_confirm`
// candidate frames in a row make it dirty, and one frame that is not clears it. Frames taken
// without enough motion confirm nothing, but clear a tile that shows texture or light again
// (a stopped machine must see its lens wiped). A blot's rim covers its tiles only in part
// (their spread is the scene's): the tiles next to a fallen or dirty one are masked with it.
//
// The machine's own hood and bucket stand still in the image while it drives, as a blot does:
// tiles that are mostly the own machine (by the segmentation) are never dirt.
//
// Limit: a lens dirty before the machine's first frame is not found (no tile has fallen); a
// pre-start check of the camera has to catch it.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "runtime/sensors/sensor_data.h"

namespace autoshovel::perception {

struct LensDirtConfig {
  int tile = 24;               ///< tile side [px]
  double max_mean = 70;        ///< grey level [0, 255]
  double relative_dark = 0.6;  ///< or this fraction of the tile's last clean look
  double max_spread = 8;       ///< standard deviation of the grey level within a tile
  double max_change = 1.5;     ///< of the tile's mean between frames
  double min_motion = 0.2;     ///< camera travel between judged frames [m]
  double min_turn = 0.03;      ///< camera turn between judged frames [rad]
  int frames_to_confirm = 3;
  double onset_drop = 30;  ///< below the tile's last clean look, to have fallen
};

class LensDirtMonitor {
 public:
  explicit LensDirtMonitor(const LensDirtConfig& config = {}) : config_(config) {}

  /// Judges one frame taken with the camera at `T_world_camera`. Returns whether the camera had
  /// moved enough since the last such frame for its stillness to count.
  /// `own_machine`: per pixel of the frame, non-zero where the segmentation sees the machine
  /// itself (empty: nowhere).
  bool Observe(const sensors::CameraFrame& frame, const Eigen::Isometry3d& T_world_camera,
               const std::vector<std::uint8_t>& own_machine = {});

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
  std::vector<int> candidate_run_;  ///< consecutive judged frames as a candidate
  std::vector<bool> masked_;        ///< per tile
  std::vector<bool> suspect_;       ///< per tile
  std::vector<double> last_clean_;  ///< mean of the tile's last clean look (NaN: none yet)
  double masked_fraction_ = 0, dirty_fraction_ = 0;
};

}  // namespace autoshovel::perception
