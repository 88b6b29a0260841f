// The linkage for a joint state (seed §4.5, Fig. 15): pins from the generated kinematics against
// the interpreted reference model, inverse kinematics round trips, the underside points of the
// simple link shapes, and the minimal elevation grid.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "excavator_test_support.h"
#include "runtime/control/excavator/linkage_clearance.h"
#include "runtime/model/interpreted_model.h"

namespace autoshovel::control {
namespace {

using testing::Excavator25t;
using testing::kDeg;

JointVector RandomPose(std::mt19937& rng) {
  const ExcavatorKinematics& k = *Excavator25t().kinematics;
  JointVector q;
  for (int j = 0; j < kNumExcavatorJoints; ++j) {
    const double lo = j == 3 ? -M_PI : k.joint_min()[j], hi = j == 3 ? M_PI : k.joint_max()[j];
    q[j] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

TEST(ExcavatorKinematics, PinsAgreeWithTheInterpretedReferenceModel) {
  const testing::Excavator& e = Excavator25t();
  const model::InterpretedModel reference(e.machine);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const JointVector q = RandomPose(rng);
    const ArmPlanePins pins = e.kinematics->Pins(q);
    std::vector<model::V2<double>> origins;
    std::vector<double> angles;
    reference.LinkFrames(q.data(), origins, angles);
    for (int k = 0; k <= 3; ++k) {
      EXPECT_NEAR(pins.pins[k].x(), e.machine.arm_pivot.x() + origins[k].x, 1e-9);
      EXPECT_NEAR(pins.pins[k].y(), e.machine.arm_pivot.y() + origins[k].z, 1e-9);
    }
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(pins.link_angles[k], angles[k], 1e-12);
    const Eigen::Vector4d tip = reference.TipFromJoints(q.data());
    EXPECT_LT((e.kinematics->TipPosition(q) - tip.head<3>()).norm(), 1e-9);
  }
}

TEST(ExcavatorKinematics, InverseKinematicsRoundTrips) {
  const ExcavatorKinematics& k = *Excavator25t().kinematics;
  std::mt19937 rng(11);
  int solved = 0;
  for (int trial = 0; trial < 200; ++trial) {
    JointVector q = RandomPose(rng);
    const ArmPlanePins pins = k.Pins(q);
    const std::optional<JointVector> tip = k.SolveTip(k.TipPosition(q), pins.link_angles[2]);
    ASSERT_TRUE(tip.has_value());
    EXPECT_LT((*tip - q).norm(), 1e-6);
    const std::optional<JointVector> pin = k.SolveBucketPin(pins.pins[2], q[3], q[2]);
    if (pins.pins[2].x() - k.link_lengths()[2] > 0.5) {
      ASSERT_TRUE(pin.has_value());
      EXPECT_LT((k.Pins(*pin).pins[2] - pins.pins[2]).norm(), 1e-6);
      EXPECT_NEAR((*pin)[2], q[2], 1e-12);
      ++solved;
    }
  }
  EXPECT_GT(solved, 100);
  EXPECT_FALSE(k.SolveTip(Eigen::Vector3d(30, 0, 0), 0.0).has_value());
  EXPECT_FALSE(k.SolveTip(Eigen::Vector3d(std::nan(""), 0, 0), 0.0).has_value());
}

TEST(LinkageEnvelope, UndersideIsTheLowerBoundaryOfEachLinkShape) {
  const LinkageEnvelope& envelope = *Excavator25t().envelope;
  const ExcavatorKinematics& k = envelope.kinematics();
  std::mt19937 rng(3);
  for (int trial = 0; trial < 100; ++trial) {
    const JointVector q = RandomPose(rng);
    const ArmPlanePins pins = k.Pins(q);
    for (int link = 0; link < 3; ++link) {
      const std::vector<Eigen::Vector2d> chain =
          envelope.LowerChain(q, static_cast<LinkageLink>(link));
      ASSERT_GE(chain.size(), 2u);
      // Every outline vertex lies on or above the chain at its radial position, and the chain
      // spans the outline from its leftmost to its rightmost vertex.
      double r_min = 1e9, r_max = -1e9;
      for (const Eigen::Vector2d& v : envelope.config().shapes[link].outline) {
        const Eigen::Vector2d p = ExcavatorKinematics::ArmPlanePoint(pins, link, v);
        r_min = std::min(r_min, p.x());
        r_max = std::max(r_max, p.x());
        for (std::size_t s = 1; s < chain.size(); ++s) {
          const Eigen::Vector2d& a = chain[s - 1];
          const Eigen::Vector2d& b = chain[s];
          if (p.x() < a.x() || p.x() > b.x() || b.x() - a.x() < 1e-9) continue;
          const double z = a.y() + (b.y() - a.y()) * (p.x() - a.x()) / (b.x() - a.x());
          EXPECT_GE(p.y(), z - 1e-9);
        }
      }
      EXPECT_NEAR(chain.front().x(), r_min, 1e-9);
      EXPECT_NEAR(chain.back().x(), r_max, 1e-9);
    }
  }
}

TEST(LinkageEnvelope, PointsAreDenseAndTurnWithTheSwing) {
  const testing::Excavator& e = Excavator25t();
  const LinkageEnvelope& envelope = *e.envelope;
  // Boom level, stick straight down, bucket curled; swing 90° (arm along +y).
  const JointVector q(0.0, -90 * kDeg, -120 * kDeg, 90 * kDeg);
  const std::vector<EnvelopePoint> points = envelope.Underside(q);
  int boom = 0;
  for (const EnvelopePoint& p : points) {
    if (p.link != LinkageLink::kBoom) continue;
    ++boom;
    // A level boom's underside is 0.4 m below the foot pin's height, across its 0.7 m width
    // (x is the lateral offset now), from 0.3 m behind the foot to 0.3 m past the tip.
    EXPECT_NEAR(p.p.z(), e.machine.arm_pivot.y() - 0.4, 1e-9);
    EXPECT_LE(std::abs(p.p.x()), 0.35 + 1e-9);
    EXPECT_GE(p.p.y(), e.machine.arm_pivot.x() - 0.3 - 1e-9);
    EXPECT_LE(p.p.y(), e.machine.arm_pivot.x() + 5.7 + 0.3 + 1e-9);
  }
  // Along 6.3 m at <= 0.25 m and across 0.7 m at <= 0.25 m: at least 26 × 4 points.
  EXPECT_GE(boom, 26 * 4);
  // Neighbouring points are never farther apart than the spacing (across: consecutive points).
  for (std::size_t i = 1; i < points.size(); ++i) {
    if (points[i].link != points[i - 1].link) continue;
    const double gap = (points[i].p - points[i - 1].p).norm();
    if (gap > 0.3) {
      // The next row along the chain starts at the other edge: its partner is `across` back.
      continue;
    }
    EXPECT_LE(gap, 0.25 + 1e-9);
  }
  // A transform moves every point.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(10, -5, 1);
  const std::vector<EnvelopePoint> moved = envelope.Underside(q, T);
  ASSERT_EQ(moved.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_LT((moved[i].p - points[i].p - T.translation()).norm(), 1e-12);
  }
}

TEST(HeightGrid, RaiseBoxCoversEveryOverlappedCellAndLeavesFarCellsAlone) {
  HeightGrid grid(Eigen::Vector2d(-5, -5), 0.15, 67, 67, 0.0);
  ObstacleBox person;
  person.center = Eigen::Vector2d(1.03, -0.41);
  person.yaw = 0.3;
  person.half_extents = Eigen::Vector2d(0.25, 0.25);
  person.z_max = 1.8;
  grid.RaiseBox(person);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector2d local(0.25 * u(rng), 0.25 * u(rng));
    const Eigen::Vector2d xy =
        person.center + Eigen::Rotation2Dd(person.yaw) * local;  // a point of the footprint
    EXPECT_EQ(grid.HeightAt(xy.x(), xy.y()), 1.8);
  }
  for (int iy = 0; iy < grid.ny(); ++iy) {
    for (int ix = 0; ix < grid.nx(); ++ix) {
      if (person.FootprintDistance(grid.CellCenter(ix, iy)) > 0.15) {
        EXPECT_EQ(grid.height(ix, iy), 0.0);
      }
    }
  }
  EXPECT_TRUE(std::isnan(grid.HeightAt(100, 0)));
  EXPECT_TRUE(std::isnan(grid.HeightAt(std::nan(""), 0)));
  EXPECT_THROW(HeightGrid(Eigen::Vector2d::Zero(), 0.0, 3, 3), std::invalid_argument);
}

TEST(ObstacleBox, SignedDistanceIsEuclideanOutsideAndNegativeInside) {
  ObstacleBox box;
  box.center = Eigen::Vector2d(2, 0);
  box.yaw = M_PI / 2;  // long axis along y
  box.half_extents = Eigen::Vector2d(2.0, 1.0);
  box.z_max = 3.0;
  EXPECT_NEAR(box.SignedDistance(Eigen::Vector3d(2, 0, 3.5)), 0.5, 1e-12);
  EXPECT_NEAR(box.SignedDistance(Eigen::Vector3d(4, 0, 1.0)), 1.0, 1e-12);  // beyond x = 3
  EXPECT_NEAR(box.SignedDistance(Eigen::Vector3d(2, 3, 4.0)), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(box.SignedDistance(Eigen::Vector3d(2, 0, 2.5)), -0.5, 1e-12);
  EXPECT_NEAR(box.FootprintDistance(Eigen::Vector2d(2, 2.5)), 0.5, 1e-12);
}

TEST(ObstacleBox, MinClearanceIsTheSmallestSignedDistance) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<ObstacleBox> boxes(2);
    for (ObstacleBox& box : boxes) {
      box.center = Eigen::Vector2d(3 * u(rng), 3 * u(rng));
      box.yaw = 3 * u(rng);
      box.half_extents = Eigen::Vector2d(1.5 + u(rng), 1.5 + u(rng));
      box.z_min = u(rng);
      box.z_max = 3 + u(rng);
    }
    std::vector<EnvelopePoint> points(20);
    double expected = 1e300;
    for (EnvelopePoint& p : points) {
      p.p = Eigen::Vector3d(5 * u(rng), 5 * u(rng), 2 + 3 * u(rng));
      for (const ObstacleBox& box : boxes) expected = std::min(expected, box.SignedDistance(p.p));
    }
    EXPECT_NEAR(MinClearance(points, boxes), expected, 1e-12);
  }
  EXPECT_TRUE(std::isinf(MinClearance({}, {})));
}

}  // namespace
}  // namespace autoshovel::control
