// Arm calibration (wheel-loader seed §3.1, §7.1) on data with a known truth: poses of the
// simulated arm, IMU angles by Eq. (1) with 0.1° noise, tip displacements with 5 mm noise.
#include "identification/calibration/arm_calibration.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "generated/registry.h"
#include "runtime/model/description.h"
#include "runtime/model/interpreted_model.h"

namespace autoshovel::identification {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Truth {
  model::MachineDescription machine;
  const generated::MachineFunctions* functions = nullptr;
  std::vector<double> params;  // the true l, α
};

Truth LoadTruth(const std::string& name) {
  Truth t;
  const std::string models = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
  t.machine = model::LoadMachineDescription(model::ResolveMachineDescription(name, models));
  t.functions = generated::FindMachine(name);
  t.params.assign(t.functions->nominal_params,
                  t.functions->nominal_params + t.functions->num_params);
  return t;
}

// `poses` joint configurations spread over the joint ranges the way a calibration plan spreads
// them (§7.1: seven poses; boom and bucket at opposite ends of their ranges in turn, with a few
// degrees of jitter), measured the way the seed does: IMU pitch angles with noise, the tip's
// displacement with a rangefinder.
ArmCalibrationData Simulate(const Truth& t, int poses, double imu_noise, double range_noise,
                            std::uint64_t seed) {
  const model::InterpretedModel reference(t.machine);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> jitter(-0.04, 0.04);
  const double boom_plan[] = {0.05, 0.95, 0.5, 0.2, 0.8, 0.35, 0.65};
  const double bucket_plan[] = {0.9, 0.1, 0.5, 0.15, 0.85, 0.7, 0.3};
  ArmCalibrationData data;
  std::vector<Eigen::Vector4d> tips;
  for (int i = 0; i < poses; ++i) {
    std::vector<double> q(t.machine.num_joints(), 0.0);
    for (std::size_t j = 0; j < t.machine.num_links(); ++j) {
      const auto& link = t.machine.links[j];
      const double plan = (j == 0 ? boom_plan : bucket_plan)[i % 7] + jitter(rng);
      q[j] = link.joint_min + std::clamp(plan, 0.02, 0.98) * (link.joint_max - link.joint_min);
    }
    std::vector<double> angles = reference.AnglesFromJoints(q.data(), t.params.data());
    const double cab_pitch = 2 * kDeg * gauss(rng);  // the machine stands on uneven ground
    for (double& a : angles) a += cab_pitch;
    tips.push_back(reference.TipFromJoints(q.data()));
    for (std::size_t k = 0; k <= t.machine.num_links(); ++k) {
      angles[k] += imu_noise * gauss(rng);
    }
    data.angles.push_back(angles);
  }
  for (int i = 0; i + 1 < poses; ++i) {
    const Eigen::Vector4d d = tips[i] - tips[i + 1];
    data.displacements.emplace_back(d.x() + range_noise * gauss(rng),
                                    d.z() + range_noise * gauss(rng));
  }
  return data;
}

// §7.1: seven poses, 0.1° IMU noise, 5 mm rangefinder noise; lengths within 1 %, offsets within
// 0.5°, from any initial values inside the bounds.
TEST(ArmCalibration, RecoversLengthsAndOffsetsFromAnyStart) {
  for (const std::string name : {"xcmg_968ev", "sdlg_l955he"}) {
    const Truth t = LoadTruth(name);
    const int n = t.functions->num_links;
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> length(0.2, 8.0), offset(-3.0, 3.0);
    for (int trial = 0; trial < 30; ++trial) {
      const ArmCalibrationData data = Simulate(t, 7, 0.1 * kDeg, 0.005, 100 + trial);
      std::vector<double> initial(t.functions->num_params);
      for (int k = 0; k < n; ++k) initial[k] = length(rng), initial[n + k] = offset(rng);
      const ArmCalibrationResult r = CalibrateArm(*t.functions, data, initial);
      ASSERT_TRUE(r.ok) << name << " trial " << trial << ": " << r.degenerate;
      EXPECT_LE(r.gradient_max_norm, 1e-10) << name << " trial " << trial;
      for (int k = 0; k < n; ++k) {
        EXPECT_NEAR(r.params[k], t.params[k], 0.01 * t.params[k]) << name << " l" << k + 1;
        EXPECT_NEAR(r.params[n + k], t.params[n + k], 0.5 * kDeg) << name << " alpha" << k + 1;
      }
    }
  }
}

TEST(ArmCalibration, NoiseFreeDataGiveTheTruthExactly) {
  const Truth t = LoadTruth("xcmg_968ev");
  const ArmCalibrationResult r =
      CalibrateArm(*t.functions, Simulate(t, 7, 0.0, 0.0, 7), {1.0, 1.0, 0.5, -0.5});
  ASSERT_TRUE(r.ok) << r.degenerate;
  for (int k = 0; k < t.functions->num_params; ++k) EXPECT_NEAR(r.params[k], t.params[k], 1e-8);
  EXPECT_LT(r.cost, 1e-20);
}

TEST(ArmCalibration, DegenerateDataAreReportedNotAnswered) {
  const Truth t = LoadTruth("xcmg_968ev");
  // Two poses only.
  ArmCalibrationData two = Simulate(t, 2, 0.0, 0.0, 3);
  const ArmCalibrationResult few = CalibrateArm(*t.functions, two);
  EXPECT_FALSE(few.ok);
  EXPECT_NE(few.degenerate.find("at least 3"), std::string::npos) << few.degenerate;
  EXPECT_TRUE(few.params.empty());
  // Seven poses in which only the boom moves, the bucket IMU reading the same relative angle:
  // the bucket link's length and offset are not separable from the boom's.
  ArmCalibrationData collinear = Simulate(t, 7, 0.0, 0.0, 5);
  for (auto& angles : collinear.angles) angles[2] = angles[1] + 0.3;
  const ArmCalibrationResult flat = CalibrateArm(*t.functions, collinear);
  EXPECT_FALSE(flat.ok);
  EXPECT_NE(flat.degenerate.find("condition number"), std::string::npos) << flat.degenerate;
  EXPECT_TRUE(flat.params.empty());
  // Malformed input is an error, not a result.
  ArmCalibrationData bad = Simulate(t, 5, 0.0, 0.0, 9);
  bad.displacements[1].x() = std::nan("");
  EXPECT_THROW(CalibrateArm(*t.functions, bad), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::identification
