// Closed chains across joints (issue 39): a tilt cylinder pinned to the front frame and to the
// bell crank on the boom (Z-bar, parallel lift). With the cylinder held at one length, the
// generated code's bucket angle over a boom lift must equal a hand construction of the same
// linkage, done the other way round: from the cylinder length to the bell crank by intersecting
// two circles, then from the coupler to the bucket by intersecting two more.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "tests/codegen/generated_test_support.h"

namespace autoshovel::testing {
namespace {

using Eigen::Vector2d;

Vector2d Rotate(double angle, const Vector2d& v) {
  return {std::cos(angle) * v.x() - std::sin(angle) * v.y(),
          std::sin(angle) * v.x() + std::cos(angle) * v.y()};
}

// The intersections of the circle around a with radius ra and the circle around b with radius
// rb, both of them.
std::optional<std::array<Vector2d, 2>> Circles(const Vector2d& a, double ra, const Vector2d& b,
                                               double rb) {
  const Vector2d ab = b - a;
  const double d = ab.norm();
  const double along = (ra * ra - rb * rb + d * d) / (2 * d);
  const double h2 = ra * ra - along * along;
  if (!(h2 >= 0)) return std::nullopt;
  const Vector2d base = a + along / d * ab;
  const Vector2d normal(-ab.y() / d, ab.x() / d);
  return std::array<Vector2d, 2>{base + std::sqrt(h2) * normal, base - std::sqrt(h2) * normal};
}

struct ZBar {
  int actuator = -1;
  const model::Actuator* cylinder = nullptr;
  const model::FourBarLinkage* bar = nullptr;
};

// A loader whose tilt cylinder runs from the chassis to the rocker.
std::optional<ZBar> FrameMountedTilt(const model::MachineDescription& m) {
  if (m.kind != model::MachineKind::kWheelLoader || !m.links[1].linkage) return std::nullopt;
  for (std::size_t i = 0; i < m.hydraulics.actuators.size(); ++i) {
    const model::Actuator& a = m.hydraulics.actuators[i];
    if (a.joint == m.links[1].name && a.base_mount.body == "chassis" &&
        a.rod_mount.body == "rocker") {
      return ZBar{static_cast<int>(i), &a, &*m.links[1].linkage};
    }
  }
  return std::nullopt;
}

// Bucket joint angle for boom angle q0 and tilt cylinder length L, by construction; the
// branches are chosen next to the previous solution (the linkage moves continuously).
std::optional<double> HandBucketAngle(const model::MachineDescription& m, const ZBar& z, double q0,
                                      double length, const Vector2d& previous_pin,
                                      Vector2d& rocker_pin, double previous_q1) {
  const Vector2d frame_pin = z.cylinder->base_mount.point;  // frame M
  const Vector2d pivot = Rotate(q0, z.bar->rocker_pivot);   // rocker pivot E in M
  const double arm = z.cylinder->rod_mount.point.norm();    // E to the cylinder's rocker pin
  const auto pins = Circles(pivot, arm, frame_pin, length);
  if (!pins) return std::nullopt;
  rocker_pin = ((*pins)[0] - previous_pin).norm() < ((*pins)[1] - previous_pin).norm() ? (*pins)[0]
                                                                                       : (*pins)[1];
  // Rocker angle from the pin, then F at rocker_length along the rocker's x axis.
  const Vector2d r = rocker_pin - pivot;
  const double rocker_angle =
      std::atan2(r.y(), r.x()) -
      std::atan2(z.cylinder->rod_mount.point.y(), z.cylinder->rod_mount.point.x());
  const Vector2d f = pivot + Rotate(rocker_angle, Vector2d(z.bar->rocker_length, 0));
  // G: coupler_length from F, |G| from the bucket pivot (the boom tip).
  const Vector2d tip = Rotate(q0, Vector2d(m.links[0].length, 0));
  const auto gs = Circles(f, z.bar->coupler_length, tip, z.bar->child_coupler_point.norm());
  if (!gs) return std::nullopt;
  double best = 0, best_distance = 1e300;
  for (const Vector2d& g : *gs) {
    const Vector2d v = g - tip;
    const double phi = std::atan2(v.y(), v.x()) -
                       std::atan2(z.bar->child_coupler_point.y(), z.bar->child_coupler_point.x());
    const double q1 = std::remainder(phi - q0, 2 * M_PI);
    if (std::abs(q1 - previous_q1) < best_distance) {
      best_distance = std::abs(q1 - previous_q1);
      best = q1;
    }
  }
  return best;
}

TEST(GeneratedLinkage, FrameMountedTiltCylinderMatchesHandConstruction) {
  int machines = 0;
  for (const auto& m : LoadGeneratedMachines()) {
    const auto z = FrameMountedTilt(*m.description);
    if (!z) continue;
    ++machines;
    const auto& g = *m.generated;
    // Start racked back at the lowest boom angle, fix the cylinder there, lift the boom.
    std::vector<double> q{g.joint_min[0], 0.5 * (g.joint_min[1] + g.joint_max[1])};
    const double length = g.cylinder_length(z->actuator, q.data());
    std::vector<double> q_out(2);
    // The cylinder's rocker pin at the start, from the interpreted geometry: it seeds the
    // choice of circle intersection, which then follows by continuity.
    Vector2d pin = Vector2d::Zero();
    {
      std::vector<model::V2<double>> origins;
      std::vector<double> angles;
      m.interpreted->LinkFrames(q.data(), origins, angles);
      model::V2<double> e;
      double rocker_angle = 0;
      ASSERT_TRUE(m.interpreted->SolveLinkage(1, origins, angles, e, rocker_angle));
      const Vector2d p = Rotate(rocker_angle, z->cylinder->rod_mount.point);
      pin = Vector2d(e.x + p.x(), e.z + p.y());
    }
    double previous_q1 = q[1];
    double attitude_min = 1e300, attitude_max = -1e300;
    for (int s = 0; s <= 40; ++s) {
      const double q0 = g.joint_min[0] + (g.joint_max[0] - g.joint_min[0]) * s / 40.0;
      q[0] = q0;
      if (g.joint_from_cylinder_length(z->actuator, length, q.data(), q_out.data()) != 0) {
        continue;  // the held length leaves the bucket's range: the linkage would hit a stop
      }
      Vector2d rocker_pin = pin;
      const auto hand =
          HandBucketAngle(*m.description, *z, q0, length, pin, rocker_pin, previous_q1);
      ASSERT_TRUE(hand.has_value()) << g.name << " at boom " << q0;
      EXPECT_NEAR(q_out[1], *hand, 1e-9) << g.name << " at boom angle " << q0;
      pin = rocker_pin;
      previous_q1 = *hand;
      attitude_min = std::min(attitude_min, q0 + q_out[1]);
      attitude_max = std::max(attitude_max, q0 + q_out[1]);
    }
    // A boom-mounted tilt cylinder held still keeps q1, so the bucket's attitude would turn by
    // the boom's whole travel; pinned to the frame it turns by clearly less (a Z-bar levels low
    // and tips forward near the top, a parallel lift stays near level throughout).
    EXPECT_LT(attitude_max - attitude_min, 0.75 * (g.joint_max[0] - g.joint_min[0])) << g.name;
    RecordProperty(std::string(g.name) + "_attitude_change_deg",
                   std::to_string((attitude_max - attitude_min) * 180 / M_PI));
  }
  EXPECT_GE(machines, 1) << "no shipped loader has a frame-mounted tilt cylinder";
}

}  // namespace
}  // namespace autoshovel::testing
