// Generated rigid-body dynamics (issue 39) against the interpreted reference on random
// configurations, and energy conservation of the generated unactuated, frictionless arm.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/codegen/generated_test_support.h"

namespace autoshovel::testing {
namespace {

TEST(GeneratedDynamics, MassMatrixBiasAndEnergyMatchInterpreted) {
  std::mt19937_64 rng(3939);
  for (const auto& m : LoadGeneratedMachines()) {
    const auto& g = *m.generated;
    const int J = g.num_joints;
    for (int trial = 0; trial < 20; ++trial) {
      const std::vector<double> q = RandomJoints(g, rng);
      std::vector<double> qd(J);
      for (double& v : qd) v = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
      const double payload = std::uniform_real_distribution<double>(0.0, 5000.0)(rng);
      const double pitch = std::uniform_real_distribution<double>(-0.2, 0.2)(rng);
      std::vector<double> mass(J * J), bias(J), energy(2);
      g.mass_matrix(q.data(), payload, mass.data());
      g.bias_forces(q.data(), qd.data(), payload, pitch, bias.data());
      g.mechanical_energy(q.data(), qd.data(), payload, pitch, energy.data());
      std::vector<double> ref_mass(J * J), ref_h(J), ref_gravity(J), ref_bias(J);
      m.interpreted->Dynamics(q.data(), qd.data(), payload, pitch, ref_mass.data(), ref_h.data(),
                              ref_gravity.data());
      for (int j = 0; j < J; ++j) ref_bias[j] = ref_h[j] - ref_gravity[j];
      const auto ref_energy = m.interpreted->MechanicalEnergy(q.data(), qd.data(), payload, pitch);
      EXPECT_LT(RelativeError(mass, ref_mass), 1e-10) << g.name;
      EXPECT_LT(RelativeError(bias, ref_bias), 1e-10) << g.name;
      EXPECT_NEAR(energy[0], ref_energy[0], 1e-9 * std::max(1.0, std::abs(ref_energy[0])));
      EXPECT_NEAR(energy[1], ref_energy[1], 1e-9 * std::max(1.0, std::abs(ref_energy[1])));
      // Symmetric positive definite: the plant divides by it.
      for (int i = 0; i < J; ++i) {
        EXPECT_GT(mass[i * J + i], 0.0);
        for (int j = 0; j < J; ++j) EXPECT_DOUBLE_EQ(mass[i * J + j], mass[j * J + i]);
      }
    }
  }
}

// q̈ = −M⁻¹ bias with no actuator, friction or end stop: T + V stays constant (RK4, 0.2 s).
TEST(GeneratedDynamics, UnactuatedFrictionlessArmConservesEnergy) {
  for (const auto& m : LoadGeneratedMachines()) {
    const auto& g = *m.generated;
    const int J = g.num_joints;
    std::vector<double> q(J), qd(J);
    for (int j = 0; j < J; ++j) {
      q[j] = 0.5 * (g.joint_min[j] + g.joint_max[j]);
      qd[j] = j % 2 == 0 ? 0.6 : -0.7;
    }
    const double payload = 1500.0;
    auto acceleration = [&](const std::vector<double>& qq, const std::vector<double>& vv) {
      std::vector<double> mass(J * J), bias(J);
      g.mass_matrix(qq.data(), payload, mass.data());
      g.bias_forces(qq.data(), vv.data(), payload, 0.0, bias.data());
      // Gaussian elimination of M a = −bias.
      std::vector<double> a(J);
      for (int i = 0; i < J; ++i) bias[i] = -bias[i];
      for (int k = 0; k < J; ++k) {
        for (int i = k + 1; i < J; ++i) {
          const double f = mass[i * J + k] / mass[k * J + k];
          for (int c = k; c < J; ++c) mass[i * J + c] -= f * mass[k * J + c];
          bias[i] -= f * bias[k];
        }
      }
      for (int i = J - 1; i >= 0; --i) {
        double v = bias[i];
        for (int c = i + 1; c < J; ++c) v -= mass[i * J + c] * a[c];
        a[i] = v / mass[i * J + i];
      }
      return a;
    };
    auto total = [&](const std::vector<double>& qq, const std::vector<double>& vv) {
      double e[2];
      g.mechanical_energy(qq.data(), vv.data(), payload, 0.0, e);
      return e[0] + e[1];
    };
    double kinetic[2];
    g.mechanical_energy(q.data(), qd.data(), payload, 0.0, kinetic);
    const double start = total(q, qd);
    double worst = 0;
    constexpr double kDt = 2e-4;
    for (int step = 0; step < 1000; ++step) {
      auto shift = [&](const std::vector<double>& b, const std::vector<double>& d, double h) {
        std::vector<double> out(J);
        for (int i = 0; i < J; ++i) out[i] = b[i] + h * d[i];
        return out;
      };
      const auto a1 = acceleration(q, qd);
      const auto v2 = shift(qd, a1, kDt / 2);
      const auto a2 = acceleration(shift(q, qd, kDt / 2), v2);
      const auto v3 = shift(qd, a2, kDt / 2);
      const auto a3 = acceleration(shift(q, v2, kDt / 2), v3);
      const auto v4 = shift(qd, a3, kDt);
      const auto a4 = acceleration(shift(q, v3, kDt), v4);
      for (int i = 0; i < J; ++i) {
        q[i] += kDt / 6 * (qd[i] + 2 * v2[i] + 2 * v3[i] + v4[i]);
        qd[i] += kDt / 6 * (a1[i] + 2 * a2[i] + 2 * a3[i] + a4[i]);
      }
      worst = std::max(worst, std::abs(total(q, qd) - start));
    }
    EXPECT_LT(worst, 1e-7 * kinetic[0]) << g.name << ": kinetic " << kinetic[0] << " J";
  }
}

}  // namespace
}  // namespace autoshovel::testing
