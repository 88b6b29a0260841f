// The energy audit (runtime/plant/energy_audit.h): its terms add up to the energy drawn, it
// leaves the trajectory alone, and the terms that have an independent measure agree with it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "runtime/model/interpreted_model.h"
#include "runtime/plant/plant.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::plant {
namespace {

struct AuditRun {
  EnergyAudit audit;
  Energy energy;
  std::map<std::string, EnergyAudit> phases;
  std::vector<double> state_bytes;
  std::size_t trace_samples = 0;
};

// Drives into a gravel cone while raising the boom and curling, then backs out: every travel and
// hydraulic term has something to do (slip and soil in the cone, meter-out on the way down).
AuditRun DigScript(const std::string& name, bool audit) {
  const model::MachineDescription machine = testing::LoadMachine(name);
  World world = testing::FlatYard(machine, 24.0);
  testing::AddCone(world, {6.0, 0.0}, 3.0, "small_gravel");
  MachineState start;
  if (machine.kind == model::MachineKind::kWheelLoader) {
    start = testing::LoaderAt(machine, -1.0);
  } else {
    start.q.assign(machine.num_joints(), 0.0);
    for (std::size_t j = 0; j < machine.num_links(); ++j) {
      start.q[j] = 0.5 * (machine.links[j].joint_min + machine.links[j].joint_max);
    }
  }
  PlantOptions options;
  options.energy_audit = audit;
  Plant plant(machine, testing::Functions(name), world, start, options);
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  AuditRun run;
  while (plant.time() < 9.0 - 1e-9) {
    const double t = plant.time();
    plant.SetPhase(t < 3.0 ? "approach" : (t < 6.5 ? "scoop" : "retreat"));
    command.drive = t < 3.0 ? 0.6 : (t < 6.0 ? 0.3 : -0.4);
    for (std::size_t a = 0; a < command.valve.size(); ++a) {
      const double sign = a % 2 == 0 ? 1.0 : -1.0;
      command.valve[a] = (t > 3.0 && t < 6.0) ? 0.8 : (t > 7.0 ? -0.5 * sign : 0.0);
    }
    EXPECT_TRUE(plant.SetCommand(command));
    plant.Advance(0.01);
    const MachineState& s = plant.state();
    for (const auto* v : {&s.q, &s.qd, &s.spool, &s.pressure_a, &s.pressure_b}) {
      run.state_bytes.insert(run.state_bytes.end(), v->begin(), v->end());
    }
    run.state_bytes.insert(run.state_bytes.end(), {s.hinge_xy.x(), s.speed, s.payload_volume});
  }
  run.audit = plant.energy_audit();
  run.energy = plant.energy();
  run.phases = plant.phase_energy_audit();
  run.trace_samples = plant.energy_audit_trace().size();
  return run;
}

TEST(EnergyAudit, TermsAddUpToTheEnergyDrawn) {
  for (const std::string name : {"xcmg_968ev", "sdlg_l955he"}) {
    const AuditRun run = DigScript(name, true);
    ASSERT_GT(run.energy.hydraulic, 50e3) << name;
    ASSERT_GT(run.energy.travel, 50e3) << name;
    EXPECT_NEAR(run.audit.hydraulic(), run.energy.hydraulic, 0.01 * run.energy.hydraulic) << name;
    EXPECT_NEAR(run.audit.travel(), run.energy.travel, 0.01 * run.energy.travel) << name;
    // The script exercises the terms a scoop is made of.
    EXPECT_GT(run.audit[EnergyTerm::kTyreSlip], 1e3) << name;
    // Cutting: the drive and the arm together (either alone may be negative: a curl moving the
    // tip back while the machine pushes on lets the soil push the chassis).
    EXPECT_GT(run.audit.soil(), 1e3) << name;

    EXPECT_GT(run.audit[EnergyTerm::kLifting], 10e3) << name;
    EXPECT_GT(run.audit[EnergyTerm::kMeterIn], 1e3) << name;
    EXPECT_GT(run.audit[EnergyTerm::kPumpLoss], 1e3) << name;
    // Dissipations are never negative.
    for (EnergyTerm t : {EnergyTerm::kTravelDriveLoss, EnergyTerm::kTravelNotRecovered,
                         EnergyTerm::kTyreSlip, EnergyTerm::kRolling, EnergyTerm::kPumpLoss,
                         EnergyTerm::kMeterIn, EnergyTerm::kMeterOut, EnergyTerm::kArmFriction}) {
      EXPECT_GE(run.audit[t], -1.0) << name << " " << EnergyTermName(t);
    }
    // The phases partition the run.
    EnergyAudit sum;
    for (const auto& [phase, audit] : run.phases) sum += audit;
    for (int k = 0; k < kEnergyTermCount; ++k) {
      EXPECT_NEAR(sum.terms[k], run.audit.terms[k], 1e-6 * std::abs(run.audit.terms[k]) + 1e-6);
    }
    EXPECT_EQ(run.phases.size(), 3u);
    EXPECT_EQ(run.trace_samples, 900u);
  }
}

TEST(EnergyAudit, LeavesTheTrajectoryUnchanged) {
  const AuditRun with = DigScript("xcmg_968ev", true);
  const AuditRun without = DigScript("xcmg_968ev", false);
  ASSERT_EQ(with.state_bytes.size(), without.state_bytes.size());
  EXPECT_EQ(0, std::memcmp(with.state_bytes.data(), without.state_bytes.data(),
                           with.state_bytes.size() * sizeof(double)));
  EXPECT_EQ(with.energy.hydraulic, without.energy.hydraulic);
  EXPECT_TRUE(without.phases.empty());
}

TEST(EnergyAudit, ExcavatorSwingAndArmAddUp) {
  const AuditRun run = DigScript("excavator_25t", true);
  ASSERT_GT(run.energy.hydraulic, 20e3);
  EXPECT_NEAR(run.audit.hydraulic(), run.energy.hydraulic, 0.01 * run.energy.hydraulic);
  EXPECT_EQ(run.audit.travel(), 0.0);
}

// A boom lift in the open from rest to rest: the lifting term is the rise of the arm's potential
// energy, measured independently from the bodies' heights (InterpretedModel::MechanicalEnergy),
// and nothing goes into the soil or the travel drive.
TEST(EnergyAudit, LiftingEqualsThePotentialEnergyGained) {
  const model::MachineDescription machine = testing::LoadMachine("xcmg_968ev");
  World world = testing::FlatYard(machine, 24.0);
  PlantOptions options;
  options.energy_audit = true;
  Plant plant(machine, testing::Functions("xcmg_968ev"), world, testing::LoaderAt(machine, 0.0),
              options);
  const model::InterpretedModel reference(machine);
  const auto before =
      reference.MechanicalEnergy(plant.state().q.data(), plant.state().qd.data(), 0.0, 0.0);
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  command.brake = 1.0;
  while (plant.time() < 6.0 - 1e-9) {
    command.valve[0] = plant.time() < 3.0 ? 0.6 : 0.0;
    ASSERT_TRUE(plant.SetCommand(command));
    plant.Advance(0.01);
  }
  const auto after =
      reference.MechanicalEnergy(plant.state().q.data(), plant.state().qd.data(), 0.0, 0.0);
  const EnergyAudit& audit = plant.energy_audit();
  const double gained = after[1] - before[1];
  ASSERT_GT(gained, 20e3);  // the boom rose
  EXPECT_NEAR(audit[EnergyTerm::kLifting], gained, 0.01 * gained);
  EXPECT_NEAR(audit[EnergyTerm::kArmKinetic], after[0] - before[0], 0.01 * gained);
  EXPECT_EQ(audit[EnergyTerm::kSoilByArm], 0.0);
  EXPECT_NEAR(audit.travel(), 0.0, 1.0);
  // Lifting takes most of what the cylinders did; the pump drew more than that.
  EXPECT_GT(audit[EnergyTerm::kLifting], 0.8 * audit.cylinder_work());
  EXPECT_GT(plant.energy().hydraulic, audit.cylinder_work());
}

}  // namespace
}  // namespace autoshovel::plant
