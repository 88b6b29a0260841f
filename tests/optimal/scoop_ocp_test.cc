// The optimal-control scoop: the smooth model's exact derivatives, the collocation's optimality
// (KKT) and feasibility, its trajectory re-integrated, and warm starts.
#include "runtime/optimal/scoop_ocp.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>

#include "runtime/model/description.h"
#include "runtime/plant/poses.h"

namespace autoshovel::optimal {
namespace {

model::MachineDescription Loader(const std::string& name = "xcmg_968ev") {
  return model::LoadMachineDescription(
      model::ResolveMachineDescription(name, std::string(AUTOSHOVEL_SOURCE_DIR) + "/models"));
}

const model::Material& MaterialNamed(const model::MachineDescription& m, const std::string& name) {
  for (const model::Material& material : m.materials) {
    if (material.name == name) return material;
  }
  throw std::runtime_error("no material " + name);
}

// The attack pose's edge sits at the pile's toe: contact.
struct ScoopSetup {
  model::MachineDescription machine;
  std::unique_ptr<ScoopModel> model;
  ScoopStart start;
};

ScoopSetup MakeSetup(const std::string& material, double pile_height = 2.5) {
  ScoopSetup s;
  s.machine = Loader();
  const std::vector<double> q = plant::BucketOnFloor(s.machine);
  s.start.q = {q[0], q[1]};
  s.start.speed = 1.0;
  // Where the edge is at the attack pose: the toe goes there.
  const model::Material& m = MaterialNamed(s.machine, material);
  ScoopModel probe_model(s.machine, m, PileProfile::Ramp(0.0, 100.0, 0.6, 1.0, 2.0));
  double tip_x = 0, tip_z = 0, angle = 0;
  probe_model.Tip(s.start.q.data(), 0.0, &tip_x, &tip_z, &angle);
  s.model = std::make_unique<ScoopModel>(
      s.machine, m, PileProfile::Ramp(0.0, tip_x, m.angle_of_repose, pile_height, 8.0));
  return s;
}

TEST(ScoopModel, JetDerivativesMatchCentralDifferences) {
  const ScoopSetup s = MakeSetup("big_gravel");
  // A state in the pile: driven 1.2 m in, boom raised a little, bucket starting to curl,
  // half full.
  double node[kNodeVariables] = {
      1.2, 0.6, s.start.q[0] + 0.02, s.start.q[1] + 0.05, 0.1, 0.3, 1.5, 5e4, 6e4, 0.5, 1.0};
  using Jet = ceres::Jet<double, kNodeVariables>;
  Jet jets[kNodeVariables];
  for (int i = 0; i < kNodeVariables; ++i) jets[i] = Jet(node[i], i);
  Jet rate[kStates], path[kNumPath];
  s.model->Evaluate(jets, jets + kStates, rate, path);
  for (int i = 0; i < kNodeVariables; ++i) {
    const double step = 1e-6 * std::max(1.0, std::abs(node[i]));
    double plus[kNodeVariables], minus[kNodeVariables];
    std::copy(node, node + kNodeVariables, plus);
    std::copy(node, node + kNodeVariables, minus);
    plus[i] += step;
    minus[i] -= step;
    double rate_plus[kStates], rate_minus[kStates], path_plus[kNumPath], path_minus[kNumPath];
    s.model->Evaluate(plus, plus + kStates, rate_plus, path_plus);
    s.model->Evaluate(minus, minus + kStates, rate_minus, path_minus);
    for (int r = 0; r < kStates; ++r) {
      const double numeric = (rate_plus[r] - rate_minus[r]) / (2 * step);
      EXPECT_NEAR(rate[r].v[i], numeric, 1e-5 * std::max(1.0, std::abs(numeric)))
          << "d rate[" << r << "] / d var[" << i << "]";
    }
  }
  // The state is in the pile: resistance acts, material flows in.
  const ScoopModelProbe probe = s.model->Probe(node, node + kStates);
  EXPECT_GT(probe.depth, 0.5);
  EXPECT_LT(probe.soil_force_s, -1e4);
  EXPECT_GT(probe.intake, 0.0);
}

TEST(ScoopModel, McKyesFactorsFitTheirTable) {
  const ScoopSetup s = MakeSetup("river_sand");
  EXPECT_LT(s.model->factor_fit_error(), 0.02);
}

TEST(ScoopModel, RefusesAnExcavator) {
  const model::MachineDescription excavator = Loader("excavator_25t");
  EXPECT_THROW(
      ScoopModel(excavator, excavator.materials.front(), PileProfile::Ramp(0, 1, 0.6, 1, 2)),
      std::invalid_argument);
}

class ScoopOcpSolve : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    setup_ = new ScoopSetup(MakeSetup("big_gravel"));
    options_.target_volume = 0.9 * setup_->model->heaped_capacity();
    options_.max_time = 8;
    ocp_ = new ScoopOcp(*setup_->model, options_);
    first_ = new ScoopOcpSolution(ocp_->Solve(setup_->start));
  }
  static void TearDownTestSuite() {
    delete first_;
    delete ocp_;
    delete setup_;
  }
  static ScoopSetup* setup_;
  static ScoopOcpOptions options_;
  static ScoopOcp* ocp_;
  static ScoopOcpSolution* first_;
};
ScoopSetup* ScoopOcpSolve::setup_ = nullptr;
ScoopOcpOptions ScoopOcpSolve::options_;
ScoopOcp* ScoopOcpSolve::ocp_ = nullptr;
ScoopOcpSolution* ScoopOcpSolve::first_ = nullptr;

TEST_F(ScoopOcpSolve, ConvergesToAKktPoint) {
  const ScoopOcpSolution& r = *first_;
  ASSERT_TRUE(r.ok) << r.status << "; worst: " << r.worst_constraint << " by " << r.worst_violation;
  // Ipopt's unscaled measures at the solution: the Lagrangian's gradient, the constraints,
  // complementarity.
  EXPECT_LT(r.dual_infeasibility, 1e-5);
  EXPECT_LT(r.constraint_violation, 1e-6);
  EXPECT_LT(r.complementarity, 1e-5);
  EXPECT_LT(r.kkt_error, 1e-5);
  std::printf("optimal scoop on gravel: %.1f kJ, %.2f s, %.2f m3, %d iterations, %.2f s\n",
              r.energy / 1e3, r.time, r.volume, r.iterations, r.solve_seconds);
}

TEST_F(ScoopOcpSolve, MeetsItsBoundsAndEnd) {
  const ScoopOcpSolution& r = *first_;
  ASSERT_TRUE(r.ok) << r.status;
  EXPECT_GE(r.volume, options_.target_volume - 1e-6);
  EXPECT_LE(r.time, options_.max_time + 1e-6);
  const auto& end = r.state.back();
  EXPECT_NEAR(end[kV], 0.0, 1e-8);
  EXPECT_GE(end[kQ + 1], setup_->model->joint_max(1) - 0.1 - 1e-6);
  const ScoopModelProbe probe = setup_->model->Probe(end.data(), r.control.back().data());
  EXPECT_LE(probe.depth, -options_.exit_clearance + 1e-6);  // out of the pile
  // Energy can only grow, and the payload's lift alone costs at least its potential energy.
  for (std::size_t k = 1; k < r.state.size(); ++k) {
    EXPECT_GE(r.state[k][kEnergy], r.state[k - 1][kEnergy] - 1e-3);
  }
}

TEST_F(ScoopOcpSolve, TrajectoryReintegratesToItsNodes) {
  // The collocated states against the model integrated by RK4 at 1 ms under the same
  // (piecewise-linear) controls: the trapezoid's error over the scoop.
  const ScoopOcpSolution& r = *first_;
  ASSERT_TRUE(r.ok) << r.status;
  std::array<double, kStates> x = r.state.front();
  const double dt = 1e-3;
  auto rate = [&](double t, const std::array<double, kStates>& state) {
    const std::array<double, kControls> u = r.ControlAt(t);
    std::array<double, kStates> out{};
    double path[kNumPath];
    setup_->model->Evaluate(state.data(), u.data(), out.data(), path);
    return out;
  };
  double t = 0;
  const double t_end = r.time_at.back();
  while (t < t_end - 1e-12) {
    const double h = std::min(dt, t_end - t);
    auto add = [](std::array<double, kStates> a, const std::array<double, kStates>& b, double w) {
      for (int i = 0; i < kStates; ++i) a[i] += w * b[i];
      return a;
    };
    const auto k1 = rate(t, x);
    const auto k2 = rate(t + h / 2, add(x, k1, h / 2));
    const auto k3 = rate(t + h / 2, add(x, k2, h / 2));
    const auto k4 = rate(t + h, add(x, k3, h));
    for (int i = 0; i < kStates; ++i) x[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    t += h;
  }
  const auto& end = r.state.back();
  EXPECT_NEAR(x[kS], end[kS], 0.10);
  EXPECT_NEAR(x[kQ], end[kQ], 0.05);
  EXPECT_NEAR(x[kQ + 1], end[kQ + 1], 0.05);
  EXPECT_NEAR(x[kVolume], end[kVolume], 0.1 * end[kVolume]);
  EXPECT_NEAR(x[kEnergy], end[kEnergy], 0.1 * end[kEnergy]);
}

TEST_F(ScoopOcpSolve, WarmStartConvergesToTheSameOptimumFaster) {
  ASSERT_TRUE(first_->ok) << first_->status;
  const ScoopOcpSolution again = ocp_->Solve(setup_->start);
  ASSERT_TRUE(again.ok) << again.status;
  EXPECT_TRUE(again.warm_started);
  EXPECT_NEAR(again.energy, first_->energy, 0.01 * first_->energy);
  EXPECT_LT(again.iterations, first_->iterations);
}

TEST_F(ScoopOcpSolve, MinimumTimeAtTheOptimumsEnergyIsNoSlower) {
  ASSERT_TRUE(first_->ok) << first_->status;
  ScoopOcpOptions options = options_;
  options.objective = ScoopObjective::kMinimumTime;
  options.max_energy = 1.2 * first_->energy;
  ScoopOcp fastest(*setup_->model, options);
  const ScoopOcpSolution r = fastest.Solve(setup_->start);
  ASSERT_TRUE(r.ok) << r.status;
  EXPECT_LE(r.energy, options.max_energy + 1.0);
  EXPECT_LE(r.time, first_->time + 1e-3);
  EXPECT_GE(r.volume, options.target_volume - 1e-6);
}

}  // namespace
}  // namespace autoshovel::optimal
