// The templated arm terms the optimiser differentiates (ArmDynamics, ForwardKinematicsWith-
// Jacobian, CylinderGeometry) against the plain double functions of the same machine, for every
// generated machine, at joint positions spread over the range.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "generated/registry.h"
#include "generated/templated_registry.h"

namespace autoshovel::generated {
namespace {

std::vector<double> JointsAt(const MachineFunctions& m, double fraction) {
  std::vector<double> q(m.num_joints);
  for (int j = 0; j < m.num_joints; ++j) {
    q[j] = m.joint_min[j] + fraction * (m.joint_max[j] - m.joint_min[j]);
  }
  return q;
}

TEST(TemplatedTerms, MatchThePlainFunctionsOfEveryMachine) {
  for (const MachineFunctions* m : AllMachines()) {
    const TemplatedArm<double>* arm = FindTemplatedArm<double>(m->name);
    ASSERT_NE(arm, nullptr) << m->name;
    const int J = m->num_joints;
    for (double fraction : {0.2, 0.5, 0.8}) {
      const std::vector<double> q = JointsAt(*m, fraction);
      std::vector<double> qd(J);
      for (int j = 0; j < J; ++j) qd[j] = 0.3 - 0.2 * j;
      const double payload = 2500, pitch = 0.05;
      std::vector<double> mass(J * J), bias(J), mass_t(J * J), bias_t(J);
      m->mass_matrix(q.data(), payload, mass.data());
      m->bias_forces(q.data(), qd.data(), payload, pitch, bias.data());
      arm->dynamics(q.data(), qd.data(), payload, pitch, mass_t.data(), bias_t.data());
      for (int i = 0; i < J * J; ++i) {
        EXPECT_NEAR(mass_t[i], mass[i], 1e-9 * (1 + std::abs(mass[i]))) << m->name;
      }
      for (int i = 0; i < J; ++i) {
        EXPECT_NEAR(bias_t[i], bias[i], 1e-9 * (1 + std::abs(bias[i]))) << m->name;
      }
      for (int a = 0; a < m->num_actuators; ++a) {
        double length = 0;
        std::vector<double> gradient(J);
        ASSERT_TRUE(arm->cylinder(a, q.data(), &length, gradient.data()));
        EXPECT_NEAR(length, m->cylinder_length(a, q.data()), 1e-12) << m->name << " " << a;
        const int own = m->actuator_joint[a];
        EXPECT_NEAR(gradient[own], m->lever_arm(a, q.data()), 1e-12) << m->name << " " << a;
        // The gradient over the other joints against central differences of the length.
        for (int j = 0; j < J; ++j) {
          std::vector<double> plus = q, minus = q;
          plus[j] += 1e-6;
          minus[j] -= 1e-6;
          const double numeric =
              (m->cylinder_length(a, plus.data()) - m->cylinder_length(a, minus.data())) / 2e-6;
          EXPECT_NEAR(gradient[j], numeric, 1e-6) << m->name << " actuator " << a << " joint " << j;
        }
      }
      std::vector<double> angles(m->num_angles);
      for (int k = 0; k < m->num_angles; ++k) angles[k] = 0.1 * (k + 1) * (fraction - 0.4);
      double pose[4], pose_t[4];
      std::vector<double> jac(4 * m->num_angles), jac_t(4 * m->num_angles),
          jac_p(4 * m->num_params);
      m->forward_kinematics_jacobians(angles.data(), m->nominal_params, pose, jac.data(),
                                      jac_p.data());
      arm->kinematics(angles.data(), m->nominal_params, pose_t, jac_t.data());
      for (int i = 0; i < 4; ++i) EXPECT_NEAR(pose_t[i], pose[i], 1e-12) << m->name;
      for (int i = 0; i < 4 * m->num_angles; ++i) {
        EXPECT_NEAR(jac_t[i], jac[i], 1e-12) << m->name;
      }
    }
    EXPECT_FALSE(arm->cylinder(m->num_actuators, JointsAt(*m, 0.5).data(), nullptr, nullptr));
  }
}

}  // namespace
}  // namespace autoshovel::generated
