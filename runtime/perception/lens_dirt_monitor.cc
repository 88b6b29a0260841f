#include "runtime/perception/lens_dirt_monitor.h"

#include <algorithm>
#include <cmath>

namespace autoshovel::perception {

bool LensDirtMonitor::Observe(const sensors::CameraFrame& frame,
                              const Eigen::Isometry3d& T_world_camera,
                              const std::vector<std::uint8_t>& own_machine) {
  const int w = frame.width, h = frame.height;
  if (w <= 0 || h <= 0 || frame.bgr.size() != static_cast<std::size_t>(3) * w * h) return false;
  if (w != width_ || h != height_) {  // first frame, or another camera: start over
    width_ = w, height_ = h;
    tiles_x_ = (w + config_.tile - 1) / config_.tile;
    tiles_y_ = (h + config_.tile - 1) / config_.tile;
    previous_mean_.assign(static_cast<std::size_t>(tiles_x_) * tiles_y_, 0.0);
    candidate_run_.assign(previous_mean_.size(), 0);
    masked_.assign(previous_mean_.size(), false);
    suspect_.assign(previous_mean_.size(), false);
    last_clean_.assign(previous_mean_.size(), std::nan(""));
    have_previous_ = false;
  }
  bool moved = true;
  if (have_previous_) {
    const double travel = (T_world_camera.translation() - T_world_previous_.translation()).norm();
    const double turn =
        Eigen::AngleAxisd(T_world_previous_.linear().transpose() * T_world_camera.linear()).angle();
    moved = travel >= config_.min_motion || turn >= config_.min_turn;
  }
  // Grey level, sums per tile (Rec. 601 weights on BGR).
  const std::size_t tiles = previous_mean_.size();
  std::vector<double> sum(tiles, 0.0), sum_sq(tiles, 0.0);
  std::vector<int> count(tiles, 0), own(tiles, 0);
  const bool have_own = own_machine.size() == static_cast<std::size_t>(w) * h;
  for (int v = 0; v < h; ++v) {
    const int row = (v / config_.tile) * tiles_x_;
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      const std::uint8_t* p = &frame.bgr[3 * i];
      const double grey = 0.114 * p[0] + 0.587 * p[1] + 0.299 * p[2];
      const std::size_t t = static_cast<std::size_t>(row + u / config_.tile);
      sum[t] += grey, sum_sq[t] += grey * grey, ++count[t];
      if (have_own && own_machine[i] != 0) ++own[t];
    }
  }
  for (std::size_t t = 0; t < tiles; ++t) {
    const double mean = sum[t] / count[t];
    const double spread = std::sqrt(std::max(0.0, sum_sq[t] / count[t] - mean * mean));
    // Dark: below max_mean, or below relative_dark of the tile's last clean look (in glare the
    // blot itself reads ≈ 108, the lens flare over it).
    const double clean = last_clean_[t];
    const bool dark =
        mean < config_.max_mean || (!std::isnan(clean) && mean < config_.relative_dark * clean);
    const bool dark_and_even = 2 * own[t] < count[t] && dark && spread < config_.max_spread;
    // Fallen: darker by onset_drop than the tile's last clean look. A tile never seen clean (a
    // dim floor, dark from the start) never falls.
    if (!dark_and_even) last_clean_[t] = mean;
    const bool fallen = dark_and_even && !std::isnan(clean) && clean - mean > config_.onset_drop;
    suspect_[t] = fallen;
    if (!moved) {
      // The scene stood still: staying the same proves nothing, but a tile that shows texture
      // or light again is clean (the machine waits stopped for a wiper or a hand).
      if (!fallen) candidate_run_[t] = 0;
      continue;
    }
    const bool candidate =
        have_previous_ && fallen && std::abs(mean - previous_mean_[t]) < config_.max_change;
    candidate_run_[t] = candidate ? candidate_run_[t] + 1 : 0;
    previous_mean_[t] = mean;
  }
  if (moved) {
    have_previous_ = true;
    T_world_previous_ = T_world_camera;
  }
  // The mask: dirty tiles and their eight neighbours, and suspect tiles.
  long masked_pixels = 0, dirty_pixels = 0;
  for (int ty = 0; ty < tiles_y_; ++ty) {
    for (int tx = 0; tx < tiles_x_; ++tx) {
      bool near_dirt = false, near_suspect = false;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = tx + dx, y = ty + dy;
          if (x < 0 || y < 0 || x >= tiles_x_ || y >= tiles_y_) continue;
          const std::size_t n = static_cast<std::size_t>(y * tiles_x_ + x);
          near_dirt = near_dirt || candidate_run_[n] >= config_.frames_to_confirm;
          near_suspect = near_suspect || suspect_[n];
        }
      }
      const std::size_t t = static_cast<std::size_t>(ty * tiles_x_ + tx);
      masked_[t] = near_dirt || near_suspect;
      const long pixels = static_cast<long>(std::min(config_.tile, w - tx * config_.tile)) *
                          std::min(config_.tile, h - ty * config_.tile);
      if (masked_[t]) masked_pixels += pixels;
      if (near_dirt) dirty_pixels += pixels;
    }
  }
  masked_fraction_ = static_cast<double>(masked_pixels) / (static_cast<double>(w) * h);
  dirty_fraction_ = static_cast<double>(dirty_pixels) / (static_cast<double>(w) * h);
  return moved;
}

bool LensDirtMonitor::Masked(int u, int v) const {
  if (u < 0 || v < 0 || u >= width_ || v >= height_) return false;
  return masked_[static_cast<std::size_t>((v / config_.tile) * tiles_x_ + u / config_.tile)];
}

}  // namespace autoshovel::perception
