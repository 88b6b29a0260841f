#include "runtime/app/shovel_job/shovel_point_task.h"

#include <chrono>
#include <cmath>
#include <numbers>
#include <utility>

#include "runtime/app/shovel_job/cycle_log.h"

namespace autoshovel::app {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
}

ShovelPointTask::ShovelPointTask(const planning::ShovelPointConfig& config,
                                 double min_planned_clearance, bool chen2024,
                                 const planning::LoaderGeometry& loader,
                                 std::function<bool(const Eigen::Vector2d&)> in_site)
    : config_(config),
      min_planned_clearance_(min_planned_clearance),
      chen2024_(chen2024),
      loader_(loader),
      in_site_(std::move(in_site)) {}

const planning::ShovelCandidate* ShovelPointTask::Select(perception::GridMap& grid,
                                                         const Eigen::Vector3d& plane,
                                                         const planning::Pose2& T_world_hinge) {
  const auto w0 = std::chrono::steady_clock::now();
  std::vector<perception::ExtractedPile> piles = perception::ExtractPiles(grid, plane);
  std::vector<perception::ExtractedPile> in_site;
  for (auto& p : piles) {
    if (in_site_(p.centroid)) in_site.push_back(std::move(p));
  }
  last_selection_ =
      planning::SelectShovelPoints(grid, in_site, plane, T_world_hinge, loader_, config_);
  last_piles_ = in_site;
  // The best candidate whose approach and whole scoop keep the planned clearance; failing
  // that, the best whose approach does (its crowd will be ended early by the look-ahead).
  const planning::ShovelCandidate* best = nullptr;
  for (const bool whole_scoop : {true, false}) {
    for (const planning::ShovelCandidate& k : last_selection_.ranked) {
      const double d =
          whole_scoop ? k.scores.min_obstacle_distance : k.scores.approach_obstacle_distance;
      if (k.feasible && d >= min_planned_clearance_) {
        best = &k;
        break;
      }
    }
    if (best != nullptr) break;
  }
  if (chen2024_) {
    last_baseline_ = planning::RankChen2024(
        grid, plane, planning::GenerateCandidates(grid, in_site, config_), T_world_hinge.xy);
    best = nullptr;
    // The baseline's first choice that our planner can reach (Chen et al. plan no path): a
    // kinematically feasible path that neither collides nor drives over the pile, whatever
    // its clearance and our five scores.
    for (const planning::Chen2024Candidate& chen : last_baseline_) {
      const planning::CandidatePose& c = chen.pose;
      for (const planning::ShovelCandidate& k : last_selection_.ranked) {
        if (k.feasible && k.pose.pile == c.pile && k.pose.point == c.point &&
            std::abs(k.pose.entry_offset - c.entry_offset) < 1e-9) {
          best = &k;
        }
      }
      if (best != nullptr) break;
    }
  }
  ++selections_;
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  return best;
}

std::string ShovelPointTask::NoPointReason(const std::string& site) const {
  double best_approach = -INFINITY;
  for (const planning::ShovelCandidate& k : last_selection_.ranked) {
    if (k.feasible) best_approach = std::max(best_approach, k.scores.approach_obstacle_distance);
  }
  return "no feasible shovel point in " + site + " (" + last_selection_.message +
         (std::isfinite(best_approach)
              ? "; none planned " + Fixed(min_planned_clearance_, 2) +
                    " m clear of obstacles, the clearest " + Fixed(best_approach, 2) + " m"
              : std::string()) +
         ")";
}

std::string ShovelPointTask::SelectedText(const planning::ShovelCandidate& best) const {
  return "selected point (" + Fixed(best.pose.xy.x(), 2) + ", " + Fixed(best.pose.xy.y(), 2) +
         ") heading " + Fixed(best.pose.entry_heading / kDeg, 1) + " deg, F " +
         Fixed(best.score, 3) + ", path " + Fixed(best.path.length(), 1) + " m, d_min " +
         Fixed(best.scores.min_obstacle_distance, 2) + " m (approach " +
         Fixed(best.scores.approach_obstacle_distance, 2) + " m, scoop " +
         Fixed(config_.scoop_advance, 1) + " m in); Eq. (18) scores s_t " +
         Fixed(best.scores.s_t, 2) + ", s_s " + Fixed(best.scores.s_s, 2) + ", s_c " +
         Fixed(best.scores.s_c, 0) + " (V_l/V_m/V_r " + Fixed(best.scores.volume_left, 2) + "/" +
         Fixed(best.scores.volume_middle, 2) + "/" + Fixed(best.scores.volume_right, 2) +
         " m3), s_e " + Fixed(best.scores.s_e, 2) + ", s_a " + Fixed(best.scores.s_a, 2);
}

GoalChange ShovelPointTask::Reconsider(const planning::ShovelCandidate& goal,
                                       const planning::ShovelCandidate& best) const {
  // The goal being driven to, as seen on the new map and planned from where the machine is now:
  // infeasible (an obstacle came into view) → take the best; beaten by 0.05 in F (our selection
  // only) → take the best; otherwise keep it, on its re-planned path. The goal is found again as
  // the nearest candidate within 0.5 m and half the entry angles' spacing in heading: the
  // boundary normal a heading is measured from moves a few degrees as more of the pile comes
  // into view, and an exact match lost the goal every few frames and sent the machine round the
  // pile after whatever scored best.
  double half_angle_step = std::numbers::pi;
  const std::vector<double>& offsets = config_.entry_angle_offsets;
  for (std::size_t i = 1; i < offsets.size(); ++i) {
    half_angle_step = std::min(half_angle_step, 0.5 * std::abs(offsets[i] - offsets[i - 1]));
  }
  const planning::ShovelCandidate* current = nullptr;
  double current_mismatch = 1.0;
  for (const planning::ShovelCandidate& k : last_selection_.ranked) {
    const double mismatch =
        std::max((k.pose.xy - goal.pose.xy).norm() / 0.5,
                 std::abs(std::remainder(k.pose.entry_heading - goal.pose.entry_heading,
                                         2 * std::numbers::pi)) /
                     half_angle_step);
    if (mismatch < current_mismatch) current = &k, current_mismatch = mismatch;
  }
  auto where = [&]() {
    return "point (" + Fixed(best.pose.xy.x(), 2) + ", " + Fixed(best.pose.xy.y(), 2) +
           ") heading " + Fixed(best.pose.entry_heading / kDeg, 1) + " deg, F " +
           Fixed(best.score, 3) + ", d_min " + Fixed(best.scores.min_obstacle_distance, 2) + " m";
  };
  if (current == nullptr || !current->feasible ||
      (!chen2024_ && current->scores.approach_obstacle_distance < min_planned_clearance_)) {
    const std::string why =
        current == nullptr   ? "not among the new candidates"
        : !current->feasible ? current->infeasible
                             : "approach " + Fixed(current->scores.approach_obstacle_distance, 2) +
                                   " m from an obstacle";
    return {&best, true, "re-selected (goal no longer feasible: " + why + "): " + where()};
  }
  if (!chen2024_ && best.score > current->score + 0.05) {
    return {&best, true, "re-selected: " + where()};
  }
  return {current, false, ""};
}

}  // namespace autoshovel::app
