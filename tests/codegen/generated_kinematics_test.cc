// Generated kinematics (Eq. 1–2), their Jacobians, the inverse and the cylinder geometry,
// against the interpreted reference model and central finite differences, for every generated
// machine over 10,000 seeded random configurations each.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <unsupported/Eigen/AutoDiff>

#include "tests/codegen/generated_test_support.h"

namespace autoshovel::testing {
namespace {

constexpr int kSamples = 10000;
constexpr double kPositionTolerance = 1e-9;  // [m]
constexpr double kJacobianTolerance = 1e-6;  // relative

class GeneratedKinematics : public ::testing::Test {
 protected:
  void SetUp() override {
    machines_ = LoadGeneratedMachines();
    ASSERT_GE(machines_.size(), 1u);
  }
  std::vector<MachineUnderTest> machines_;
};

// Random IMU angles and parameters around the nominal ones: joints inside their limits, a
// pitched cab, parameters perturbed as an uncalibrated machine's would be.
struct Sample {
  std::vector<double> angles, params;
};

Sample RandomSample(const MachineUnderTest& m, std::mt19937_64& rng) {
  const auto& g = *m.generated;
  std::vector<double> params(g.nominal_params, g.nominal_params + g.num_params);
  std::normal_distribution<double> length_noise(0.0, 0.02), angle_noise(0.0, 0.05);
  for (int k = 0; k < g.num_links; ++k) {
    params[k] += length_noise(rng);
    params[g.num_links + k] += angle_noise(rng);
  }
  const std::vector<double> q = RandomJoints(g, rng);
  std::vector<double> angles = m.interpreted->AnglesFromJoints(q.data(), params.data());
  const double cab_pitch = std::uniform_real_distribution<double>(-0.3, 0.3)(rng);
  for (int k = 0; k <= g.num_links; ++k) angles[k] += cab_pitch;  // Eq. (1) cancels it
  return {angles, params};
}

TEST_F(GeneratedKinematics, ForwardMatchesInterpretedOver10000Configurations) {
  for (const auto& m : machines_) {
    std::mt19937_64 rng(20261123);
    double worst = 0;
    for (int i = 0; i < kSamples; ++i) {
      const Sample s = RandomSample(m, rng);
      double generated[4], reference[4];
      m.generated->forward_kinematics(s.angles.data(), s.params.data(), generated);
      m.interpreted->ForwardKinematics(s.angles.data(), s.params.data(), reference);
      for (int r = 0; r < 3; ++r) worst = std::max(worst, std::abs(generated[r] - reference[r]));
      ASSERT_NEAR(generated[3], reference[3], 1e-12) << m.generated->name;
    }
    EXPECT_LE(worst, kPositionTolerance) << m.generated->name;
  }
}

TEST_F(GeneratedKinematics, JacobiansMatchAutoDiffAndCentralDifferences) {
  using Dual = Eigen::AutoDiffScalar<Eigen::VectorXd>;
  for (const auto& m : machines_) {
    const auto& g = *m.generated;
    const int na = g.num_angles, np = g.num_params;
    std::mt19937_64 rng(7);
    double worst_autodiff = 0, worst_central = 0;
    for (int i = 0; i < kSamples; ++i) {
      const Sample s = RandomSample(m, rng);
      double pose[4];
      std::vector<double> d_angles(4 * na), d_params(4 * np);
      g.forward_kinematics_jacobians(s.angles.data(), s.params.data(), pose, d_angles.data(),
                                     d_params.data());
      // Reference 1: the interpreted model under automatic differentiation.
      std::vector<Dual> angles(na), params(np);
      for (int k = 0; k < na; ++k) angles[k] = Dual(s.angles[k], na + np, k);
      for (int k = 0; k < np; ++k) params[k] = Dual(s.params[k], na + np, na + k);
      Dual reference_pose[4];
      m.interpreted->ForwardKinematics(angles.data(), params.data(), reference_pose);
      std::vector<double> ad_angles(4 * na), ad_params(4 * np);
      for (int r = 0; r < 4; ++r) {
        const Eigen::VectorXd& d = reference_pose[r].derivatives();
        for (int k = 0; k < na; ++k) ad_angles[r * na + k] = d.size() ? d[k] : 0.0;
        for (int k = 0; k < np; ++k) ad_params[r * np + k] = d.size() ? d[na + k] : 0.0;
      }
      worst_autodiff = std::max(
          {worst_autodiff, RelativeError(d_angles, ad_angles), RelativeError(d_params, ad_params)});
      // Reference 2: central differences of the generated forward kinematics.
      constexpr double h = 1e-6;
      std::vector<double> fd_angles(4 * na), fd_params(4 * np);
      auto central = [&](std::vector<double>& a, std::vector<double>& p, double* x, int column,
                         int columns, std::vector<double>& out) {
        const double saved = *x;
        double plus[4], minus[4];
        *x = saved + h;
        g.forward_kinematics(a.data(), p.data(), plus);
        *x = saved - h;
        g.forward_kinematics(a.data(), p.data(), minus);
        *x = saved;
        for (int r = 0; r < 4; ++r) out[r * columns + column] = (plus[r] - minus[r]) / (2 * h);
      };
      std::vector<double> a = s.angles, p = s.params;
      for (int k = 0; k < na; ++k) central(a, p, &a[k], k, na, fd_angles);
      for (int k = 0; k < np; ++k) central(a, p, &p[k], k, np, fd_params);
      worst_central = std::max(
          {worst_central, RelativeError(d_angles, fd_angles), RelativeError(d_params, fd_params)});
    }
    EXPECT_LE(worst_autodiff, 1e-12) << g.name;
    EXPECT_LE(worst_central, kJacobianTolerance) << g.name;
  }
}

TEST_F(GeneratedKinematics, InverseRecoversJointsInsideTheLimits) {
  for (const auto& m : machines_) {
    const auto& g = *m.generated;
    std::mt19937_64 rng(11);
    int solved = 0;
    for (int i = 0; i < kSamples; ++i) {
      const std::vector<double> q = RandomJoints(g, rng);
      const Eigen::Vector4d pose = m.interpreted->TipFromJoints(q.data());
      std::vector<double> recovered(g.num_joints);
      const int status = g.inverse_kinematics(pose.data(), g.nominal_params, recovered.data());
      ASSERT_NE(status, 1) << g.name << ": a forward pose must be reachable";
      if (status != 0) continue;  // the other elbow branch also lies inside the limits
      const Eigen::Vector4d again = m.interpreted->TipFromJoints(recovered.data());
      ASSERT_LE((again - pose).head<3>().norm(), 1e-9) << g.name;
      ++solved;
    }
    // Inside the limits the elbow branch is unique for these arms: every sample comes back.
    EXPECT_GE(solved, kSamples * 99 / 100) << g.name;
    // A target beyond the stretched arm is reported unreachable.
    double far[4] = {100.0, 0.0, 0.0, 0.0};
    std::vector<double> q(g.num_joints);
    EXPECT_EQ(g.inverse_kinematics(far, g.nominal_params, q.data()), 1) << g.name;
  }
}

TEST_F(GeneratedKinematics, CylinderGeometryMatchesInterpretedAndInverts) {
  for (const auto& m : machines_) {
    const auto& g = *m.generated;
    std::mt19937_64 rng(13);
    for (int i = 0; i < kSamples; ++i) {
      const std::vector<double> q = RandomJoints(g, rng);
      for (int a = 0; a < g.num_actuators; ++a) {
        const int joint = g.actuator_joint[a];
        const double length = g.cylinder_length(a, q.data());
        ASSERT_NEAR(length, m.interpreted->CylinderLength(a, q.data()), 1e-10) << g.name;
        const double lever = g.lever_arm(a, q.data());
        ASSERT_NEAR(lever, m.interpreted->LeverArms(a, q.data())[joint], 1e-9) << g.name;
        // Central difference of the length along the actuator's joint.
        std::vector<double> plus = q, minus = q;
        plus[joint] += 1e-6;
        minus[joint] -= 1e-6;
        const double central =
            (g.cylinder_length(a, plus.data()) - g.cylinder_length(a, minus.data())) / 2e-6;
        ASSERT_NEAR(lever, central, 1e-6 * std::max(1.0, std::abs(lever))) << g.name;
        // Length back to joint angle.
        std::vector<double> recovered(g.num_joints);
        ASSERT_EQ(g.joint_from_cylinder_length(a, length, q.data(), recovered.data()), 0);
        ASSERT_NEAR(recovered[joint], q[joint], 1e-9) << g.name << " actuator " << a;
      }
    }
  }
}

}  // namespace
}  // namespace autoshovel::testing
