#include "runtime/prediction/volume_estimation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace autoshovel::prediction {

double HeightGrid::HeightAt(double x, double y) const {
  const int ix = static_cast<int>(std::floor((x - origin.x()) / resolution));
  const int iy = static_cast<int>(std::floor((y - origin.y()) / resolution));
  if (!InBounds(ix, iy)) return std::numeric_limits<double>::quiet_NaN();
  return at(ix, iy);
}

SweptVolume Eq19Volume(const HeightGrid& map, const std::vector<Eigen::Vector3d>& tip_path,
                       double bucket_width) {
  if (!(bucket_width > 0)) {
    throw std::invalid_argument("Eq19Volume: bucket width must be > 0 m, got " +
                                std::to_string(bucket_width));
  }
  if (map.height.size() != static_cast<std::size_t>(map.nx) * static_cast<std::size_t>(map.ny) ||
      !(map.resolution > 0)) {
    throw std::invalid_argument("Eq19Volume: grid of " + std::to_string(map.nx) + " x " +
                                std::to_string(map.ny) + " cells has " +
                                std::to_string(map.height.size()) + " heights, resolution " +
                                std::to_string(map.resolution) + " m");
  }
  SweptVolume result;
  if (tip_path.size() < 2) return result;
  const double half_width = 0.5 * bucket_width;
  const double eps = map.resolution;
  // h'_i per swept cell: the lowest tip over the cell among all segments (sparse: the strip is
  // small against the map).
  std::vector<std::pair<int, double>> lowest;  // cell index, tip height
  std::vector<int> slot(map.height.size(), -1);
  for (std::size_t k = 0; k + 1 < tip_path.size(); ++k) {
    const Eigen::Vector2d a = tip_path[k].head<2>(), b = tip_path[k + 1].head<2>();
    const Eigen::Vector2d ab = b - a;
    const double length = ab.norm();
    if (length < 1e-9) continue;  // a purely vertical move sweeps no new cell
    const Eigen::Vector2d along = ab / length;
    const Eigen::Vector2d across(-along.y(), along.x());
    const double lo_x = std::min(a.x(), b.x()) - half_width,
                 hi_x = std::max(a.x(), b.x()) + half_width;
    const double lo_y = std::min(a.y(), b.y()) - half_width,
                 hi_y = std::max(a.y(), b.y()) + half_width;
    const int ix0 = std::max(0, static_cast<int>(std::floor((lo_x - map.origin.x()) / eps)));
    const int ix1 =
        std::min(map.nx - 1, static_cast<int>(std::floor((hi_x - map.origin.x()) / eps)));
    const int iy0 = std::max(0, static_cast<int>(std::floor((lo_y - map.origin.y()) / eps)));
    const int iy1 =
        std::min(map.ny - 1, static_cast<int>(std::floor((hi_y - map.origin.y()) / eps)));
    for (int iy = iy0; iy <= iy1; ++iy) {
      for (int ix = ix0; ix <= ix1; ++ix) {
        const Eigen::Vector2d d = map.CellCenter(ix, iy) - a;
        const double s = d.dot(along);
        // Half-open along the segment, so a cell on a joint of two segments is taken once
        // (the min below makes it harmless either way); the last segment closes its end.
        const bool last = k + 2 == tip_path.size();
        if (s < 0 || s > length || (!last && s == length)) continue;
        if (std::abs(d.dot(across)) > half_width) continue;
        const double z = tip_path[k].z() + (tip_path[k + 1].z() - tip_path[k].z()) * (s / length);
        const std::size_t index = static_cast<std::size_t>(iy) * map.nx + ix;
        if (slot[index] < 0) {
          slot[index] = static_cast<int>(lowest.size());
          lowest.emplace_back(static_cast<int>(index), z);
        } else {
          double& h = lowest[slot[index]].second;
          h = std::min(h, z);
        }
      }
    }
  }
  for (const auto& [index, tip_height] : lowest) {
    ++result.cells;
    const double h = map.height[index];
    if (std::isnan(h)) {
      ++result.unknown_cells;
      continue;
    }
    result.volume += std::max(h - tip_height, 0.0) * eps * eps;
  }
  return result;
}

Eigen::Vector2d TipInBase(const model::MachineDescription& machine, double q_boom,
                          double q_bucket) {
  if (machine.links.size() != 2) {
    throw std::invalid_argument("TipInBase: needs a two-link loader arm, '" + machine.name +
                                "' has " + std::to_string(machine.links.size()) + " links");
  }
  const double phi1 = q_boom, phi2 = q_boom + q_bucket;
  return machine.arm_pivot +
         machine.links[0].length * Eigen::Vector2d(std::cos(phi1), std::sin(phi1)) +
         machine.links[1].length * Eigen::Vector2d(std::cos(phi2), std::sin(phi2));
}

std::string ScoopPlan::Invalid() const {
  auto bad = [](double value, const char* name, const char* unit) {
    return std::string(name) + " must be finite and >= 0 " + unit + ", got " +
           std::to_string(value);
  };
  if (!(delay >= 0) || !std::isfinite(delay)) return bad(delay, "delay", "s");
  if (!(bucket_rate >= 0) || !std::isfinite(bucket_rate)) {
    return bad(bucket_rate, "bucket_rate", "rad/s");
  }
  if (!(bucket_curl >= 0) || !std::isfinite(bucket_curl))
    return bad(bucket_curl, "bucket_curl", "rad");
  if (!(boom_rate >= 0) || !std::isfinite(boom_rate)) return bad(boom_rate, "boom_rate", "rad/s");
  if (!(boom_lift >= 0) || !std::isfinite(boom_lift)) return bad(boom_lift, "boom_lift", "rad");
  for (std::size_t i = 0; i < bucket_rate_along_curl.size(); ++i) {
    const double r = bucket_rate_along_curl[i];
    if (!(r >= 0) || !std::isfinite(r)) {
      return bad(r, ("bucket_rate_along_curl[" + std::to_string(i) + "]").c_str(), "rad/s");
    }
  }
  if (travel_times.size() != travel_at.size()) {
    return "travel_times and travel_at differ in length (" + std::to_string(travel_times.size()) +
           " and " + std::to_string(travel_at.size()) + ")";
  }
  for (std::size_t i = 0; i < travel_times.size(); ++i) {
    const double before = i == 0 ? 0.0 : travel_times[i - 1];
    if (!std::isfinite(travel_times[i]) || !(travel_times[i] > before)) {
      return "travel_times must be finite, > 0 and increasing, got " +
             std::to_string(travel_times[i]) + " at " + std::to_string(i);
    }
    if (!std::isfinite(travel_at[i])) {
      return "travel_at[" + std::to_string(i) + "] is not finite";
    }
  }
  if (!(time_step > 0) || !std::isfinite(time_step)) {
    return "time_step must be > 0 s, got " + std::to_string(time_step);
  }
  if (!(horizon > 0) || !std::isfinite(horizon) || horizon / time_step > 1e6) {
    return "horizon must be > 0 s and at most 1e6 time steps, got " + std::to_string(horizon);
  }
  return {};
}

namespace {

// Joint rate of `joint` at valve command `command` ∈ (0, 1]: the valve's rated flow (load-
// sensing, so flow follows the opening past the dead zone) into the cap side, over the piston
// area and the lever arm dL/dq [rad/s].
double JointRate(const model::MachineDescription& machine,
                 const generated::MachineFunctions& functions, int joint,
                 const std::vector<double>& q, double command) {
  const int a = machine.ActuatorOfJoint(static_cast<std::size_t>(joint));
  if (a < 0) {
    throw std::invalid_argument("ScoopPlanFromMachine: no actuator drives joint " +
                                std::to_string(joint) + " of '" + machine.name + "'");
  }
  const model::Actuator& act = machine.hydraulics.actuators[a];
  const double opening =
      std::clamp((std::abs(command) - act.valve.dead_zone) / (1 - act.valve.dead_zone), 0.0, 1.0);
  const double area = act.count * std::numbers::pi / 4 * act.bore * act.bore;
  const double lever = std::abs(functions.lever_arm(a, q.data()));
  if (act.kind != model::ActuatorKind::kCylinder || area <= 0 || lever < 1e-6) {
    throw std::invalid_argument("ScoopPlanFromMachine: actuator '" + act.name +
                                "' is not a cylinder with a lever arm");
  }
  return opening * act.valve.rated_flow / area / lever;
}

}  // namespace

ScoopPlan ScoopPlanFromMachine(const model::MachineDescription& machine,
                               const generated::MachineFunctions& functions,
                               const std::vector<double>& q, double bucket_command,
                               double boom_command, double bucket_curl, double boom_lift) {
  if (machine.links.size() != 2 || q.size() < 2) {
    throw std::invalid_argument(
        "ScoopPlanFromMachine: needs a two-link loader arm and two joint "
        "positions, got " +
        std::to_string(machine.links.size()) + " links and " + std::to_string(q.size()) +
        " joints");
  }
  ScoopPlan plan;
  const int tilt = machine.ActuatorOfJoint(1);
  if (tilt < 0) throw std::invalid_argument("ScoopPlanFromMachine: no actuator on the bucket");
  const model::Valve& valve = machine.hydraulics.actuators[tilt].valve;
  plan.delay = valve.transport_delay + valve.spool_time_constant;
  plan.bucket_rate = JointRate(machine, functions, 1, q, bucket_command);
  plan.boom_rate = JointRate(machine, functions, 0, q, boom_command);
  plan.bucket_curl = bucket_curl;
  plan.boom_lift = boom_lift;
  constexpr int kCurlSamples = 16;
  if (bucket_curl > 0) {
    std::vector<double> at = q;
    for (int k = 0; k <= kCurlSamples; ++k) {
      at[1] = q[1] + bucket_curl * k / kCurlSamples;
      plan.bucket_rate_along_curl.push_back(JointRate(machine, functions, 1, at, bucket_command));
    }
  }
  return plan;
}

CurlSchedule PlanCurl(const ScoopPlan& plan) {
  // Explicit Euler on the time grid: over one 20 ms step the rate changes by well under 1 %.
  auto rate_at = [&](double curl) {
    const std::vector<double>& table = plan.bucket_rate_along_curl;
    if (table.size() < 2 || plan.bucket_curl <= 0) return plan.bucket_rate;
    const double f =
        std::clamp(curl / plan.bucket_curl, 0.0, 1.0) * static_cast<double>(table.size() - 1);
    const std::size_t i = std::min(static_cast<std::size_t>(f), table.size() - 2);
    return table[i] + (f - static_cast<double>(i)) * (table[i + 1] - table[i]);
  };
  const double dt = plan.time_step;
  CurlSchedule out;
  out.curl.push_back(0.0);
  out.t_curled = plan.bucket_curl <= 0 ? plan.delay : plan.horizon;
  for (int k = 1; k * dt <= plan.horizon + 1e-12; ++k) {
    double c = out.curl.back();
    if (k * dt > plan.delay && c < plan.bucket_curl) {
      c = std::min(c + rate_at(c) * dt, plan.bucket_curl);
      if (c >= plan.bucket_curl) out.t_curled = k * dt;
    }
    out.curl.push_back(c);
  }
  return out;
}

FutureVolume PredictFutureVolume(const model::MachineDescription& machine, const HeightGrid& map,
                                 const std::vector<Eigen::Vector3d>& past_path,
                                 const MachineAtTrigger& at_trigger, double penetration,
                                 const ScoopPlan& plan) {
  if (const std::string why = plan.Invalid(); !why.empty()) {
    throw std::invalid_argument("PredictFutureVolume: scoop plan: " + why);
  }
  if (!(penetration >= 0) || !std::isfinite(penetration)) {
    throw std::invalid_argument("PredictFutureVolume: penetration must be finite and >= 0 m, got " +
                                std::to_string(penetration));
  }
  if (at_trigger.q.size() < 2 || !std::isfinite(at_trigger.speed)) {
    throw std::invalid_argument("PredictFutureVolume: needs two joint positions and a speed");
  }
  const double v = std::max(at_trigger.speed, 0.0);
  const double d = penetration;
  const double dt = plan.time_step;
  const CurlSchedule schedule = PlanCurl(plan);
  const std::vector<double>& curl_at = schedule.curl;
  const double t_curled = schedule.t_curled;
  const double t_lifted =
      std::min(t_curled + (plan.boom_rate > 0 ? plan.boom_lift / plan.boom_rate : plan.horizon),
               plan.horizon);
  // Travel: through the predicted knots when the plan has them, else a constant deceleration
  // from v to rest over d. A machine that is (nearly) at rest yet predicted to move covers d at
  // the slowest pace we consider (0.1 m/s).
  const double v_start = std::max(v, 0.1);
  std::vector<double> knot_t = {0.0}, knot_s = {0.0};
  for (std::size_t i = 0; i < plan.travel_times.size(); ++i) {
    knot_t.push_back(plan.travel_times[i]);
    knot_s.push_back(std::clamp(plan.travel_at[i], knot_s.back(), std::max(d, knot_s.back())));
  }
  // From the last knot (t = 0 without knots): constant deceleration over what is left of d.
  const double t_last = knot_t.back(), s_last = knot_s.back();
  const double v_last =
      knot_t.size() < 2
          ? v_start
          : std::max((s_last - knot_s[knot_s.size() - 2]) / (t_last - knot_t[knot_t.size() - 2]),
                     0.1);
  const double rest = std::max(d - s_last, 0.0);
  const double t_stop = t_last + (rest > 0 ? 2 * rest / v_last : 0.0);
  auto travel = [&](double t) {
    if (t >= t_stop) return s_last + rest;
    if (t >= t_last) {
      const double u = t - t_last;
      return s_last + v_last * u - v_last * v_last * u * u / (4 * rest);
    }
    const std::size_t i = static_cast<std::size_t>(
        std::upper_bound(knot_t.begin(), knot_t.end(), t) - knot_t.begin() - 1);
    return knot_s[i] + (t - knot_t[i]) / (knot_t[i + 1] - knot_t[i]) * (knot_s[i + 1] - knot_s[i]);
  };
  const double t_end = std::min(std::max(t_stop, t_lifted), plan.horizon);
  const Eigen::Vector2d forward(std::cos(at_trigger.heading), std::sin(at_trigger.heading));

  FutureVolume out;
  const double q_boom0 = at_trigger.q[0], q_bucket0 = at_trigger.q[1];
  const int steps = static_cast<int>(std::ceil(t_end / dt));
  for (int k = 0; k <= steps; ++k) {
    const double t = std::min(k * dt, t_end);
    const double curl =
        curl_at[std::min(static_cast<std::size_t>(std::lround(t / dt)), curl_at.size() - 1)];
    const double lift = std::clamp((t - t_curled) * plan.boom_rate, 0.0, plan.boom_lift);
    const Eigen::Vector2d tip = TipInBase(machine, q_boom0 + lift, q_bucket0 + curl);
    const Eigen::Vector2d xy = at_trigger.hinge_xy + (travel(t) + tip.x()) * forward;
    out.path.emplace_back(xy.x(), xy.y(), tip.y());
    if (t <= plan.delay) out.delay_points = static_cast<int>(out.path.size());
  }

  // Eq. (19) over past + future, less the past: cells are counted once, at their lowest tip.
  const double width = machine.bucket.width;
  std::vector<Eigen::Vector3d> path = past_path;
  const double v1 = Eq19Volume(map, path, width).volume;
  path.insert(path.end(), out.path.begin(), out.path.begin() + out.delay_points);
  const double through_delay = Eq19Volume(map, path, width).volume;
  path.insert(path.end(), out.path.begin() + out.delay_points, out.path.end());
  const double through_scoop = Eq19Volume(map, path, width).volume;
  out.v21 = std::max(through_delay - v1, 0.0);
  out.v22 = std::max(through_scoop - through_delay, 0.0);
  return out;
}

}  // namespace autoshovel::prediction
