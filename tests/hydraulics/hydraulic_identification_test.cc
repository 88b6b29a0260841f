// Hydraulic delay identification against plant logs with a known truth (wheel-loader seed §7.4:
// ~0.6 s from command to motion, transport delay plus spool lag).
#include "identification/hydraulics/hydraulic_identification.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "generated/registry.h"
#include "identification/hydraulics/plant_logs.h"
#include "tests/hydraulics/synthetic_cycle_log.h"

namespace autoshovel::identification {
namespace {

constexpr double kLpm = 1e-3 / 60;

model::MachineDescription Loader() {
  return model::LoadMachineDescription(model::ResolveMachineDescription(
      "xcmg_968ev", std::string(AUTOSHOVEL_SOURCE_DIR) + "/models"));
}

const generated::MachineFunctions& Functions(const model::MachineDescription& machine) {
  const generated::MachineFunctions* f = generated::FindMachine(machine.name);
  if (f == nullptr) throw std::runtime_error("no generated code for " + machine.name);
  return *f;
}

// The truth: dead zone and transport delay moved away from the description (the plant reads
// them at run time); τ_s = 80 ms and 400 l/min are compiled into the generated plant.
struct Truth {
  double dead_zone = 0.065, transport_delay = 0.42, spool_time_constant = 0.08,
         rated_flow = 400 * kLpm;
};

model::MachineDescription TrueMachine(int actuator) {
  model::MachineDescription machine = Loader();
  machine.hydraulics.actuators[actuator].valve.dead_zone = Truth{}.dead_zone;
  machine.hydraulics.actuators[actuator].valve.transport_delay = Truth{}.transport_delay;
  return machine;
}

std::string Sidecar(const std::string& log) {
  std::filesystem::path path(log);
  return (path.parent_path() / (path.stem().string() + ".columns.yaml")).string();
}

// The `--simulate` campaign of the boom: six steps (plant-step CSV, SI) and a chirp (data-logger
// CSV: ';', ms, %, deg, bar, other column order, two banner lines and a units row), read back
// from the files, fitted jointly once for the tests below.
class BoomCampaign : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const model::MachineDescription loader = Loader();
    actuator_ = FindActuator(loader, "boom");
    machine_ = new model::MachineDescription(TrueMachine(actuator_));
    const std::string dir =
        ::testing::TempDir() + "/hydraulics_boom_campaign_" + std::to_string(getpid());
    std::filesystem::remove_all(dir);
    logs_ = new std::vector<HydraulicLog>();
    for (const std::string& path :
         WriteSimulatedCampaign(*machine_, Functions(*machine_), actuator_, dir, 11)) {
      const std::string sidecar = Sidecar(path);
      logs_->push_back(ReadHydraulicLog(
          path, std::filesystem::exists(sidecar) ? ReadLogFormatYaml(sidecar) : LogFormat{}));
    }
    with_spool_ = new ActuatorIdentification(
        IdentifyActuator(*machine_, Functions(*machine_), actuator_, *logs_));
    std::vector<HydraulicLog> angle_only = *logs_;
    for (HydraulicLog& log : angle_only) log.spool.clear();
    angle_only_ = new ActuatorIdentification(
        IdentifyActuator(*machine_, Functions(*machine_), actuator_, angle_only));
  }
  static void TearDownTestSuite() {
    delete with_spool_;
    delete angle_only_;
    delete logs_;
    delete machine_;
  }
  static int actuator_;
  static model::MachineDescription* machine_;
  static std::vector<HydraulicLog>* logs_;
  static ActuatorIdentification* with_spool_;
  static ActuatorIdentification* angle_only_;
};
int BoomCampaign::actuator_ = -1;
model::MachineDescription* BoomCampaign::machine_ = nullptr;
std::vector<HydraulicLog>* BoomCampaign::logs_ = nullptr;
ActuatorIdentification* BoomCampaign::with_spool_ = nullptr;
ActuatorIdentification* BoomCampaign::angle_only_ = nullptr;

void Print(const ActuatorIdentification& r) {
  std::printf(
      "d %.4f +- %.4f | td %.4f +- %.4f | ts %.4f +- %.4f | Q %.1f +- %.1f l/min | "
      "lag %.4f | angle sigma %.3f deg | %d it, %.2f s\n",
      r.params.dead_zone, r.std_dev.dead_zone, r.params.transport_delay, r.std_dev.transport_delay,
      r.params.spool_time_constant, r.std_dev.spool_time_constant, r.params.rated_flow / kLpm,
      r.std_dev.rated_flow / kLpm, r.motion_lag, r.angle_sigma * 180 / std::numbers::pi,
      r.iterations, r.seconds);
  for (const auto& f : r.cross_validation) {
    std::printf("  held out %.0f %%: angle RMS %.3f deg of %.1f deg, spool RMS %.4f\n",
                f.level * 100, f.angle_rms * 180 / std::numbers::pi,
                f.angle_range * 180 / std::numbers::pi, f.spool_rms);
  }
}

TEST_F(BoomCampaign, FilesInDifferentFormatsReadToTheSameUnits) {
  ASSERT_EQ(logs_->size(), 7u);
  const HydraulicLog& chirp = logs_->back();  // the data-logger file
  EXPECT_EQ(chirp.actuator, "boom_cylinders");
  EXPECT_EQ(chirp.row.front(), 5);  // two banner lines, names, units
  EXPECT_NEAR(chirp.time[1] - chirp.time[0], 0.01, 1e-9);
  double largest = 0;
  for (double u : chirp.command) largest = std::max(largest, std::abs(u));
  EXPECT_NEAR(largest, 0.6, 0.01);
  EXPECT_NEAR(chirp.joint_angle.front(), logs_->front().joint_angle.front(), 0.01);
  EXPECT_GT(chirp.pressure_a.front(), 1e6);  // bar read as Pa
}

TEST_F(BoomCampaign, SpoolFeedbackPinsDelayTimeConstantAndDeadZone) {
  const ActuatorIdentification& r = *with_spool_;
  Print(r);
  const Truth truth;
  EXPECT_NEAR(r.params.transport_delay, truth.transport_delay, 0.010);
  EXPECT_NEAR(r.params.spool_time_constant, truth.spool_time_constant,
              0.05 * truth.spool_time_constant);
  EXPECT_NEAR(r.params.dead_zone, truth.dead_zone, 0.01);
  // The plant's compensators hold the drop within a 2 bar band around the 15 bar margin, so
  // its effective flow runs a few % above the rated one.
  EXPECT_NEAR(r.params.rated_flow, truth.rated_flow, 0.06 * truth.rated_flow);
  // Intervals: the truth within 3σ, at a width that still says something.
  EXPECT_LT(std::abs(r.params.transport_delay - truth.transport_delay),
            3 * r.std_dev.transport_delay + 1e-4);
  EXPECT_LT(std::abs(r.params.spool_time_constant - truth.spool_time_constant),
            3 * r.std_dev.spool_time_constant);
  EXPECT_LT(std::abs(r.params.dead_zone - truth.dead_zone), 3 * r.std_dev.dead_zone);
  EXPECT_LT(r.std_dev.transport_delay, 0.005);
  EXPECT_LT(r.std_dev.spool_time_constant, 0.02 * truth.spool_time_constant);
  EXPECT_LT(r.std_dev.dead_zone, 0.005);
  EXPECT_GT(r.std_dev.dead_zone, 0.0);
  EXPECT_FALSE(r.at_bound[0] || r.at_bound[1] || r.at_bound[2] || r.at_bound[3]);
  EXPECT_NEAR(r.spool_sigma, 0.005, 0.001);  // the logger's noise, nothing more
}

TEST_F(BoomCampaign, CrossValidationPredictsHeldOutDutyLevels) {
  const ActuatorIdentification& r = *with_spool_;
  ASSERT_EQ(r.cross_validation.size(), 3u);  // 30, 60 (steps and chirp), 100 %
  for (const CrossValidationFold& fold : r.cross_validation) {
    EXPECT_LT(fold.angle_rms, 0.25 * std::numbers::pi / 180) << fold.level;
    EXPECT_LT(fold.angle_rms, 0.02 * fold.angle_range) << fold.level;
    EXPECT_LT(fold.spool_rms, 0.008) << fold.level;
    EXPECT_NEAR(fold.params.transport_delay, Truth{}.transport_delay, 0.010);
  }
}

TEST_F(BoomCampaign, AngleOnlyLogsStillGiveTheDelay) {
  const ActuatorIdentification& r = *angle_only_;
  Print(r);
  const Truth truth;
  EXPECT_FALSE(r.has_spool);
  EXPECT_EQ(r.motion_lag, 0.0);
  EXPECT_NEAR(r.params.transport_delay, truth.transport_delay, 0.010);
  EXPECT_NEAR(r.params.dead_zone, truth.dead_zone, 0.01);
  // Without the spool, the joint's own few-ms lag behind it goes into τ_s (documented).
  EXPECT_NEAR(r.params.spool_time_constant, truth.spool_time_constant,
              0.10 * truth.spool_time_constant);
  EXPECT_NEAR(r.params.rated_flow, truth.rated_flow, 0.06 * truth.rated_flow);
  EXPECT_LT(std::abs(r.params.transport_delay - truth.transport_delay),
            3 * r.std_dev.transport_delay);
  EXPECT_LT(std::abs(r.params.spool_time_constant - truth.spool_time_constant),
            3 * r.std_dev.spool_time_constant);
  EXPECT_LT(std::abs(r.params.dead_zone - truth.dead_zone), 3 * r.std_dev.dead_zone);
}

// A boom driven into its upper end stop and back: the samples held by the stop are left out,
// and the fit is as good as without them.
TEST(HydraulicIdentification, EndStopSamplesAreLeftOut) {
  const model::MachineDescription loader = Loader();
  const int actuator = FindActuator(loader, "boom");
  const model::MachineDescription machine = TrueMachine(actuator);
  const auto& functions = Functions(machine);
  PlantLogOptions options;
  options.seed = 5;
  std::vector<HydraulicLog> logs;
  for (double level : {0.4, -0.4, 0.8, -0.8}) {
    ++options.seed;
    logs.push_back(
        SimulatePlantLog(machine, functions, actuator, StepCommand(level, 0.3, 1.5), 2.2, options));
  }
  options.start_fraction = 0.9;
  ++options.seed;
  logs.push_back(SimulatePlantLog(
      machine, functions, actuator,
      [](double t) { return t < 0.3   ? 0.0
                            : t < 2.8 ? 1.0
                            : t < 4.0 ? -0.5
                                      : 0.0; }, 4.6, options));
  for (std::size_t i = 0; i < logs.size(); ++i) logs[i].file = "log" + std::to_string(i);
  HydraulicIdentificationOptions fit;
  fit.cross_validate = false;
  const ActuatorIdentification r = IdentifyActuator(machine, functions, actuator, logs, fit);
  Print(r);
  EXPECT_GT(r.excluded, 20u);
  EXPECT_EQ(r.excluded,
            r.files.back().excluded.size() -
                std::count(r.files.back().excluded.begin(), r.files.back().excluded.end(), 0));
  EXPECT_NEAR(r.params.transport_delay, Truth{}.transport_delay, 0.010);
  EXPECT_NEAR(r.params.spool_time_constant, 0.08, 0.004);
  EXPECT_NEAR(r.params.dead_zone, Truth{}.dead_zone, 0.01);
  EXPECT_LT(r.files.back().angle_rms, 0.2 * std::numbers::pi / 180);

  fit.exclude_end_stops = false;
  const ActuatorIdentification blind = IdentifyActuator(machine, functions, actuator, logs, fit);
  Print(blind);
  EXPECT_EQ(blind.excluded, 0u);
  EXPECT_GT(blind.files.back().angle_rms, 3 * r.files.back().angle_rms);
}

// A long log of steps into the end stops has a segment between each pair of contacts, each
// with its own start angle. The fit must keep every residual block on a bounded number of
// parameters (θ, τ_m and one start angle): one block over the whole file would depend on all
// the start angles, its Jacobian rows × segments, and the fit superlinear in the log (out of
// memory at a million rows). The model-made log is noise apart the model: the truth comes back.
TEST(HydraulicIdentification, ManyEndStopSegmentsKeepBlocksSmall) {
  const model::MachineDescription machine = Loader();
  const int actuator = FindActuator(machine, "boom");
  const auto& functions = Functions(machine);
  const ActuatorKinematics kinematics(machine, functions, actuator);
  const Truth truth;
  const ValveParameters valve{truth.dead_zone, truth.transport_delay, truth.spool_time_constant,
                              truth.rated_flow};
  const std::size_t rows = 12000;  // 120 s, 15 cycles
  const std::vector<HydraulicLog> logs = {testing::SyntheticCycleLog(kinematics, valve, rows)};
  HydraulicIdentificationOptions options;
  options.cross_validate = false;
  const ActuatorIdentification r = IdentifyActuator(machine, functions, actuator, logs, options);
  Print(r);
  // Segments: runs of samples off the stops.
  const std::vector<char>& excluded = r.files.front().excluded;
  std::size_t segments = 0;
  for (std::size_t j = 0; j < excluded.size(); ++j) {
    segments += !excluded[j] && (j == 0 || excluded[j - 1]);
  }
  EXPECT_GE(segments, 10u);
  EXPECT_GT(r.excluded, rows / 10);
  EXPECT_LE(r.largest_block_parameters, 4 + 1 + 1);  // θ, τ_m, one start angle
  const std::size_t spool_blocks = r.residual_blocks - segments;
  EXPECT_GE(spool_blocks, 1u);
  EXPECT_LE(spool_blocks, rows / 1000);  // chunks of thousands of rows, not one per row
  EXPECT_NEAR(r.params.transport_delay, truth.transport_delay, 0.002);
  EXPECT_NEAR(r.params.spool_time_constant, truth.spool_time_constant,
              0.02 * truth.spool_time_constant);
  EXPECT_NEAR(r.params.dead_zone, truth.dead_zone, 0.003);
  EXPECT_NEAR(r.params.rated_flow, truth.rated_flow, 0.01 * truth.rated_flow);
  EXPECT_LT(r.files.front().angle_rms, 0.1 * std::numbers::pi / 180);
}

// The tabulated inverse kinematics the fit uses at every row against the generated inverse
// (a Newton iteration), over the boom's whole range, between the table's nodes too.
TEST(ValveModel, TabulatedInverseMatchesTheGeneratedOne) {
  const model::MachineDescription machine = Loader();
  const auto& functions = Functions(machine);
  for (const char* name : {"boom", "bucket"}) {
    const ActuatorKinematics kinematics(machine, functions, FindActuator(machine, name));
    const int joint = kinematics.joint();
    const double low = kinematics.Length(functions.joint_min[joint]);
    const double high = kinematics.Length(functions.joint_max[joint]);
    for (int i = 1; i < 997; ++i) {
      const double length = low + (high - low) * i / 997.0;
      double slope = 0;
      const double q = kinematics.Angle(length, &slope);
      EXPECT_NEAR(q, kinematics.ExactAngle(length), 1e-9) << name << " " << length;
      EXPECT_NEAR(slope * kinematics.Lever(q), 1.0, 1e-6) << name << " " << length;
    }
  }
}

// The closed-form spool response against a fine explicit integration of τ_s ẋ = r − x, and
// its derivative in τ_d (through Jets) against central differences: the cost is smooth in τ_d.
TEST(ValveModel, ClosedFormMatchesIntegrationAndIsSmoothInTheDelay) {
  std::vector<double> time, command;
  for (int i = 0; i <= 150; ++i) {
    time.push_back(0.01 * i + (i % 3) * 1e-3);  // irregular sampling
    command.push_back(i < 20 ? 0.0 : i < 60 ? 0.7 : i < 90 ? -0.4 : 0.05 * std::sin(i));
  }
  const double d = 0.08, delay = 0.123, tau = 0.06;
  const ValveResponse<double> r = SimulateValve(time, command, d, delay, tau);
  // Explicit reference, 1 µs steps.
  double x = 0, pos = 0, neg = 0, t = time[0];
  std::size_t k = 0;
  for (std::size_t j = 0; j < time.size(); ++j) {
    while (t < time[j] - 1e-12) {
      const double h = std::min(1e-6, time[j] - t);
      std::size_t in_force = 0;
      while (in_force + 1 < time.size() && time[in_force + 1] + delay <= t) ++in_force;
      const double ref = DeadZone(command[in_force], d);
      x += h * (ref - x) / tau;
      (x > 0 ? pos : neg) += h * x;
      t += h;
    }
    EXPECT_NEAR(r.spool[j], x, 2e-4) << j;
    EXPECT_NEAR(r.positive[j], pos, 2e-5) << j;
    EXPECT_NEAR(r.negative[j], neg, 2e-5) << j;
    ++k;
  }
  using Jet = ceres::Jet<double, 1>;
  const ValveResponse<Jet> jets = SimulateValve(time, command, Jet(d), Jet(delay, 0), Jet(tau));
  const double h = 1e-6;
  const ValveResponse<double> plus = SimulateValve(time, command, d, delay + h, tau);
  const ValveResponse<double> minus = SimulateValve(time, command, d, delay - h, tau);
  for (std::size_t j = 0; j < time.size(); ++j) {
    const double numeric = (plus.positive[j] - minus.positive[j]) / (2 * h);
    EXPECT_NEAR(jets.positive[j].v[0], numeric, 1e-5) << j;
    const double numeric_neg = (plus.negative[j] - minus.negative[j]) / (2 * h);
    EXPECT_NEAR(jets.negative[j].v[0], numeric_neg, 1e-5) << j;
  }
}

}  // namespace
}  // namespace autoshovel::identification
