#include "runtime/model/spec_sheet.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "runtime/model/dual.h"
#include "runtime/model/interpreted_model.h"
#include "runtime/model/plant_constants.h"

namespace autoshovel::model {
namespace {

constexpr double kPi = std::numbers::pi;

double Lerp(double a, double b, double t) { return a + (b - a) * t; }

double WrapAngle(double angle) { return std::remainder(angle, 2 * kPi); }

// Link frame origins and angles in M (doubles).
void Frames(const InterpretedModel& model, const double* q, std::vector<V2<double>>& origins,
            std::vector<double>& angles) {
  model.LinkFrames(q, origins, angles);
}

// A point of the bucket frame in the base frame [x, z].
Eigen::Vector2d BucketPointInBase(const MachineDescription& m, const InterpretedModel& model,
                                  const double* q, const Eigen::Vector2d& p_bucket) {
  std::vector<V2<double>> origins;
  std::vector<double> angles;
  Frames(model, q, origins, angles);
  const int last = static_cast<int>(m.links.size()) - 1;
  const V2<double> p = origins[last] + internal::Rotate(angles[last], p_bucket);
  return m.arm_pivot + Eigen::Vector2d(p.x, p.z);
}

// ∂z/∂q_i of a bucket-frame point, for every link joint i.
std::vector<double> PointHeightGradient(const MachineDescription& m, const InterpretedModel& model,
                                        const double* q, const Eigen::Vector2d& p_bucket) {
  const int n = static_cast<int>(m.links.size());
  const int J = static_cast<int>(m.num_joints());
  std::vector<double> gradient(J, 0.0);
  for (int i = 0; i < n; ++i) {
    std::vector<Dual<double>> seeded(J);
    for (int k = 0; k < J; ++k) seeded[k] = Dual<double>(q[k], k == i ? 1.0 : 0.0);
    std::vector<V2<Dual<double>>> origins;
    std::vector<Dual<double>> angles;
    model.LinkFrames(seeded.data(), origins, angles);
    const V2<Dual<double>> p = origins[n - 1] + internal::Rotate(angles[n - 1], p_bucket);
    gradient[i] = p.z.d;
  }
  return gradient;
}

double Dot(const std::vector<double>& a, const Eigen::VectorXd& b) {
  double sum = 0;
  for (int i = 0; i < b.size(); ++i) sum += a[i] * b[i];
  return sum;
}

// The joint motion left free when every cylinder but `driving` is locked (their lengths held):
// the null space of the locked cylinders' lever rows over the link joints. Unit length.
Eigen::VectorXd FreeMotion(const MachineDescription& m, const InterpretedModel& model,
                           const double* q, int driving) {
  const int n = static_cast<int>(m.links.size());
  Eigen::MatrixXd locked(std::max(n - 1, 1), n);
  locked.setZero();
  int row = 0;
  for (int j = 0; j < n; ++j) {
    const int a = m.ActuatorOfJoint(j);
    if (a == driving) continue;
    const std::vector<double> lever = model.LeverArms(a, q);
    for (int i = 0; i < n; ++i) locked(row, i) = lever[i];
    ++row;
  }
  const Eigen::MatrixXd kernel = Eigen::FullPivLU<Eigen::MatrixXd>(locked).kernel();
  if (kernel.cols() != 1) {
    throw std::invalid_argument("the locked cylinders do not leave exactly one free motion");
  }
  return kernel.col(0).normalized();
}

// Cap-side and annulus areas of an actuator (all its parallel cylinders) [m²].
void Areas(const Actuator& a, double& cap, double& annulus) {
  cap = a.count * kPi / 4 * a.bore * a.bore;
  annulus = a.count * kPi / 4 * (a.bore * a.bore - a.rod * a.rod);
}

}  // namespace

bool CylinderMovesWithEarlierJoints(const MachineDescription& m, int joint) {
  const int actuator = m.ActuatorOfJoint(joint);
  if (actuator < 0 || m.hydraulics.actuators[actuator].kind != ActuatorKind::kCylinder)
    return false;
  const InterpretedModel model(m);
  std::vector<double> q(m.num_joints(), 0.0);
  for (std::size_t k = 0; k < m.links.size(); ++k) {
    q[k] = Lerp(m.links[k].joint_min, m.links[k].joint_max, 0.5);
  }
  const std::vector<double> lever = model.LeverArms(actuator, q.data());
  for (int k = 0; k < joint; ++k) {
    if (std::abs(lever[k]) > 1e-9) return true;
  }
  return false;
}

JointWindow ReachableJointWindow(const MachineDescription& m, int joint, const double* q_in,
                                 double extend) {
  const Link& link = m.links[joint];
  JointWindow w;
  const int actuator = m.ActuatorOfJoint(joint);
  if (actuator < 0 || m.hydraulics.actuators[actuator].kind != ActuatorKind::kCylinder) {
    w.min = link.joint_min;
    w.max = link.joint_max;
    w.empty = false;
    return w;
  }
  const Actuator& a = m.hydraulics.actuators[actuator];
  const InterpretedModel model(m);
  std::vector<double> q(q_in, q_in + m.num_joints());
  const auto inside = [&](double angle) {
    q[joint] = angle;
    const double length = model.CylinderLength(actuator, q.data());
    return std::isfinite(length) && length >= a.retracted_length - 1e-9 &&
           length <= a.retracted_length + a.stroke + 1e-9;
  };
  // Samples every 0.25°; the run of reachable samples nearest the limits' middle, then its two
  // ends bisected to 1e-7 rad.
  const double low = link.joint_min - extend, high = link.joint_max + extend;
  const int n = std::max(2, static_cast<int>(std::ceil((high - low) / (0.25 * kPi / 180))) + 1);
  const auto angle = [&](int i) { return low + (high - low) * i / (n - 1); };
  const double middle = (link.joint_min + link.joint_max) / 2;
  int seed = -1;
  for (int i = 0; i < n; ++i) {
    if (inside(angle(i)) &&
        (seed < 0 || std::abs(angle(i) - middle) < std::abs(angle(seed) - middle))) {
      seed = i;
    }
  }
  if (seed < 0) return w;
  int first = seed, last = seed;
  while (first > 0 && inside(angle(first - 1))) --first;
  while (last < n - 1 && inside(angle(last + 1))) ++last;
  const auto refine = [&](double in, double out) {
    for (int k = 0; k < 40 && std::abs(out - in) > 1e-7; ++k) {
      const double mid = (in + out) / 2;
      (inside(mid) ? in : out) = mid;
    }
    return in;
  };
  w.min = first > 0 ? refine(angle(first), angle(first - 1)) : angle(first);
  w.max = last < n - 1 ? refine(angle(last), angle(last + 1)) : angle(last);
  w.empty = false;
  return w;
}

std::vector<double> CarryPose(const MachineDescription& m) {
  std::vector<double> q(m.num_joints(), 0.0);
  if (m.kind == MachineKind::kWheelLoader) {
    q[0] = Lerp(m.links[0].joint_min, m.links[0].joint_max, 0.2);
    q[1] = m.links[1].joint_max;
    // A frame-mounted tilt cylinder may stop the bucket short of its limit at this boom angle.
    if (CylinderMovesWithEarlierJoints(m, 1)) {
      const JointWindow w = ReachableJointWindow(m, 1, q.data());
      if (!w.empty) q[1] = std::min(q[1], w.max);
    }
  } else {
    for (std::size_t k = 0; k < m.links.size(); ++k)
      q[k] = Lerp(m.links[k].joint_min, m.links[k].joint_max, 0.5);
  }
  return q;
}

MassModel MachineMassModel(const MachineDescription& m) {
  const InterpretedModel model(m);
  MassModel mass;
  mass.operating_mass = m.chassis.operating_mass;
  mass.carry_pose = CarryPose(m);
  const double front = m.chassis.hinge_to_front_axle, rear = m.chassis.hinge_to_rear_axle;
  // Axle loads: F_front·(front + rear) = M g (x_cg + rear).
  mass.reference_cg_x = -rear + m.chassis.front_axle_load_fraction * (front + rear);
  std::vector<V2<double>> origins;
  std::vector<double> angles;
  Frames(model, mass.carry_pose.data(), origins, angles);
  double arm_mass = 0, arm_moment = 0;
  for (std::size_t k = 0; k < m.links.size(); ++k) {
    const V2<double> c = origins[k] + internal::Rotate(angles[k], m.links[k].center_of_mass);
    arm_mass += m.links[k].mass;
    arm_moment += m.links[k].mass * (m.arm_pivot.x() + c.x);
  }
  mass.chassis_mass = mass.operating_mass - arm_mass;
  if (!(mass.chassis_mass > 0)) {
    throw std::invalid_argument("the arm's links weigh more than the operating mass");
  }
  mass.chassis_x = (mass.operating_mass * mass.reference_cg_x - arm_moment) / mass.chassis_mass;
  return mass;
}

Eigen::Vector2d MachineCenterOfMass(const MachineDescription& m, const MassModel& mass,
                                    const double* q, double articulation) {
  const InterpretedModel model(m);
  std::vector<V2<double>> origins;
  std::vector<double> angles;
  Frames(model, q, origins, angles);
  Eigen::Vector2d moment = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k < m.links.size(); ++k) {
    const V2<double> c = origins[k] + internal::Rotate(angles[k], m.links[k].center_of_mass);
    moment += m.links[k].mass * Eigen::Vector2d(m.arm_pivot.x() + c.x, 0.0);
  }
  // Behind the hinge the lumped chassis rides on the rear frame, turned by −γ about the hinge.
  const Eigen::Vector2d rear_axis(std::cos(articulation), -std::sin(articulation));
  const Eigen::Vector2d chassis = mass.chassis_x >= 0 ? Eigen::Vector2d(mass.chassis_x, 0.0)
                                                      : Eigen::Vector2d(mass.chassis_x * rear_axis);
  moment += mass.chassis_mass * chassis;
  return moment / mass.operating_mass;
}

double HydraulicVerticalForce(const MachineDescription& m, const double* q,
                              const Eigen::Vector2d& p_bucket_point, int driving) {
  const InterpretedModel model(m);
  Eigen::VectorXd v = FreeMotion(m, model, q, driving);
  const std::vector<double> dz = PointHeightGradient(m, model, q, p_bucket_point);
  double rise = Dot(dz, v);
  if (rise < 0) {
    v = -v;
    rise = -rise;
  }
  if (!(rise > 1e-9)) return 0.0;  // the free motion does not raise the point
  const Actuator& a = m.hydraulics.actuators[driving];
  double cap = 0, annulus = 0;
  Areas(a, cap, annulus);
  const double stroke_rate = Dot(model.LeverArms(driving, q), v);  // dL along v
  // Extending (cap side at relief, rod side at tank) or retracting (the reverse).
  const double cylinder_force =
      stroke_rate >= 0 ? a.relief_pressure * cap - m.hydraulics.tank_pressure * annulus
                       : a.relief_pressure * annulus - m.hydraulics.tank_pressure * cap;
  const std::vector<double> gravity = model.GravityTorques(q, 0.0, 0.0);
  return (cylinder_force * std::abs(stroke_rate) + Dot(gravity, v)) / rise;
}

BreakoutForce ComputeBreakoutForce(const MachineDescription& m, const MassModel& mass) {
  const InterpretedModel model(m);
  const auto& profile = m.bucket.profile;
  const Link& boom = m.links[0];
  const Link& bucket = m.links[1];
  BreakoutForce b;
  // Bucket bottom (cutting edge → first profile point behind it) level and pointing back:
  // its direction β in the bucket frame is at π in the base frame.
  const Eigen::Vector2d bottom = (profile[1] - profile[0]).normalized();
  const double attitude = WrapAngle(kPi - std::atan2(bottom.y(), bottom.x()));
  // Cutting edge tip on the ground: pivot_z + l1 sin q0 + (R(attitude) p0)_z = 0.
  const V2<double> tip = internal::Rotate(attitude, profile[0]);
  const double s = -(m.arm_pivot.y() + tip.z) / boom.length;
  double q0 = std::asin(std::clamp(s, -1.0, 1.0));
  double q1 = WrapAngle(attitude - q0);
  b.pose_in_range = std::abs(s) <= 1 && q0 >= boom.joint_min && q0 <= boom.joint_max &&
                    q1 >= bucket.joint_min && q1 <= bucket.joint_max;
  q0 = std::clamp(q0, boom.joint_min, boom.joint_max);
  q1 = std::clamp(q1, bucket.joint_min, bucket.joint_max);
  b.pose = {q0, q1};
  const Eigen::Vector2d point = profile[0] + kBreakoutPointBehindTip * bottom;
  b.p_base_point = BucketPointInBase(m, model, b.pose.data(), point);
  b.p_base_tip = BucketPointInBase(m, model, b.pose.data(), profile[0]);
  b.bottom_slope = WrapAngle(q0 + q1 - attitude);
  b.by_tilt = HydraulicVerticalForce(m, b.pose.data(), point, m.ActuatorOfJoint(1));
  b.by_lift = HydraulicVerticalForce(m, b.pose.data(), point, m.ActuatorOfJoint(0));
  const double front = m.chassis.hinge_to_front_axle;
  const Eigen::Vector2d cg = MachineCenterOfMass(m, mass, b.pose.data(), 0.0);
  b.tipping_limit = b.p_base_point.x() > front ? mass.operating_mass * plant::kGravity *
                                                     (front - cg.x()) / (b.p_base_point.x() - front)
                                               : std::numeric_limits<double>::infinity();
  return b;
}

TippingLoad TippingLoadAt(const MachineDescription& m, const MassModel& mass, const double* q,
                          const Eigen::Vector2d& p_base_load) {
  TippingLoad t;
  t.pose.assign(q, q + m.num_joints());
  t.p_base_load = p_base_load;
  t.articulation = m.chassis.max_articulation;
  const double front = m.chassis.hinge_to_front_axle, rear = m.chassis.hinge_to_rear_axle;
  const double half_track = m.chassis.track_width / 2;
  const Eigen::Vector2d load(p_base_load.x(), 0.0);
  for (const double gamma : {0.0, t.articulation}) {
    // Support: the front tyres' contact centres (the front axle is fixed to the front frame)
    // and the rear axle's oscillation pivot, which turns with the rear frame. Counter-clockwise.
    const Eigen::Vector2d rear_axis(std::cos(gamma), -std::sin(gamma));
    const Eigen::Vector2d vertices[3] = {
        {front, -half_track}, {front, half_track}, -rear * rear_axis};
    const char* names[3] = {"front axle (rear wheels lift)", "left front tyre to rear axle pivot",
                            "rear axle pivot to right front tyre"};
    const Eigen::Vector2d cg = MachineCenterOfMass(m, mass, q, gamma);
    double best = std::numeric_limits<double>::infinity();
    std::string edge;
    for (int e = 0; e < 3; ++e) {
      const Eigen::Vector2d a = vertices[e], b = vertices[(e + 1) % 3];
      const Eigen::Vector2d inward = Eigen::Vector2d(-(b - a).y(), (b - a).x()).normalized();
      const double margin_cg = inward.dot(cg - a), margin_load = inward.dot(load - a);
      if (margin_load >= 0) continue;  // the load lies inside this edge: it steadies the machine
      const double tipping = std::max(0.0, mass.operating_mass * margin_cg / -margin_load);
      if (tipping < best) {
        best = tipping;
        edge = names[e];
      }
    }
    if (gamma == 0.0) {
      t.straight = best;
    } else {
      t.full_turn = best;
      t.full_turn_edge = edge;
    }
  }
  return t;
}

TippingLoad ComputeTippingLoad(const MachineDescription& m, const MassModel& mass) {
  const InterpretedModel model(m);
  // Boom horizontal through the hinge pin (its line from the foot pin to the bucket pivot
  // level: the pin at its largest forward reach), bucket racked back fully.
  std::vector<double> q(m.num_joints(), 0.0);
  q[0] = std::clamp(0.0, m.links[0].joint_min, m.links[0].joint_max);
  q[1] = m.links[1].joint_max;
  if (CylinderMovesWithEarlierJoints(m, 1)) {  // as far as a frame-mounted cylinder reaches
    const JointWindow w = ReachableJointWindow(m, 1, q.data());
    if (!w.empty) q[1] = std::min(q[1], w.max);
  }
  const Eigen::Vector2d load = BucketPointInBase(m, model, q.data(), BucketPayloadCenter(m));
  return TippingLoadAt(m, mass, q.data(), load);
}

TurningRadius ComputeTurningRadius(const MachineDescription& m) {
  const InterpretedModel model(m);
  TurningRadius r;
  const double gamma = m.chassis.max_articulation;
  const double front = m.chassis.hinge_to_front_axle, rear = m.chassis.hinge_to_rear_axle;
  r.articulation = gamma;
  // The turning centre is where the two axle lines meet (no tyre slips sideways).
  r.front_axle_centre = (rear + front * std::cos(gamma)) / std::sin(gamma);
  r.tyre_width = kAssumedTyreWidthPerDiameter * 2 * m.chassis.wheel_radius;
  r.tyre_width_assumed = true;
  r.outside_tyre = r.front_axle_centre + m.chassis.track_width / 2 + r.tyre_width / 2;
  const std::vector<double> carry = CarryPose(m);
  double foremost = -std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& p : m.bucket.profile) {
    foremost = std::max(foremost, BucketPointInBase(m, model, carry.data(), p).x());
  }
  r.bucket_ahead_of_axle = foremost - front;
  r.bucket_corner = std::hypot(r.front_axle_centre + m.bucket.width / 2, r.bucket_ahead_of_axle);
  return r;
}

HeapedCapacity ComputeHeapedCapacity(const MachineDescription& m) {
  HeapedCapacity c;
  // The profile polygon closes from the top of the back to the cutting edge: its closing edge
  // is the strike line, so its area is the struck cross-section.
  c.struck_area = BucketProfileArea(m);
  c.strike_length = (m.bucket.profile.back() - m.bucket.profile.front()).norm();
  c.struck = c.struck_area * m.bucket.width;
  // Heap at 2:1 (rise 1 in 2) from every edge of the b × W strike rectangle: a hip roof of ridge
  // height a/4 over the short side a, volume a²·c/8 − a³/24 (ISO 7546: W·b²/8 − b³/24).
  const double a = std::min(c.strike_length, m.bucket.width);
  const double long_side = std::max(c.strike_length, m.bucket.width);
  c.heap = a * a * long_side / 8 - a * a * a / 24;
  c.heaped = c.struck + c.heap;
  c.rated = m.bucket.rated_capacity;
  return c;
}

SpecSheet ComputeSpecSheet(const MachineDescription& m) {
  if (m.kind != MachineKind::kWheelLoader || m.links.size() != 2) {
    throw std::invalid_argument("spec-sheet figures are defined for wheel loaders");
  }
  const MassModel mass = MachineMassModel(m);
  SpecSheet sheet;
  sheet.breakout = ComputeBreakoutForce(m, mass);
  sheet.tipping = ComputeTippingLoad(m, mass);
  sheet.turning = ComputeTurningRadius(m);
  sheet.capacity = ComputeHeapedCapacity(m);
  {
    // Holding the rated load in carry: F·dL + Q_gravity(rated)·v = 0 along the boom's motion.
    const InterpretedModel model(m);
    const std::vector<double>& q = mass.carry_pose;
    const int boom = m.ActuatorOfJoint(0);
    const Eigen::VectorXd v = FreeMotion(m, model, q.data(), boom);
    const double dl = Dot(model.LeverArms(boom, q.data()), v);
    const double work = Dot(model.GravityTorques(q.data(), m.bucket.rated_load, 0.0), v);
    double cap = 0, annulus = 0;
    Areas(m.hydraulics.actuators[boom], cap, annulus);
    const double force = -work / dl;  // along the extension
    sheet.boom_pressure_for_rated_load = force >= 0 ? force / cap : -force / annulus;
  }
  return sheet;
}

}  // namespace autoshovel::model
