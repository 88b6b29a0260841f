#include "runtime/planning/dump/dump_planner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "runtime/planning/dump/grid_filters.h"

namespace autoshovel::planning {
namespace {

// Slack on the wall test so that a footprint exactly touching the margin counts as inside.
constexpr double kGeometrySlack = 1e-9;

void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("DumpPlanner: " + what);
}

bool FinitePositive(double value) { return std::isfinite(value) && value > 0; }

}  // namespace

DumpPlanner::DumpPlanner(const DumpPlannerConfig& config) : config_(config) {
  // GaussianKernel1d owns the σ range; calling it here reports a bad σ at construction.
  GaussianKernel1d(config.smoothing_sigma_cells);
  Require(config.template_size == 0 || (config.template_size % 2 == 1 &&
                                        config.template_size >= 3 && config.template_size <= 15),
          "template size must be 0 (from the bucket) or odd in [3, 15], got " +
              std::to_string(config.template_size));
  Require(
      FinitePositive(config.footprint_along_bed_m) && FinitePositive(config.footprint_across_bed_m),
      "bucket footprint sides must be finite and positive");
  Require(std::isfinite(config.wall_margin_m) && config.wall_margin_m >= 0,
          "wall margin must be finite and non-negative");
  Require(std::isfinite(config.tie_tolerance_m) && config.tie_tolerance_m >= 0,
          "tie tolerance must be finite and non-negative");
  Require(std::isfinite(config.surroundings_sigma_m) && config.surroundings_sigma_m >= 0,
          "surroundings sigma must be finite and non-negative");
  Require(std::isfinite(config.surroundings_tolerance_m) && config.surroundings_tolerance_m >= 0,
          "surroundings tolerance must be finite and non-negative");
}

int DumpPlanner::TemplateSize(double cell_size_m) const {
  if (config_.template_size != 0) return config_.template_size;
  return ChooseTemplateSize(std::max(config_.footprint_along_bed_m, config_.footprint_across_bed_m),
                            cell_size_m);
}

CellMask DumpPlanner::FeasibleCells(const BedHeightMap& map) const {
  const double reach_x = 0.5 * config_.footprint_along_bed_m + config_.wall_margin_m;
  const double reach_y = 0.5 * config_.footprint_across_bed_m + config_.wall_margin_m;
  const double length = map.bed().length_m;
  const double width = map.bed().width_m;
  CellMask feasible(map.cells_x(), map.cells_y());
  for (int ix = 0; ix < map.cells_x(); ++ix) {
    for (int iy = 0; iy < map.cells_y(); ++iy) {
      const Eigen::Vector2d c = map.CellCentre(ix, iy);
      feasible(ix, iy) =
          c.x() - reach_x >= -kGeometrySlack && c.x() + reach_x <= length + kGeometrySlack &&
          c.y() - reach_y >= -kGeometrySlack && c.y() + reach_y <= width + kGeometrySlack;
    }
  }
  return feasible;
}

DumpPlan DumpPlanner::Plan(const BedHeightMap& map, const Eigen::Isometry3d& T_world_bed) const {
  if (!T_world_bed.matrix().allFinite()) {
    throw std::invalid_argument("DumpPlanner: T_world_bed is not finite");
  }
  DumpPlan plan;
  plan.feasible = FeasibleCells(map);
  if (!plan.feasible.any()) {
    throw std::invalid_argument(
        "DumpPlanner: the bucket footprint (" + std::to_string(config_.footprint_along_bed_m) +
        " m x " + std::to_string(config_.footprint_across_bed_m) + " m) with " +
        std::to_string(config_.wall_margin_m) + " m wall margins fits nowhere in the " +
        std::to_string(map.bed().length_m) + " m x " + std::to_string(map.bed().width_m) +
        " m bed");
  }

  // §4.3, in order: smooth, fill the unseen cells with the seen mean, correlate the template.
  const Eigen::MatrixXd smoothed =
      SmoothKnown(map.heights(), map.known_mask(), config_.smoothing_sigma_cells);
  plan.prepared_heights = FillUnknownWithKnownMean(smoothed, map.known_mask());
  plan.known_cells = map.known_count();
  plan.filled_cells = map.cells_x() * map.cells_y() - plan.known_cells;
  plan.template_size = TemplateSize(map.cell_size_m());
  plan.score_map =
      Correlate(plan.prepared_heights, MakeDumpTemplate(config_.shape, plan.template_size));

  double best_score = -std::numeric_limits<double>::infinity();
  for (int ix = 0; ix < map.cells_x(); ++ix) {
    for (int iy = 0; iy < map.cells_y(); ++iy) {
      if (plan.feasible(ix, iy)) best_score = std::max(best_score, plan.score_map(ix, iy));
    }
  }
  // Ties: a low region wider than the template scores the same everywhere (an empty bed, the
  // empty half of one). Among the near-best cells, prefer the one whose wider surroundings, at
  // the scale a poured load spreads over, are lowest, so the load lands away from earlier heaps
  // rather than on their toes; then the one nearest the bed centre; row-major order settles exact
  // distance ties, so the choice is deterministic.
  const CellMask ties =
      plan.feasible && (plan.score_map.array() >= best_score - config_.tie_tolerance_m);
  // σ = 0 turns the stage off (all surroundings 0, all tied), not into a per-cell comparison.
  plan.surroundings = config_.surroundings_sigma_m > 0
                          ? SmoothKnown(plan.prepared_heights,
                                        CellMask::Constant(map.cells_x(), map.cells_y(), true),
                                        config_.surroundings_sigma_m / map.cell_size_m())
                          : Eigen::MatrixXd::Zero(map.cells_x(), map.cells_y());
  double lowest_surroundings = std::numeric_limits<double>::infinity();
  for (int ix = 0; ix < map.cells_x(); ++ix) {
    for (int iy = 0; iy < map.cells_y(); ++iy) {
      if (ties(ix, iy)) {
        lowest_surroundings = std::min(lowest_surroundings, plan.surroundings(ix, iy));
      }
    }
  }
  const Eigen::Vector2d bed_centre(0.5 * map.bed().length_m, 0.5 * map.bed().width_m);
  double best_distance = std::numeric_limits<double>::infinity();
  for (int ix = 0; ix < map.cells_x(); ++ix) {
    for (int iy = 0; iy < map.cells_y(); ++iy) {
      if (!ties(ix, iy) ||
          plan.surroundings(ix, iy) > lowest_surroundings + config_.surroundings_tolerance_m) {
        continue;
      }
      const double distance = (map.CellCentre(ix, iy) - bed_centre).norm();
      if (distance < best_distance - kGeometrySlack) {
        best_distance = distance;
        plan.cell = {ix, iy};
      }
    }
  }

  const Eigen::Vector2d p_xy = map.CellCentre(plan.cell.x(), plan.cell.y());
  plan.score = plan.score_map(plan.cell.x(), plan.cell.y());
  plan.p_bed_dump = {p_xy.x(), p_xy.y(), plan.prepared_heights(plan.cell.x(), plan.cell.y())};
  plan.p_world_dump = T_world_bed * plan.p_bed_dump;
  return plan;
}

}  // namespace autoshovel::planning
