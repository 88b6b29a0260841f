// Generated forward kinematics + Jacobians against the run-time interpreted evaluation of the
// same description (the interpreted model differentiated by Eigen's AutoDiffScalar), and the
// plant right-hand side and Jacobian, for every generated machine.
//   build/tests/bench/kinematics_bench --benchmark_min_time=0.2
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <memory>
#include <random>
#include <unsupported/Eigen/AutoDiff>

#include "generated/registry.h"
#include "runtime/model/interpreted_model.h"

namespace {

using autoshovel::generated::MachineFunctions;
using autoshovel::model::InterpretedModel;
using autoshovel::model::MachineDescription;

struct Fixture {
  const MachineFunctions* generated;
  std::unique_ptr<MachineDescription> description;
  std::unique_ptr<InterpretedModel> interpreted;
  std::vector<std::vector<double>> angles;  // a ring of random configurations
};

Fixture Make(const MachineFunctions* g) {
  Fixture f{g,
            std::make_unique<MachineDescription>(autoshovel::model::LoadMachineDescription(
                std::string(AUTOSHOVEL_SOURCE_DIR) + "/" + g->source_file)),
            nullptr,
            {}};
  f.interpreted = std::make_unique<InterpretedModel>(*f.description);
  std::mt19937_64 rng(1);
  for (int i = 0; i < 256; ++i) {
    std::vector<double> q(g->num_joints);
    for (int j = 0; j < g->num_joints; ++j) {
      q[j] = std::uniform_real_distribution<double>(g->joint_min[j], g->joint_max[j])(rng);
    }
    f.angles.push_back(f.interpreted->AnglesFromJoints(q.data(), g->nominal_params));
  }
  return f;
}

void GeneratedFkAndJacobians(benchmark::State& state, const MachineFunctions* g) {
  const Fixture f = Make(g);
  std::vector<double> pose(4), da(4 * g->num_angles), dp(4 * g->num_params);
  std::size_t i = 0;
  for (auto _ : state) {
    g->forward_kinematics_jacobians(f.angles[i++ & 255].data(), g->nominal_params, pose.data(),
                                    da.data(), dp.data());
    benchmark::DoNotOptimize(pose.data());
    benchmark::DoNotOptimize(dp.data());
  }
}

void InterpretedFkAndJacobians(benchmark::State& state, const MachineFunctions* g) {
  using Dual = Eigen::AutoDiffScalar<Eigen::VectorXd>;
  const Fixture f = Make(g);
  const int na = g->num_angles, np = g->num_params;
  std::vector<Dual> angles(na), params(np);
  Dual pose[4];
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& a = f.angles[i++ & 255];
    for (int k = 0; k < na; ++k) angles[k] = Dual(a[k], na + np, k);
    for (int k = 0; k < np; ++k) params[k] = Dual(g->nominal_params[k], na + np, na + k);
    f.interpreted->ForwardKinematics(angles.data(), params.data(), pose);
    benchmark::DoNotOptimize(pose[0].derivatives().data());
  }
}

void PlantState(const Fixture& f, std::vector<double>& x, std::vector<double>& u) {
  const auto* g = f.generated;
  const int J = g->num_joints;
  x.assign(g->num_states, 0.0);
  u.assign(g->num_inputs, 0.0);
  for (int j = 0; j < J; ++j) {
    x[j] = 0.5 * (g->joint_min[j] + g->joint_max[j]);
    x[2 * J + j] = 0.3;
    x[3 * J + j] = 1e7;
    x[4 * J + j] = 3e6;
    u[j] = 0.5;
  }
  for (int j = 0; j < J; ++j) u[2 * J + 2 + j] = 2.5e7;  // supply pressures
}

void GeneratedPlantRhsAndJacobian(benchmark::State& state, const MachineFunctions* g) {
  const Fixture f = Make(g);
  std::vector<double> x, u, xdot(g->num_states), jac(g->num_states * g->num_states);
  PlantState(f, x, u);
  for (auto _ : state) {
    g->plant_rhs(0.0, x.data(), u.data(), xdot.data());
    g->plant_jacobian(0.0, x.data(), u.data(), jac.data());
    benchmark::DoNotOptimize(jac.data());
  }
}

void InterpretedPlantRhsAndJacobian(benchmark::State& state, const MachineFunctions* g) {
  const Fixture f = Make(g);
  std::vector<double> x, u, xdot(g->num_states), jac(g->num_states * g->num_states);
  PlantState(f, x, u);
  for (auto _ : state) {
    f.interpreted->PlantRhs(x.data(), u.data(), xdot.data());
    f.interpreted->PlantJacobian(x.data(), u.data(), jac.data());
    benchmark::DoNotOptimize(jac.data());
  }
}

}  // namespace

int main(int argc, char** argv) {
  for (const MachineFunctions* g : autoshovel::generated::AllMachines()) {
    const std::string name = g->name;
    benchmark::RegisterBenchmark(("FkJacobians/generated/" + name).c_str(), GeneratedFkAndJacobians,
                                 g);
    benchmark::RegisterBenchmark(("FkJacobians/interpreted/" + name).c_str(),
                                 InterpretedFkAndJacobians, g);
    benchmark::RegisterBenchmark(("PlantRhsJacobian/generated/" + name).c_str(),
                                 GeneratedPlantRhsAndJacobian, g);
    benchmark::RegisterBenchmark(("PlantRhsJacobian/interpreted/" + name).c_str(),
                                 InterpretedPlantRhsAndJacobian, g);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
