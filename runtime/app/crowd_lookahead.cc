// The crowd look-ahead (crowd_lookahead.h).
#include "runtime/app/crowd_lookahead.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "runtime/model/interpreted_model.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/prediction/volume_estimation.h"

namespace autoshovel::app {

std::vector<Eigen::Vector2d> SureObstacleCells(const perception::GridMap& map, double margin,
                                               int growth_cells, double min_confidence) {
  const Eigen::MatrixXf& cls = map["class"];
  // The evidence that an obstacle stands in the cell (semantic_map.h): a wall seen over a pile
  // top at a grazing angle does not make the pile top a place to stop before.
  const Eigen::MatrixXf& obstacle_confidence = map.Exists("steep_obstacle_confidence")
                                                   ? map["steep_obstacle_confidence"]
                                                   : map["obstacle_confidence"];
  const Eigen::MatrixXf& pile_confidence = map["pile_confidence"];
  const float obstacle = static_cast<float>(perception::CellClass::kObstacle);
  const int nx = static_cast<int>(cls.rows()), ny = static_cast<int>(cls.cols());
  auto confident = [&](int ix, int iy) {
    return cls(ix, iy) == obstacle && obstacle_confidence(ix, iy) >= min_confidence;
  };
  Eigen::Matrix<bool, Eigen::Dynamic, Eigen::Dynamic> sure(nx, ny);
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const double p_pile = std::isfinite(pile_confidence(ix, iy)) ? pile_confidence(ix, iy) : 0.0;
      sure(ix, iy) = confident(ix, iy) && obstacle_confidence(ix, iy) - p_pile >= margin;
    }
  }
  std::vector<Eigen::Vector2d> cells;
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      bool take = sure(ix, iy);
      for (int dy = -growth_cells; dy <= growth_cells && !take && confident(ix, iy); ++dy) {
        for (int dx = -growth_cells; dx <= growth_cells && !take; ++dx) {
          const int jx = ix + dx, jy = iy + dy;
          take = jx >= 0 && jy >= 0 && jx < nx && jy < ny && sure(jx, jy);
        }
      }
      if (take) cells.push_back(map.PositionOf(perception::Index(ix, iy)));
    }
  }
  return cells;
}

double ScoopReach(const model::MachineDescription& machine, double q_boom, double q_bucket,
                  const control::StrategyParameters& strategy) {
  const double q_lifted =
      std::min(q_boom + strategy.exit_boom_lift + strategy.max_steps * strategy.step_boom_lift,
               machine.links[0].joint_max);
  const double level_attitude = model::BucketLevelAttitude(machine);
  double reach = 0;
  // Levelling ends with the bucket level; shaking then swings it by a few degrees either way
  // (FinishingParameters: pulses of 0.12 s), covered by ±kShakeSwing.
  constexpr double kShakeSwing = 0.1;  // [rad]
  for (const double boom : {q_boom, q_lifted}) {
    for (const double bucket : {q_bucket, level_attitude - boom - kShakeSwing,
                                level_attitude - boom, level_attitude - boom + kShakeSwing}) {
      reach = std::max(reach, prediction::TipInBase(machine, boom, bucket).x());
    }
  }
  return reach;
}

double DistanceAhead(const std::vector<Eigen::Vector2d>& cells, const Eigen::Vector2d& hinge_xy,
                     double heading, double half_width, double front_length, double cell_size,
                     int* nearest) {
  const Eigen::Vector2d u(std::cos(heading), std::sin(heading)), lateral(-u.y(), u.x());
  double ahead = std::numeric_limits<double>::infinity();
  if (nearest != nullptr) *nearest = -1;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const Eigen::Vector2d d = cells[k] - hinge_xy;
    if (d.dot(u) <= 0 || std::abs(d.dot(lateral)) > half_width) continue;
    const double distance = d.dot(u) - front_length - 0.5 * cell_size;
    if (distance < ahead) {
      ahead = distance;
      if (nearest != nullptr) *nearest = static_cast<int>(k);
    }
  }
  return ahead;
}

double FootprintDistanceToCells(const perception::MachineFootprint& footprint,
                                const std::vector<Eigen::Vector2d>& cells, double cell_size,
                                int* nearest) {
  // Each frame is a rectangle [from, to] × [−half_width, half_width] in its own axes; a point's
  // distance to it is the norm of how far it lies outside on each axis.
  struct Frame {
    double heading, from, to;
  };
  const Frame frames[2] = {
      {footprint.heading_front, 0.0, footprint.front_length},
      {footprint.heading_front - footprint.articulation, -footprint.rear_length, 0.0}};
  double best = std::numeric_limits<double>::infinity();
  if (nearest != nullptr) *nearest = -1;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const Eigen::Vector2d d = cells[k] - footprint.hinge_xy;
    for (const Frame& f : frames) {
      const double c = std::cos(f.heading), s = std::sin(f.heading);
      const double along = c * d.x() + s * d.y(), across = -s * d.x() + c * d.y();
      const double out_along = std::max({0.0, f.from - along, along - f.to});
      const double out_across = std::max(0.0, std::abs(across) - footprint.half_width);
      const double distance = std::hypot(out_along, out_across) - 0.5 * cell_size;
      if (distance < best) {
        best = distance;
        if (nearest != nullptr) *nearest = static_cast<int>(k);
      }
    }
  }
  return best;
}

}  // namespace autoshovel::app
