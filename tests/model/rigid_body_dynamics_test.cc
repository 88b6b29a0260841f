// The interpreted model's rigid-body dynamics (issue 39) against an independent numerical
// Lagrangian, and energy conservation of the unactuated, frictionless arm. The description is a
// shipped loader with masses added to its rocker, coupler and cylinders, so that every kind of
// moving body takes part.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>

#include "runtime/model/description.h"
#include "runtime/model/interpreted_model.h"

namespace autoshovel::model {
namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// xcmg_968ev with a heavy rocker and coupler and massive cylinder barrels and rods.
MachineDescription LoaderWithEveryBody() {
  const std::string source = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models/loaders/xcmg_968ev.yaml";
  std::string text = ReadText(source);
  text = std::regex_replace(text, std::regex("        assembly_branch: 1\n"),
                            "        assembly_branch: 1\n        rocker_mass: 420\n"
                            "        rocker_center_of_mass: [-0.2, -0.05]\n"
                            "        rocker_inertia: 45\n        coupler_mass: 160\n"
                            "        coupler_inertia: 14\n");
  text = std::regex_replace(text, std::regex("      dead_volume: ([0-9.]+)\n"),
                            "      dead_volume: $1\n      barrel_mass: 190\n      rod_mass: 110\n");
  const auto folder = std::filesystem::temp_directory_path() / "autoshovel_dynamics_test";
  std::filesystem::create_directories(folder / "loaders");
  const auto path = folder / "loaders" / "every_body.yaml";
  std::ofstream(path) << text;
  LoadOptions options;
  options.materials_dir = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models/materials";
  return LoadMachineDescription(path.string(), options);
}

struct Terms {
  std::vector<double> mass, velocity_terms, gravity;
};

Terms DynamicsOf(const InterpretedModel& model, const std::vector<double>& q,
                 const std::vector<double>& qd, double payload) {
  const int J = model.sizes().num_joints;
  Terms t{std::vector<double>(J * J), std::vector<double>(J), std::vector<double>(J)};
  model.Dynamics(q.data(), qd.data(), payload, 0.0, t.mass.data(), t.velocity_terms.data(),
                 t.gravity.data());
  return t;
}

// T(q, v) from body velocities by central differences of the body positions along v: no
// Jacobian and no closed form, only positions.
double NumericKinetic(const InterpretedModel& model, const std::vector<double>& q,
                      const std::vector<double>& v, double payload) {
  constexpr double kStep = 1e-6;
  std::vector<double> plus = q, minus = q;
  for (std::size_t i = 0; i < q.size(); ++i) {
    plus[i] += kStep * v[i];
    minus[i] -= kStep * v[i];
  }
  std::vector<BodyState<double>> a, b;
  EXPECT_TRUE(model.MovingBodies(plus.data(), payload, a));
  EXPECT_TRUE(model.MovingBodies(minus.data(), payload, b));
  double kinetic = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const double vx = (a[k].center.x - b[k].center.x) / (2 * kStep);
    const double vz = (a[k].center.z - b[k].center.z) / (2 * kStep);
    const double w = (a[k].angle - b[k].angle) / (2 * kStep);
    kinetic += 0.5 * (a[k].mass * (vx * vx + vz * vz) + a[k].inertia * w * w);
  }
  return kinetic;
}

// M_ij by polarisation of the quadratic form T(v) = ½ vᵀ M v.
std::vector<double> NumericMass(const InterpretedModel& model, const std::vector<double>& q,
                                double payload) {
  const int J = static_cast<int>(q.size());
  std::vector<double> mass(J * J);
  for (int i = 0; i < J; ++i) {
    for (int j = 0; j < J; ++j) {
      std::vector<double> ei(J, 0.0), ej(J, 0.0), eij(J, 0.0);
      ei[i] = 1;
      ej[j] = 1;
      eij[i] += 1;
      eij[j] += 1;
      mass[i * J + j] = NumericKinetic(model, q, eij, payload) -
                        NumericKinetic(model, q, ei, payload) -
                        NumericKinetic(model, q, ej, payload);
      if (i == j) mass[i * J + j] = 2 * NumericKinetic(model, q, ei, payload);
    }
  }
  return mass;
}

double Potential(const InterpretedModel& model, const std::vector<double>& q, double payload) {
  std::vector<BodyState<double>> bodies;
  EXPECT_TRUE(model.MovingBodies(q.data(), payload, bodies));
  double v = 0;
  for (const auto& b : bodies) v += b.mass * 9.80665 * b.center.z;
  return v;
}

TEST(RigidBodyDynamics, AgreesWithANumericalLagrangian) {
  const MachineDescription machine = LoaderWithEveryBody();
  const InterpretedModel model(machine);
  const int J = model.sizes().num_joints;
  std::mt19937_64 rng(39);
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<double> q(J), qd(J);
    for (int j = 0; j < J; ++j) {
      const Link& link = machine.links[j];
      q[j] = std::uniform_real_distribution<double>(link.joint_min, link.joint_max)(rng);
      qd[j] = std::uniform_real_distribution<double>(-0.8, 0.8)(rng);
    }
    const double payload = std::uniform_real_distribution<double>(0, 6000)(rng);
    const Terms terms = DynamicsOf(model, q, qd, payload);
    const std::vector<double> mass = NumericMass(model, q, payload);
    double scale = 0;
    for (double m : mass) scale = std::max(scale, std::abs(m));
    for (int k = 0; k < J * J; ++k) EXPECT_NEAR(terms.mass[k], mass[k], 1e-6 * scale) << k;
    // Off-diagonal coupling is real, not a rounding residue.
    EXPECT_GT(std::abs(terms.mass[1]), 1e-3 * scale);

    // Lagrange: h_i = Σ_k ∂(M q̇)_i/∂q_k q̇_k − ∂T/∂q_i, Q_g = −∂V/∂q, by central differences.
    constexpr double kStep = 1e-4;
    std::vector<double> h(J, 0.0), gravity(J, 0.0);
    for (int k = 0; k < J; ++k) {
      std::vector<double> plus = q, minus = q;
      plus[k] += kStep;
      minus[k] -= kStep;
      const std::vector<double> mp = NumericMass(model, plus, payload);
      const std::vector<double> mm = NumericMass(model, minus, payload);
      for (int i = 0; i < J; ++i) {
        for (int l = 0; l < J; ++l) {
          h[i] += (mp[i * J + l] - mm[i * J + l]) / (2 * kStep) * qd[l] * qd[k];
        }
      }
      const double dT =
          (NumericKinetic(model, plus, qd, payload) - NumericKinetic(model, minus, qd, payload)) /
          (2 * kStep);
      h[k] -= dT;
      gravity[k] =
          -(Potential(model, plus, payload) - Potential(model, minus, payload)) / (2 * kStep);
    }
    double h_scale = 1.0, g_scale = 1.0;
    for (int i = 0; i < J; ++i) {
      h_scale = std::max(h_scale, std::abs(h[i]));
      g_scale = std::max(g_scale, std::abs(gravity[i]));
    }
    for (int i = 0; i < J; ++i) {
      EXPECT_NEAR(terms.velocity_terms[i], h[i], 1e-4 * h_scale) << "joint " << i;
      EXPECT_NEAR(terms.gravity[i], gravity[i], 1e-6 * g_scale) << "joint " << i;
    }
  }
}

// The unactuated, frictionless arm conserves T + V; dropping the velocity terms (the old
// diagonal model's simplification) does not.
double EnergyDrift(const InterpretedModel& model, std::vector<double> q, std::vector<double> qd,
                   bool with_velocity_terms) {
  const int J = static_cast<int>(q.size());
  auto acceleration = [&](const std::vector<double>& qq, const std::vector<double>& vv) {
    Terms t = DynamicsOf(model, qq, vv, 2000.0);
    std::vector<double> rhs(J);
    for (int i = 0; i < J; ++i) {
      rhs[i] = t.gravity[i] - (with_velocity_terms ? t.velocity_terms[i] : 0.0);
    }
    // 2 × 2 (a loader): Cramer's rule.
    const double det = t.mass[0] * t.mass[3] - t.mass[1] * t.mass[2];
    return std::vector<double>{(rhs[0] * t.mass[3] - t.mass[1] * rhs[1]) / det,
                               (t.mass[0] * rhs[1] - t.mass[2] * rhs[0]) / det};
  };
  auto energy = [&](const std::vector<double>& qq, const std::vector<double>& vv) {
    const auto e = model.MechanicalEnergy(qq.data(), vv.data(), 2000.0, 0.0);
    return e[0] + e[1];
  };
  const double start = energy(q, qd);
  double worst = 0;
  constexpr double kDt = 2e-4;
  for (int step = 0; step < 1500; ++step) {  // 0.3 s, RK4
    auto shift = [&](const std::vector<double>& base, const std::vector<double>& d, double h) {
      std::vector<double> out(J);
      for (int i = 0; i < J; ++i) out[i] = base[i] + h * d[i];
      return out;
    };
    const auto a1 = acceleration(q, qd);
    const auto q2 = shift(q, qd, kDt / 2), v2 = shift(qd, a1, kDt / 2);
    const auto a2 = acceleration(q2, v2);
    const auto q3 = shift(q, v2, kDt / 2), v3 = shift(qd, a2, kDt / 2);
    const auto a3 = acceleration(q3, v3);
    const auto q4 = shift(q, v3, kDt), v4 = shift(qd, a3, kDt);
    const auto a4 = acceleration(q4, v4);
    for (int i = 0; i < J; ++i) {
      q[i] += kDt / 6 * (qd[i] + 2 * v2[i] + 2 * v3[i] + v4[i]);
      qd[i] += kDt / 6 * (a1[i] + 2 * a2[i] + 2 * a3[i] + a4[i]);
    }
    worst = std::max(worst, std::abs(energy(q, qd) - start));
  }
  return worst;
}

TEST(RigidBodyDynamics, UnactuatedFrictionlessArmConservesEnergy) {
  const MachineDescription machine = LoaderWithEveryBody();
  const InterpretedModel model(machine);
  const std::vector<double> q{0.1, 0.2}, qd{0.9, -1.2};
  const auto e = model.MechanicalEnergy(q.data(), qd.data(), 2000.0, 0.0);
  const double drift = EnergyDrift(model, q, qd, true);
  const double drift_without = EnergyDrift(model, q, qd, false);
  EXPECT_LT(drift, 1e-7 * e[0]) << "kinetic " << e[0] << " J";
  EXPECT_GT(drift_without, 1e3 * drift) << "the velocity terms must matter";
}

}  // namespace
}  // namespace autoshovel::model
