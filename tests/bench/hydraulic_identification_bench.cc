// Hydraulic identification on long logs: `build/hydraulic_identification_bench`.
// Fits synthetic cycle logs (steps into the end stops, a segment between contacts every few
// cycles; tests/hydraulics/synthetic_cycle_log.h) of 20k and 100k rows; the counter `rows/s`
// should stay about the same from one length to the other: the fit is linear in the log.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "generated/registry.h"
#include "identification/hydraulics/hydraulic_identification.h"
#include "tests/hydraulics/synthetic_cycle_log.h"

namespace {

using namespace autoshovel;
using namespace autoshovel::identification;

void BM_IdentifyCycleLog(benchmark::State& state) {
  const model::MachineDescription machine =
      model::LoadMachineDescription(model::ResolveMachineDescription(
          "xcmg_968ev", std::string(AUTOSHOVEL_SOURCE_DIR) + "/models"));
  const generated::MachineFunctions& functions = *generated::FindMachine(machine.name);
  const int actuator = FindActuator(machine, "boom");
  const ActuatorKinematics kinematics(machine, functions, actuator);
  const ValveParameters truth{0.065, 0.42, 0.08, 400e-3 / 60};
  const auto rows = static_cast<std::size_t>(state.range(0));
  const std::vector<HydraulicLog> logs = {testing::SyntheticCycleLog(kinematics, truth, rows)};
  HydraulicIdentificationOptions options;
  options.cross_validate = false;
  std::size_t blocks = 0;
  for (auto _ : state) {
    const ActuatorIdentification r = IdentifyActuator(machine, functions, actuator, logs, options);
    blocks = r.residual_blocks;
    benchmark::DoNotOptimize(r.params.transport_delay);
  }
  state.counters["rows/s"] = benchmark::Counter(static_cast<double>(rows) * state.iterations(),
                                                benchmark::Counter::kIsRate);
  state.counters["blocks"] = static_cast<double>(blocks);
}
BENCHMARK(BM_IdentifyCycleLog)
    ->Arg(20000)
    ->Arg(100000)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
