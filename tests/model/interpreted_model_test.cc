// The interpreted reference model against hand-computed truths.
#include "runtime/model/interpreted_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace autoshovel::model {
namespace {

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";

class Interpreted : public ::testing::Test {
 protected:
  Interpreted()
      : machine_(LoadMachineDescription(ResolveMachineDescription("xcmg_968ev", kModels))),
        model_(machine_) {}
  MachineDescription machine_;
  InterpretedModel model_;
};

// Eq. (1)–(2) by hand: φ_k = θ_k − θ_cab + α_k, tip = Σ l_k (cos φ_k, sin φ_k) + pivot.
TEST_F(Interpreted, ForwardKinematicsIsEquationsOneAndTwo) {
  const double angles[3] = {0.1, 0.4, -0.2};
  const double params[4] = {3.0, 1.2, 0.05, -0.07};
  double pose[4];
  model_.ForwardKinematics(angles, params, pose);
  const double phi1 = 0.4 - 0.1 + 0.05, phi2 = -0.2 - 0.1 - 0.07;
  EXPECT_NEAR(pose[0], machine_.arm_pivot.x() + 3.0 * std::cos(phi1) + 1.2 * std::cos(phi2), 1e-15);
  EXPECT_NEAR(pose[2], machine_.arm_pivot.y() + 3.0 * std::sin(phi1) + 1.2 * std::sin(phi2), 1e-15);
  EXPECT_EQ(pose[1], 0.0);
  EXPECT_NEAR(pose[3], phi2, 1e-15);
}

TEST_F(Interpreted, AnglesFromJointsInvertsEquationOne) {
  const std::vector<double> params = model_.NominalParams();
  const double q[2] = {0.3, -0.5};
  const auto angles = model_.AnglesFromJoints(q, params.data());
  double pose[4];
  model_.ForwardKinematics(angles.data(), params.data(), pose);
  EXPECT_NEAR(pose[3], q[0] + q[1], 1e-15);
}

// The four-bar's rocker point stays at its link lengths from both its pivots.
TEST_F(Interpreted, FourBarClosesWithItsLinkLengths) {
  const auto& bar = *machine_.links[1].linkage;
  for (double q2 = machine_.links[1].joint_min; q2 <= machine_.links[1].joint_max; q2 += 0.05) {
    const double q[2] = {0.2, q2};
    std::vector<V2<double>> origins;
    std::vector<double> angles;
    model_.LinkFrames(q, origins, angles);
    V2<double> pivot;
    double rocker_angle;
    ASSERT_TRUE(model_.SolveLinkage(1, origins, angles, pivot, rocker_angle));
    const V2<double> f{pivot.x + bar.rocker_length * std::cos(rocker_angle),
                       pivot.z + bar.rocker_length * std::sin(rocker_angle)};
    const V2<double> g = origins[1] + internal::Rotate(angles[1], bar.child_coupler_point);
    EXPECT_NEAR(std::hypot(f.x - g.x, f.z - g.z), bar.coupler_length, 1e-12);
  }
}

// Gravity torque on the boom with a payload: the payload adds m g times its horizontal distance
// from the boom pivot (pulling the boom down).
TEST_F(Interpreted, PayloadGravityTorqueIsWeightTimesHorizontalArm) {
  const double q[2] = {0.1, 0.6};
  const auto empty = model_.GravityTorques(q, 0.0, 0.0);
  const auto loaded = model_.GravityTorques(q, 1000.0, 0.0);
  std::vector<V2<double>> origins;
  std::vector<double> angles;
  model_.LinkFrames(q, origins, angles);
  const V2<double> c = origins[1] + internal::Rotate(angles[1], BucketPayloadCenter(machine_));
  // Relative 1e-9: the torques come out of the plant through an inertia probe (round-off).
  const double boom = -1000.0 * plant::kGravity * c.x;
  const double bucket = -1000.0 * plant::kGravity * (c.x - origins[1].x);
  EXPECT_NEAR(loaded[0] - empty[0], boom, 1e-9 * std::abs(boom));
  EXPECT_NEAR(loaded[1] - empty[1], bucket, 1e-9 * std::abs(bucket));
}

TEST_F(Interpreted, ProfileCentroidOfASquareIsItsCentre) {
  MachineDescription square = machine_;
  square.bucket.profile = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_NEAR(BucketProfileArea(square), 1.0, 1e-15);
  EXPECT_TRUE(BucketPayloadCenter(square).isApprox(Eigen::Vector2d(0.5, 0.5)));
}

}  // namespace
}  // namespace autoshovel::model
