#include "runtime/control/excavator/dig_motion.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace autoshovel::control {
namespace {

void Require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("DigMotion: ") + what);
}

}  // namespace

void Validate(const DigMotionSettings& s) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  auto non_negative = [](double v) { return std::isfinite(v) && v >= 0; };
  Require(non_negative(s.approach_height), "approach_height must be finite and >= 0");
  Require(std::isfinite(s.entry_attitude) && std::isfinite(s.drag_end_attitude) &&
              std::isfinite(s.curl_attitude),
          "attitudes must be finite");
  Require(std::isfinite(s.drag_rise), "drag_rise must be finite");
  Require(non_negative(s.curl_rise), "curl_rise must be finite and >= 0");
  Require(std::isfinite(s.lift_height), "lift_height must be finite");
  Require(positive(s.penetrate_speed) && positive(s.drag_speed) && positive(s.curl_speed) &&
              positive(s.lift_speed),
          "speeds must be finite and > 0");
  Require(positive(s.max_lead), "max_lead must be finite and > 0");
  Require(non_negative(s.stall_speed) && positive(s.stall_window) && non_negative(s.stall_raise),
          "stall_speed, stall_window, stall_raise must be finite (window > 0)");
  Require(s.max_stalls >= 0, "max_stalls must be >= 0");
  Require(positive(s.finish_tolerance), "finish_tolerance must be finite and > 0");
  Require(positive(s.max_duration), "max_duration must be finite and > 0");
}

const char* ToString(DigPhase phase) {
  switch (phase) {
    case DigPhase::kApproach:
      return "approach";
    case DigPhase::kPenetrate:
      return "penetrate";
    case DigPhase::kDrag:
      return "drag";
    case DigPhase::kCurl:
      return "curl";
    case DigPhase::kLift:
      return "lift";
    case DigPhase::kDone:
      return "done";
    case DigPhase::kFailed:
      return "failed";
  }
  return "?";
}

DigMotion::DigMotion(const ExcavatorKinematics& kinematics, const DigStroke& stroke,
                     const DigMotionSettings& settings)
    : kinematics_(kinematics), stroke_(stroke), settings_(settings) {
  Validate(settings_);
  Require(std::isfinite(stroke.swing) && std::isfinite(stroke.radius) &&
              std::isfinite(stroke.entry_height) && std::isfinite(stroke.depth) &&
              std::isfinite(stroke.drag_length),
          "the stroke must be finite");
  Require(stroke.depth >= 0 && stroke.drag_length >= 0,
          "depth and drag length must be non-negative");
  const DigMotionSettings& s = settings_;
  const Eigen::Vector2d entry(stroke.radius, stroke.entry_height);
  const Eigen::Vector2d approach = entry + Eigen::Vector2d(0, s.approach_height);
  const Eigen::Vector2d bottom = entry - Eigen::Vector2d(0, stroke.depth);
  const Eigen::Vector2d drag_end = bottom + Eigen::Vector2d(-stroke.drag_length, s.drag_rise);
  const Eigen::Vector2d curled = drag_end + Eigen::Vector2d(0, s.curl_rise);
  const Eigen::Vector2d lifted(curled.x(), std::max(curled.y(), entry.y() + s.lift_height));
  waypoints_ = {
      {approach, s.entry_attitude, s.penetrate_speed, DigPhase::kApproach},
      {bottom, s.entry_attitude, s.penetrate_speed, DigPhase::kPenetrate},
      {drag_end, s.drag_end_attitude, s.drag_speed, DigPhase::kDrag},
      {curled, s.curl_attitude, s.curl_speed, DigPhase::kCurl},
      {lifted, s.curl_attitude, s.lift_speed, DigPhase::kLift},
  };
  // Each waypoint's attitude is made one the bucket can take there (the nearest to the one asked
  // for), so that the measured attitude can reach it and progress along the curl is measurable.
  for (Waypoint& w : waypoints_) {
    if (const std::optional<JointVector> q = Solve({w.p, w.attitude})) {
      w.attitude = (*q)[0] + (*q)[1] + (*q)[2];
    }
  }
  RecomputeLengths();
  last_command_.position = JointVector::Zero();
  last_command_.stop = true;
}

void DigMotion::RecomputeLengths() {
  cumulative_.assign(waypoints_.size(), 0.0);
  for (std::size_t i = 1; i < waypoints_.size(); ++i) {
    // The curl turns the bucket about a nearly fixed tip: its length in the path's metric is the
    // larger of the tip's travel and half the attitude change at the bucket's length, so that its
    // speed paces the curl too.
    const double turn = std::abs(waypoints_[i].attitude - waypoints_[i - 1].attitude) *
                        kinematics_.link_lengths()[2];
    cumulative_[i] = cumulative_[i - 1] +
                     std::max((waypoints_[i].p - waypoints_[i - 1].p).norm(), 0.5 * turn) + 1e-6;
  }
}

DigMotion::PathPoint DigMotion::At(double s) const {
  s = std::clamp(s, 0.0, Length());
  std::size_t i = 1;
  while (i + 1 < waypoints_.size() && cumulative_[i] < s) ++i;
  const double span = cumulative_[i] - cumulative_[i - 1];
  const double f = span > 0 ? std::clamp((s - cumulative_[i - 1]) / span, 0.0, 1.0) : 1.0;
  return {waypoints_[i - 1].p + f * (waypoints_[i].p - waypoints_[i - 1].p),
          waypoints_[i - 1].attitude + f * (waypoints_[i].attitude - waypoints_[i - 1].attitude)};
}

DigPhase DigMotion::PhaseAt(double s) const {
  for (std::size_t i = 1; i < waypoints_.size(); ++i) {
    if (s < cumulative_[i]) return waypoints_[i].phase;
  }
  return DigPhase::kLift;
}

double DigMotion::Project(const Eigen::Vector2d& tip, double attitude, double s_hint) const {
  // Only near the last projection: the path folds back on itself where the curl turns the
  // bucket in place, and a global nearest point could jump ahead.
  const double from = std::max(0.0, s_hint - 0.3), to = std::min(Length(), s_hint + 0.6);
  double best_s = from, best_d = std::numeric_limits<double>::infinity();
  for (double s = from; s <= to + 1e-9; s += 0.01) {
    // The attitude weighs as the arc half the bucket's length sweeps (RecomputeLengths' metric).
    const PathPoint point = At(s);
    const double turn = 0.5 * kinematics_.link_lengths()[2] * (point.attitude - attitude);
    const double d = (point.p - tip).squaredNorm() + turn * turn;
    if (d < best_d) best_d = d, best_s = s;
  }
  return best_s;
}

std::optional<JointVector> DigMotion::Solve(const PathPoint& point) const {
  const Eigen::Vector3d p_base = ExcavatorKinematics::BaseFromArmPlane(stroke_.swing, point.p);
  auto within_limits = [&](const JointVector& q) {
    for (int j = 0; j < 3; ++j) {
      if (q[j] < kinematics_.joint_min()[j] - 1e-9 || q[j] > kinematics_.joint_max()[j] + 1e-9) {
        return false;
      }
    }
    return true;
  };
  // The attitude asked for first, then the nearest ones either side: where the bucket's joint
  // range does not allow it, the tip position matters more than the attitude.
  for (int k = 0; k <= 16; ++k) {
    for (int side : {1, -1}) {
      if (k == 0 && side < 0) continue;
      std::optional<JointVector> q = kinematics_.SolveTip(p_base, point.attitude + side * k * 0.05);
      if (q && within_limits(*q)) {
        (*q)[3] = stroke_.swing;
        return q;
      }
    }
  }
  return std::nullopt;
}

std::optional<JointVector> DigMotion::ApproachPose() const { return Solve(At(0.0)); }

void DigMotion::RaiseFrom(double s, double dz) {
  for (std::size_t i = 0; i < waypoints_.size(); ++i) {
    if (cumulative_[i] > s) waypoints_[i].p.y() += dz;
  }
}

std::vector<Eigen::Vector3d> DigMotion::PlannedTipPath(double spacing) const {
  std::vector<Eigen::Vector3d> out;
  const double step = spacing > 0 ? spacing : 0.1;
  for (double s = 0; s < Length(); s += step) {
    out.push_back(ExcavatorKinematics::BaseFromArmPlane(stroke_.swing, At(s).p));
  }
  out.push_back(ExcavatorKinematics::BaseFromArmPlane(stroke_.swing, At(Length()).p));
  return out;
}

ExcavatorCommand DigMotion::Step(const ExcavatorState& measured, double time) {
  if (phase_ == DigPhase::kDone || phase_ == DigPhase::kFailed) return last_command_;
  auto fail = [&](const std::string& why) {
    phase_ = DigPhase::kFailed;
    failure_ = why;
    last_command_ = ExcavatorCommand{};
    last_command_.stop = true;
    return last_command_;
  };
  if (FirstNonFinite(measured.q) >= 0 || !std::isfinite(time)) {
    return fail("non-finite joint state or time");
  }
  if (!std::isfinite(start_time_)) start_time_ = last_time_ = time;
  const double dt = std::max(0.0, time - last_time_);
  last_time_ = time;
  if (time - start_time_ > settings_.max_duration) return fail("dig took too long");

  const Eigen::Vector3d tip = kinematics_.TipPosition(measured.q);
  const Eigen::Vector2d tip_plane(
      tip.x() * std::cos(stroke_.swing) + tip.y() * std::sin(stroke_.swing), tip.z());
  if (phase_ == DigPhase::kApproach) {
    if ((tip_plane - At(0).p).norm() <= 2 * settings_.finish_tolerance &&
        std::abs(measured.q[3] - stroke_.swing) < 0.02) {
      phase_ = DigPhase::kPenetrate;
      s_ref_ = s_tip_ = 0;
      window_start_time_ = time;
      window_start_s_ = 0;
    }
  } else {
    s_tip_ = Project(tip_plane, measured.q[0] + measured.q[1] + measured.q[2], s_tip_);
    // The segment speed at the reference: segments end at waypoints, each with its own speed.
    double speed = waypoints_.back().speed;
    for (std::size_t i = 1; i < waypoints_.size(); ++i) {
      if (s_ref_ < cumulative_[i]) {
        speed = waypoints_[i].speed;
        break;
      }
    }
    s_ref_ = std::min({s_ref_ + speed * dt, s_tip_ + settings_.max_lead, Length()});
    phase_ = PhaseAt(s_ref_);
    if (time - window_start_time_ >= settings_.stall_window) {
      const double progress = (s_tip_ - window_start_s_) / (time - window_start_time_);
      if (phase_ == DigPhase::kDrag && progress < settings_.stall_speed) {
        ++stalls_;
        if (stalls_ > settings_.max_stalls) {
          // Too heavy however shallow: end the drag where the tip is and curl from there.
          const Eigen::Vector2d shift = At(s_tip_).p - waypoints_[2].p;
          for (std::size_t i = 2; i < waypoints_.size(); ++i) waypoints_[i].p += shift;
          RecomputeLengths();
          s_ref_ = s_tip_ = cumulative_[2];
        } else {
          RaiseFrom(s_tip_, settings_.stall_raise);
        }
      }
      window_start_time_ = time;
      window_start_s_ = s_tip_;
    }
    if (s_ref_ >= Length() - 1e-9 &&
        (tip_plane - At(Length()).p).norm() <= settings_.finish_tolerance) {
      phase_ = DigPhase::kDone;
    }
  }
  const std::optional<JointVector> q = Solve(At(s_ref_));
  if (!q) return fail("the dig path leaves the arm's reach");
  last_command_.position = *q;
  last_command_.stop = false;
  return last_command_;
}

}  // namespace autoshovel::control
