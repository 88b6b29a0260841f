// Fixtures of the dig planning tests (excavator seed §4.2): the shipped 25 t excavator with its
// generated kinematics, synthetic terrain maps in the base frame, and an analytic forward model
// that stands in for the plant in Fig. 13.
//
// The analytic model digs straight cuts: the bucket (the description's width, 1.3 m) sweeps the
// strip of the arm plane from the drag's end to the entry radius, `bucket_width` wide across the
// plane, and takes every cell of that strip down to the cut height (entry height − depth); of what
// it cuts, a share spills over the sides on long drags:
//   V = f(L) · Σ over the strip's cells of max(0, h − z_cut) · cell area        [m^3]
//   f(L) = fill · (1 − spill · max(0, L − 1 m))    (defaults: f = 0.85 for a 2.5 m drag)
//   E = ρ g V (z_lift − z_cut) + k_cut V (1 + depth / 1 m) + k_move · path length   [J]
//       (lifting the load to z_lift = entry height + 1 m, cutting that gets harder with depth,
//        moving the linkage)
//   t = path length / tip speed + curl time                              [s]
// and its tip path is E, P, D of the nominal path followed by the curl: the tip swings back
// 0.3 m and up to 1 m above the entry. Carve() applies the same cut to a map, so a sequence of
// plans on a carved map is a consistent little simulation.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "generated/registry.h"
#include "runtime/control/excavator/excavator_kinematics.h"
#include "runtime/control/excavator/height_grid.h"
#include "runtime/model/description.h"
#include "runtime/planning/dig/dig_action.h"

namespace autoshovel::planning::testing {

inline constexpr double kDeg = std::numbers::pi / 180.0;
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Excavator {
  model::MachineDescription machine;
  const generated::MachineFunctions* functions = nullptr;
  std::unique_ptr<control::ExcavatorKinematics> kinematics;
};

/// The shipped 25 t excavator, loaded once.
inline const Excavator& Excavator25t() {
  static const Excavator* const excavator = [] {
    auto* e = new Excavator;
    const std::string models_dir = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
    e->machine = model::LoadMachineDescription(
        model::ResolveMachineDescription("excavator_25t", models_dir));
    e->functions = generated::FindMachine("excavator_25t");
    if (e->functions == nullptr) throw std::runtime_error("no generated code for excavator_25t");
    e->kinematics = std::make_unique<control::ExcavatorKinematics>(e->machine, *e->functions);
    return e;
  }();
  return *excavator;
}

/// A 24 m × 24 m base-frame map centred on the swing axis, 0.1 m cells, heights from `surface(x,
/// y)` at the cell centres.
inline control::HeightGrid MapFrom(const std::function<double(double, double)>& surface,
                                   double resolution = 0.1) {
  const int n = static_cast<int>(std::lround(24.0 / resolution));
  control::HeightGrid map(Eigen::Vector2d(-12.0, -12.0), resolution, n, n, 0.0);
  for (int iy = 0; iy < n; ++iy) {
    for (int ix = 0; ix < n; ++ix) {
      const Eigen::Vector2d c = map.CellCenter(ix, iy);
      map.set_height(ix, iy, surface(c.x(), c.y()));
    }
  }
  return map;
}

/// A bench in front of the machine: `height` [m] over the annulus radius ∈ [r_min, r_max] within
/// swing ∈ [swing_min, swing_max], the floor at 0 elsewhere.
inline control::HeightGrid BenchMap(double height, double r_min, double r_max, double swing_min,
                                    double swing_max) {
  return MapFrom([=](double x, double y) {
    const double r = std::hypot(x, y), swing = std::atan2(y, x);
    return r >= r_min && r <= r_max && swing >= swing_min && swing <= swing_max ? height : 0.0;
  });
}

struct AnalyticDigModelParams {
  double bucket_width = 1.3;      ///< [m] (the 25 t description's)
  double density = 1800;          ///< [kg/m^3]
  double cutting_energy = 1.5e5;  ///< k_cut [J/m^3]
  double moving_energy = 2.0e4;   ///< k_move [J/m]
  double tip_speed = 0.6;         ///< [m/s]
  double curl_time = 2.0;         ///< [s]
  double spill = 0.1;             ///< share of the cut lost per metre of drag past 1 m [1/m]
  double fill = 1.0;              ///< share of the cut the bucket holds at most [-]
};

class AnalyticDigModel : public DigForwardModel {
 public:
  explicit AnalyticDigModel(const control::HeightGrid& map_base,
                            const AnalyticDigModelParams& params = {})
      : map_(&map_base), params_(params) {}

  DigPrediction Predict(const DigAction& action) override {
    ++calls;
    actions.push_back(action);
    return Evaluate(action);
  }

  /// What Predict returns, without counting a call.
  DigPrediction Evaluate(const DigAction& action) const {
    DigPrediction out;
    out.executed = true;
    const double z_cut = action.entry_height - action.depth;
    ForEachStripCell(*map_, action, [&](int ix, int iy) {
      const double h = map_->height(ix, iy);
      if (std::isfinite(h) && h > z_cut) {
        out.volume += (h - z_cut) * map_->resolution() * map_->resolution();
      }
    });
    out.volume *= params_.fill * (1.0 - params_.spill * std::max(0.0, action.drag_length - 1.0));
    out.tip_path = TipPath(action);
    double length = 0;
    for (std::size_t i = 1; i < out.tip_path.size(); ++i) {
      length += (out.tip_path[i] - out.tip_path[i - 1]).norm();
    }
    const double lift = action.entry_height + 1.0 - z_cut;
    out.energy = params_.density * 9.81 * out.volume * lift +
                 params_.cutting_energy * out.volume * (1.0 + action.depth) +
                 params_.moving_energy * length;
    out.duration = length / params_.tip_speed + params_.curl_time;
    return out;
  }

  /// E, P, D and the curl: back 0.3 m and up to 1 m above the entry.
  static std::vector<Eigen::Vector3d> TipPath(const DigAction& a) {
    auto at = [&](double r, double z) {
      return Eigen::Vector3d(r * std::cos(a.swing), r * std::sin(a.swing), z);
    };
    const double z_cut = a.entry_height - a.depth;
    const double r_end = a.radius - a.drag_length;
    return {at(a.radius, a.entry_height), at(a.radius, z_cut), at(r_end, z_cut),
            at(r_end - 0.3, a.entry_height + 1.0)};
  }

  /// Cells whose centre lies in the strip the bucket sweeps: radial distance in [r − L, r] along
  /// the arm plane, within half the bucket width across it.
  void ForEachStripCell(const control::HeightGrid& map, const DigAction& a,
                        const std::function<void(int, int)>& visit) const {
    const Eigen::Vector2d along(std::cos(a.swing), std::sin(a.swing));
    const Eigen::Vector2d across(-along.y(), along.x());
    const double half = 0.5 * params_.bucket_width;
    const double r0 = a.radius - a.drag_length;
    // Bounding box of the strip's four corners, in cells, clamped to the grid.
    Eigen::Vector2d lo = r0 * along - half * across, hi = lo;
    for (const Eigen::Vector2d& corner : {Eigen::Vector2d(r0 * along + half * across),
                                          Eigen::Vector2d(a.radius * along - half * across),
                                          Eigen::Vector2d(a.radius * along + half * across)}) {
      lo = lo.cwiseMin(corner);
      hi = hi.cwiseMax(corner);
    }
    auto cell = [&](double v, double origin, int n) {
      return std::clamp(static_cast<int>(std::floor((v - origin) / map.resolution())), 0, n - 1);
    };
    const int ix0 = cell(lo.x(), map.origin().x(), map.nx());
    const int ix1 = cell(hi.x(), map.origin().x(), map.nx());
    const int iy0 = cell(lo.y(), map.origin().y(), map.ny());
    const int iy1 = cell(hi.y(), map.origin().y(), map.ny());
    for (int iy = iy0; iy <= iy1; ++iy) {
      for (int ix = ix0; ix <= ix1; ++ix) {
        const Eigen::Vector2d c = map.CellCenter(ix, iy);
        const double s = c.dot(along), t = c.dot(across);
        if (s >= r0 && s <= a.radius && std::abs(t) <= half) visit(ix, iy);
      }
    }
  }

  /// Takes the cut out of `map` (cells of the strip above the cut height come down to it).
  void Carve(control::HeightGrid& map, const DigAction& a) const {
    const double z_cut = a.entry_height - a.depth;
    ForEachStripCell(map, a, [&](int ix, int iy) {
      const double h = map.height(ix, iy);
      if (std::isfinite(h) && h > z_cut) map.set_height(ix, iy, z_cut);
    });
  }

  int calls = 0;
  std::vector<DigAction> actions;

 private:
  const control::HeightGrid* map_;
  AnalyticDigModelParams params_;
};

/// Wraps a model and rewrites its predictions, counting calls.
class RewritingModel : public DigForwardModel {
 public:
  RewritingModel(DigForwardModel& inner,
                 std::function<void(const DigAction&, DigPrediction&)> rewrite)
      : inner_(&inner), rewrite_(std::move(rewrite)) {}
  DigPrediction Predict(const DigAction& action) override {
    ++calls;
    DigPrediction p = inner_->Predict(action);
    rewrite_(action, p);
    return p;
  }
  int calls = 0;

 private:
  DigForwardModel* inner_;
  std::function<void(const DigAction&, DigPrediction&)> rewrite_;
};

}  // namespace autoshovel::planning::testing
