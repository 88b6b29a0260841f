// The generated plant right-hand side and its Jacobian against the interpreted reference model
// (a different derivation of the same physics) and against central differences, plus physical
// truths: at rest with balanced pressures the arm holds, and energy flows the right way.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/codegen/generated_test_support.h"

namespace autoshovel::testing {
namespace {

constexpr int kSamples = 2000;

// A random plant state inside the operating envelope and a random input.
void RandomStateAndInput(const MachineUnderTest& m, std::mt19937_64& rng, std::vector<double>& x,
                         std::vector<double>& u) {
  const auto& g = *m.generated;
  const int J = g.num_joints;
  x.assign(g.num_states, 0.0);
  u.assign(g.num_inputs, 0.0);
  const std::vector<double> q = RandomJoints(g, rng);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> pressure(2e5, 3.0e7);
  for (int j = 0; j < J; ++j) {
    x[j] = q[j];
    x[J + j] = 0.5 * unit(rng);
    x[2 * J + j] = unit(rng);
    x[3 * J + j] = pressure(rng);
    x[4 * J + j] = pressure(rng);
    u[j] = unit(rng);
    u[J + j] = 2e4 * unit(rng);
  }
  u[2 * J] = std::uniform_real_distribution<double>(0.0, 6000.0)(rng);
  u[2 * J + 1] = 0.1 * unit(rng);
  for (int j = 0; j < J; ++j) {
    u[2 * J + 2 + j] = std::uniform_real_distribution<double>(5e6, 3.0e7)(rng);
  }
}

TEST(GeneratedPlant, RightHandSideMatchesInterpreted) {
  for (const auto& m : LoadGeneratedMachines()) {
    std::mt19937_64 rng(3);
    std::vector<double> x, u;
    for (int i = 0; i < kSamples; ++i) {
      RandomStateAndInput(m, rng, x, u);
      std::vector<double> generated(x.size()), reference(x.size());
      m.generated->plant_rhs(0.0, x.data(), u.data(), generated.data());
      m.interpreted->PlantRhs(x.data(), u.data(), reference.data());
      const std::size_t J = static_cast<std::size_t>(m.generated->num_joints);
      for (std::size_t r = 0; r < x.size(); ++r) {
        ASSERT_TRUE(std::isfinite(generated[r]));
        // The accelerations solve M q̈ = force, by Cholesky in the generated code and Gaussian
        // elimination in the reference, where the random cylinder forces (up to ~1e6 N, on a
        // frame-mounted tilt cylinder acting on both joints) largely cancel: rounding then
        // reaches ~1e-9 of the result. A modelling difference is of order one.
        const double relative = (r >= J && r < 2 * J) ? 1e-7 : 1e-9;
        // Pressure rates are differences of flow terms of order β/V·Q ~ 1e6 Pa/s: a result near
        // zero is compared on that scale (1e3 Pa/s floor), not on its own.
        const double floor = r >= 3 * J ? 1e3 : 1.0;
        ASSERT_NEAR(generated[r], reference[r], relative * std::max(floor, std::abs(reference[r])))
            << m.generated->name << " row " << r;
      }
    }
  }
}

TEST(GeneratedPlant, JacobianMatchesAutoDiffAndCentralDifferences) {
  for (const auto& m : LoadGeneratedMachines()) {
    const int n = m.generated->num_states;
    std::mt19937_64 rng(5);
    std::vector<double> x, u;
    for (int i = 0; i < 200; ++i) {
      RandomStateAndInput(m, rng, x, u);
      std::vector<double> jacobian(n * n), reference(n * n);
      m.generated->plant_jacobian(0.0, x.data(), u.data(), jacobian.data());
      m.interpreted->PlantJacobian(x.data(), u.data(), reference.data());
      for (int r = 0; r < n; ++r) {
        const std::vector<double> row(jacobian.begin() + r * n, jacobian.begin() + (r + 1) * n);
        const std::vector<double> ref(reference.begin() + r * n, reference.begin() + (r + 1) * n);
        ASSERT_LE(RelativeError(row, ref), 1e-9) << m.generated->name << " row " << r;
      }
      // Five-point central differences (error O(h⁴)), each column with a step scaled to its
      // variable: near the cylinders' smooth end stops the third derivative is large, so the
      // plain three-point formula's O(h²) error would dominate.
      for (int c = 0; c < n; ++c) {
        const double h = 1e-5 * std::max(1.0, std::abs(x[c]));
        std::vector<std::vector<double>> f(4, std::vector<double>(n));
        const double offsets[4] = {2, 1, -1, -2};
        for (int k = 0; k < 4; ++k) {
          std::vector<double> shifted = x;
          shifted[c] += offsets[k] * h;
          m.generated->plant_rhs(0.0, shifted.data(), u.data(), f[k].data());
        }
        for (int r = 0; r < n; ++r) {
          const double central = (-f[0][r] + 8 * f[1][r] - 8 * f[2][r] + f[3][r]) / (12 * h);
          // Rows are scaled by their largest entry (pressure rows reach 1e10 per unit). The
          // accelerations are differences of torques near 1e6 N m, so round-off limits the
          // differences to about 1e-6 of the row scale; the exact check is the one above.
          double scale = 1.0;
          for (int k = 0; k < n; ++k) scale = std::max(scale, std::abs(jacobian[r * n + k]));
          ASSERT_NEAR(jacobian[r * n + c], central, 1e-5 * scale)
              << m.generated->name << " d f[" << r << "] / d x[" << c << "]";
        }
      }
    }
  }
}

// A closed valve with chamber pressures chosen to carry the arm's weight holds it still: the
// joint accelerations vanish, the spool stays, and the pressures do not drift.
TEST(GeneratedPlant, ClosedValveHoldsTheArmAtStaticBalance) {
  for (const auto& m : LoadGeneratedMachines()) {
    const auto& g = *m.generated;
    const int J = g.num_joints;
    std::vector<double> q(J);
    for (int j = 0; j < J; ++j) q[j] = 0.5 * (g.joint_min[j] + g.joint_max[j]);
    const std::vector<double> gravity = m.interpreted->GravityTorques(q.data(), 0.0, 0.0);
    std::vector<double> x(g.num_states, 0.0), u(g.num_inputs, 0.0), xdot(g.num_states);
    for (int j = 0; j < J; ++j) x[j] = q[j];
    const double tank = m.description->hydraulics.tank_pressure;
    // Solve each cylinder's force that balances gravity, distal joints first: a cylinder may
    // also push on the joints before the one it drives (a frame-mounted tilt cylinder), never
    // on those after it, so the balance is triangular.
    std::vector<double> cylinder_force(J, 0.0);
    for (int j = J - 1; j >= 0; --j) {
      double torque = -gravity[j];
      for (int k = j + 1; k < J; ++k) {
        const int other = m.interpreted->ActuatorOfJoint(k);
        torque -= cylinder_force[k] * m.interpreted->LeverArms(other, q.data())[j];
      }
      const int actuator = m.interpreted->ActuatorOfJoint(j);
      const auto& a = m.description->hydraulics.actuators[actuator];
      x[4 * J + j] = tank;
      if (a.kind == model::ActuatorKind::kMotor) {
        x[3 * J + j] = tank;
        continue;
      }
      cylinder_force[j] = torque / g.lever_arm(actuator, q.data());
      const double area_a = a.count * M_PI / 4 * a.bore * a.bore;
      const double area_b = a.count * M_PI / 4 * (a.bore * a.bore - a.rod * a.rod);
      // The smooth end-stop spring pushes a little even mid-stroke: the pressure makes up the
      // rest of the force.
      const double extension = g.cylinder_length(actuator, q.data()) - a.retracted_length;
      const double end_force =
          a.count * model::plant::kEndStopStiffness *
          (model::internal::SmoothPositive(-extension, model::plant::kEndStopSmoothing) -
           model::internal::SmoothPositive(extension - a.stroke, model::plant::kEndStopSmoothing));
      x[3 * J + j] = (cylinder_force[j] - end_force + tank * area_b) / area_a;
    }
    for (int j = 0; j < J; ++j) u[2 * J + 2 + j] = m.description->hydraulics.pump_pressure;
    g.plant_rhs(0.0, x.data(), u.data(), xdot.data());
    for (int j = 0; j < J; ++j) {
      // Unbalanced, gravity alone would give several rad/s²; balanced, only rounding remains.
      EXPECT_NEAR(xdot[J + j], 0.0, 1e-6) << g.name << " joint " << j;  // [rad/s²]
      EXPECT_EQ(xdot[j], 0.0);
      EXPECT_EQ(xdot[2 * J + j], 0.0);
    }
  }
}

// Opening a valve towards the cap side pushes oil in: the cap pressure rises and the rod side
// falls when the cylinder is held still.
TEST(GeneratedPlant, OpenValveFillsCapSideAndDrainsRodSide) {
  for (const auto& m : LoadGeneratedMachines()) {
    const auto& g = *m.generated;
    const int J = g.num_joints;
    std::vector<double> x(g.num_states, 0.0), u(g.num_inputs, 0.0), xdot(g.num_states);
    for (int j = 0; j < J; ++j) {
      x[j] = 0.5 * (g.joint_min[j] + g.joint_max[j]);
      x[2 * J + j] = 0.8;
      x[3 * J + j] = x[4 * J + j] = 8e6;
      u[j] = 0.8;
    }
    for (int j = 0; j < J; ++j) u[2 * J + 2 + j] = m.description->hydraulics.pump_pressure;
    g.plant_rhs(0.0, x.data(), u.data(), xdot.data());
    for (int j = 0; j < J; ++j) {
      EXPECT_GT(xdot[3 * J + j], 0.0) << g.name << " joint " << j;
      EXPECT_LT(xdot[4 * J + j], 0.0) << g.name << " joint " << j;
    }
  }
}

}  // namespace
}  // namespace autoshovel::testing
