// The interpreted fallback behind generated::MachineFunctions (runtime/machines/
// interpreted_functions.h) against the generated code of every compiled-in machine: the same
// kinematics, inverse, Jacobians, cylinder geometry and calibration residual at random
// configurations, and a plant Jacobian that is the derivative of its own right-hand side.
#include "runtime/machines/interpreted_functions.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include "generated/registry.h"
#include "runtime/machines/machine_code.h"
#include "runtime/model/interpreted_model.h"

namespace autoshovel::machines {
namespace {

const std::string kSource = AUTOSHOVEL_SOURCE_DIR;

struct Pair {
  const generated::MachineFunctions* generated;
  const generated::MachineFunctions* interpreted;
};

std::vector<Pair> Machines() {
  std::vector<Pair> pairs;  // InterpretedFunctions copies the description: d may go
  for (const generated::MachineFunctions* g : generated::AllMachines()) {
    const model::MachineDescription d =
        model::LoadMachineDescription(kSource + "/" + g->source_file);
    pairs.push_back({g, &InterpretedFunctions(d)});
  }
  return pairs;
}

std::vector<double> RandomJoints(const generated::MachineFunctions& f, std::mt19937_64& rng) {
  std::vector<double> q(f.num_joints);
  for (int j = 0; j < f.num_joints; ++j) {
    q[j] = std::uniform_real_distribution<double>(f.joint_min[j], f.joint_max[j])(rng);
  }
  return q;
}

std::vector<double> RandomAngles(const generated::MachineFunctions& f, std::mt19937_64& rng) {
  std::vector<double> a(f.num_angles);
  for (double& v : a) v = std::uniform_real_distribution<double>(-1.2, 1.2)(rng);
  return a;
}

TEST(InterpretedFunctions, DescribeTheSameMachineAsTheGeneratedCode) {
  for (const Pair& p : Machines()) {
    const auto& g = *p.generated;
    const auto& f = *p.interpreted;
    SCOPED_TRACE(g.name);
    EXPECT_STREQ(f.name, g.name);
    EXPECT_STREQ(f.kind, g.kind);
    EXPECT_STREQ(f.source_sha256, g.source_sha256);
    EXPECT_EQ(f.num_links, g.num_links);
    EXPECT_EQ(f.num_joints, g.num_joints);
    EXPECT_EQ(f.num_angles, g.num_angles);
    EXPECT_EQ(f.num_params, g.num_params);
    EXPECT_EQ(f.num_states, g.num_states);
    EXPECT_EQ(f.num_inputs, g.num_inputs);
    ASSERT_EQ(f.num_actuators, g.num_actuators);
    for (int k = 0; k < g.num_params; ++k)
      EXPECT_DOUBLE_EQ(f.nominal_params[k], g.nominal_params[k]);
    for (int j = 0; j < g.num_joints; ++j) {
      EXPECT_DOUBLE_EQ(f.joint_min[j], g.joint_min[j]);
      EXPECT_DOUBLE_EQ(f.joint_max[j], g.joint_max[j]);
    }
    for (int a = 0; a < g.num_actuators; ++a) EXPECT_EQ(f.actuator_joint[a], g.actuator_joint[a]);
    // The same description again gives the same table.
    EXPECT_EQ(&InterpretedFunctions(model::LoadMachineDescription(kSource + "/" + g.source_file)),
              &f);
  }
}

TEST(InterpretedFunctions, KinematicsAndJacobiansMatchGeneratedCode) {
  for (const Pair& p : Machines()) {
    const auto& g = *p.generated;
    const auto& f = *p.interpreted;
    SCOPED_TRACE(g.name);
    std::mt19937_64 rng(3901);
    const std::vector<double> params(g.nominal_params, g.nominal_params + g.num_params);
    for (int i = 0; i < 500; ++i) {
      const std::vector<double> angles = RandomAngles(g, rng);
      double pose_g[4], pose_f[4];
      std::vector<double> da_g(4 * g.num_angles), dp_g(4 * g.num_params);
      std::vector<double> da_f(da_g.size()), dp_f(dp_g.size());
      g.forward_kinematics_jacobians(angles.data(), params.data(), pose_g, da_g.data(),
                                     dp_g.data());
      f.forward_kinematics_jacobians(angles.data(), params.data(), pose_f, da_f.data(),
                                     dp_f.data());
      for (int r = 0; r < 4; ++r) ASSERT_NEAR(pose_f[r], pose_g[r], 1e-10);
      for (std::size_t k = 0; k < da_g.size(); ++k) ASSERT_NEAR(da_f[k], da_g[k], 1e-10) << k;
      for (std::size_t k = 0; k < dp_g.size(); ++k) ASSERT_NEAR(dp_f[k], dp_g[k], 1e-10) << k;
      f.forward_kinematics(angles.data(), params.data(), pose_f);
      for (int r = 0; r < 4; ++r) ASSERT_NEAR(pose_f[r], pose_g[r], 1e-10);

      // Eq. (3) residual between two random poses.
      const std::vector<double> other = RandomAngles(g, rng);
      const double measured[2] = {0.3, -0.1};
      double r_g[2], r_f[2];
      g.tip_displacement_residual(angles.data(), other.data(), measured, params.data(), r_g);
      f.tip_displacement_residual(angles.data(), other.data(), measured, params.data(), r_f);
      ASSERT_NEAR(r_f[0], r_g[0], 1e-10);
      ASSERT_NEAR(r_f[1], r_g[1], 1e-10);
    }
  }
}

TEST(InterpretedFunctions, InverseKinematicsMatchesGeneratedCodeAndClosesTheLoop) {
  for (const Pair& p : Machines()) {
    const auto& g = *p.generated;
    const auto& f = *p.interpreted;
    SCOPED_TRACE(g.name);
    std::mt19937_64 rng(3902);
    const std::vector<double> params(g.nominal_params, g.nominal_params + g.num_params);
    int solved = 0;
    for (int i = 0; i < 500; ++i) {
      // A reachable target: the tip at random joints (frame M level, no IMU offsets).
      const std::vector<double> q = RandomJoints(g, rng);
      std::vector<double> angles(g.num_angles, 0.0);
      double phi = 0;
      for (int k = 0; k < g.num_links; ++k) {
        phi += q[k];
        angles[k + 1] = phi - params[g.num_links + k];
      }
      if (g.num_angles > g.num_links + 1) angles.back() = q.back();
      double target[4];
      g.forward_kinematics(angles.data(), params.data(), target);
      std::vector<double> q_g(g.num_joints), q_f(g.num_joints);
      const int status_g = g.inverse_kinematics(target, params.data(), q_g.data());
      const int status_f = f.inverse_kinematics(target, params.data(), q_f.data());
      ASSERT_EQ(status_f, status_g);
      for (int j = 0; j < g.num_joints; ++j) ASSERT_NEAR(q_f[j], q_g[j], 1e-9) << j;
      solved += status_f == 0;
    }
    EXPECT_GT(solved, 250);
    const double far[4] = {1e3, 0.0, 1e3, 0.0};
    std::vector<double> q(g.num_joints);
    EXPECT_EQ(f.inverse_kinematics(far, params.data(), q.data()), 1);
  }
}

TEST(InterpretedFunctions, CylinderGeometryMatchesGeneratedCode) {
  for (const Pair& p : Machines()) {
    const auto& g = *p.generated;
    const auto& f = *p.interpreted;
    SCOPED_TRACE(g.name);
    std::mt19937_64 rng(3903);
    for (int i = 0; i < 500; ++i) {
      const std::vector<double> q = RandomJoints(g, rng);
      for (int a = 0; a < g.num_actuators; ++a) {
        const double length = g.cylinder_length(a, q.data());
        if (!std::isfinite(length)) continue;  // a linkage that does not close there
        ASSERT_NEAR(f.cylinder_length(a, q.data()), length, 1e-10) << a;
        ASSERT_NEAR(f.lever_arm(a, q.data()), g.lever_arm(a, q.data()), 1e-8) << a;
        // Back from the length to the joint.
        std::vector<double> start = RandomJoints(g, rng);
        start[g.actuator_joint[a]] =
            0.5 * (g.joint_min[g.actuator_joint[a]] + g.joint_max[g.actuator_joint[a]]);
        for (int j = 0; j < g.num_joints; ++j) {
          if (j != g.actuator_joint[a]) start[j] = q[j];
        }
        std::vector<double> q_f(g.num_joints), q_g(g.num_joints);
        const int status_f = f.joint_from_cylinder_length(a, length, start.data(), q_f.data());
        const int status_g = g.joint_from_cylinder_length(a, length, start.data(), q_g.data());
        ASSERT_EQ(status_f, status_g);
        if (status_f == 0) {
          ASSERT_NEAR(q_f[g.actuator_joint[a]], q[g.actuator_joint[a]], 1e-8);
          ASSERT_NEAR(q_f[g.actuator_joint[a]], q_g[g.actuator_joint[a]], 1e-8);
        }
      }
    }
    std::vector<double> q(g.num_joints, 0.0);
    EXPECT_TRUE(std::isnan(f.cylinder_length(g.num_actuators, q.data())));
    EXPECT_TRUE(std::isnan(f.lever_arm(-1, q.data())));
  }
}

TEST(InterpretedFunctions, RigidBodyTermsMatchGeneratedCode) {
  for (const Pair& p : Machines()) {
    const auto& g = *p.generated;
    const auto& f = *p.interpreted;
    SCOPED_TRACE(g.name);
    ASSERT_NE(f.mass_matrix, nullptr);
    ASSERT_NE(f.bias_forces, nullptr);
    ASSERT_NE(f.mechanical_energy, nullptr);
    const int J = g.num_joints;
    std::mt19937_64 rng(3905);
    for (int i = 0; i < 100; ++i) {
      const std::vector<double> q = RandomJoints(g, rng);
      std::vector<double> qd(J);
      for (double& v : qd) v = std::uniform_real_distribution<double>(-0.8, 0.8)(rng);
      const double payload = 3000.0, pitch = 0.05;
      std::vector<double> mass_g(J * J), mass_f(J * J), bias_g(J), bias_f(J);
      g.mass_matrix(q.data(), payload, mass_g.data());
      f.mass_matrix(q.data(), payload, mass_f.data());
      double scale = 1.0;
      for (double v : mass_g) scale = std::max(scale, std::abs(v));
      for (int k = 0; k < J * J; ++k) ASSERT_NEAR(mass_f[k], mass_g[k], 1e-8 * scale) << k;
      g.bias_forces(q.data(), qd.data(), payload, pitch, bias_g.data());
      f.bias_forces(q.data(), qd.data(), payload, pitch, bias_f.data());
      scale = 1.0;
      for (double v : bias_g) scale = std::max(scale, std::abs(v));
      for (int k = 0; k < J; ++k) ASSERT_NEAR(bias_f[k], bias_g[k], 1e-8 * scale) << k;
      double energy_g[2], energy_f[2];
      g.mechanical_energy(q.data(), qd.data(), payload, pitch, energy_g);
      f.mechanical_energy(q.data(), qd.data(), payload, pitch, energy_f);
      ASSERT_NEAR(energy_f[0], energy_g[0], 1e-8 * std::max(1.0, std::abs(energy_g[0])));
      ASSERT_NEAR(energy_f[1], energy_g[1], 1e-8 * std::max(1.0, std::abs(energy_g[1])));
    }
  }
}

TEST(InterpretedFunctions, PlantIsTheReferenceModelAndItsJacobianItsDerivative) {
  for (const Pair& p : Machines()) {
    const auto& f = *p.interpreted;
    SCOPED_TRACE(f.name);
    const model::MachineDescription d =
        model::LoadMachineDescription(kSource + "/" + p.generated->source_file);
    const model::InterpretedModel reference(d);
    const int n = f.num_states, J = f.num_joints;
    std::mt19937_64 rng(3904);
    std::vector<double> x(n), u(f.num_inputs, 0.0), xdot(n), expected(n);
    const std::vector<double> q = RandomJoints(f, rng);
    for (int j = 0; j < J; ++j) {
      x[j] = q[j];
      x[J + j] = 0.05 * (j + 1);
      x[2 * J + j] = 0.2;
      x[3 * J + j] = 8e6;
      x[4 * J + j] = 3e6;
      u[j] = 0.4;
      u[2 * J + 2 + j] = 2.5e7;
    }
    u[2 * J] = 2000;  // payload [kg]
    f.plant_rhs(0.0, x.data(), u.data(), xdot.data());
    reference.PlantRhs(x.data(), u.data(), expected.data());
    for (int i = 0; i < n; ++i) ASSERT_DOUBLE_EQ(xdot[i], expected[i]) << i;
    std::vector<double> jacobian(n * n);
    f.plant_jacobian(0.0, x.data(), u.data(), jacobian.data());
    std::vector<double> row_scale(n, 1.0);  // entries of a row are compared at its magnitude
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) {
        row_scale[r] =
            std::max(row_scale[r], std::abs(jacobian[r * n + c]) * std::max(1.0, std::abs(x[c])));
      }
    }
    for (int c = 0; c < n; ++c) {
      const double h = 1e-6 * std::max(1.0, std::abs(x[c]));
      std::vector<double> up = x, down = x, f_up(n), f_down(n);
      up[c] += h;
      down[c] -= h;
      f.plant_rhs(0.0, up.data(), u.data(), f_up.data());
      f.plant_rhs(0.0, down.data(), u.data(), f_down.data());
      for (int r = 0; r < n; ++r) {
        const double numeric = (f_up[r] - f_down[r]) / (2 * h);
        // To 1e-6 of the row's largest change for a relative change of one state.
        ASSERT_NEAR(jacobian[r * n + c], numeric,
                    1e-6 * row_scale[r] / std::max(1.0, std::abs(x[c])))
            << "row " << r << " column " << c;
      }
    }
  }
}

// An overlay that changes a value the generated code compiles in (the spool time constant, the
// rated flow) must not run on that code, which would ignore it: the interpreted model runs, and
// says so. An overlay of values applied outside the generated code keeps the compiled code.
TEST(OverlayOnCompiledCode, CompiledInValuesSendTheMachineToTheInterpretedModel) {
  const std::string dir = ::testing::TempDir() + "/overlay_code_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  const std::string base = kSource + "/models/excavators/excavator_25t.yaml";
  const model::MachineDescription plain = model::LoadMachineDescription(base);
  auto overlay = [&](const std::string& name, const std::string& body) {
    const std::string path = dir + "/" + name;
    std::ofstream(path) << "machine: excavator_25t\nbase_sha256: " << plain.sha256
                        << "\nhydraulics:\n  actuators:\n    - name: boom_cylinders\n"
                        << body;
    model::LoadOptions options;
    options.overlays = {path};
    return model::LoadMachineDescription(base, options);
  };
  ResolveOptions resolve;
  std::ostringstream notes;
  resolve.notes = &notes;
  const model::MachineDescription delay = overlay("delay.yaml", "      transport_delay: 0.2\n");
  EXPECT_EQ(ResolveMachineCode(delay, resolve).source, CodeSource::kCompiledIn);
  const model::MachineDescription spool = overlay("spool.yaml", "      spool_time_constant: 0.2\n");
  const MachineCode code = ResolveMachineCode(spool, resolve);
  EXPECT_EQ(code.source, CodeSource::kInterpreted);
  EXPECT_NE(notes.str().find("spool_time_constant"), std::string::npos) << notes.str();
  // And the interpreted code runs with the overlay's value: the boom spool's rate
  // ẋ_s = (u − x_s)/τ_s (the plant's state 2J + actuator, codegen/symbolic_model.cc).
  const generated::MachineFunctions& compiled = *ResolveMachineCode(plain, resolve).functions;
  std::vector<double> y(static_cast<std::size_t>(compiled.num_states), 0.0);
  std::vector<double> u(static_cast<std::size_t>(compiled.num_inputs), 0.5);
  std::vector<double> a(y.size()), b(y.size());
  compiled.plant_rhs(0.0, y.data(), u.data(), a.data());
  code.functions->plant_rhs(0.0, y.data(), u.data(), b.data());
  const std::size_t spool_rate = 2 * static_cast<std::size_t>(compiled.num_joints);
  EXPECT_NEAR(b[spool_rate], 0.5 / 0.2, 1e-9);
  EXPECT_NEAR(a[spool_rate], 0.5 / plain.hydraulics.actuators[0].valve.spool_time_constant, 1e-9);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace autoshovel::machines
