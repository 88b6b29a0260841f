// Shared by the generated-code tests: each generated machine with its description and the
// interpreted reference model.
#pragma once

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "generated/registry.h"
#include "runtime/model/description.h"
#include "runtime/model/interpreted_model.h"

namespace autoshovel::testing {

struct MachineUnderTest {
  const generated::MachineFunctions* generated = nullptr;
  std::unique_ptr<model::MachineDescription> description;
  std::unique_ptr<model::InterpretedModel> interpreted;
};

inline std::vector<MachineUnderTest> LoadGeneratedMachines() {
  std::vector<MachineUnderTest> machines;
  for (const generated::MachineFunctions* functions : generated::AllMachines()) {
    MachineUnderTest m;
    m.generated = functions;
    m.description = std::make_unique<model::MachineDescription>(model::LoadMachineDescription(
        std::string(AUTOSHOVEL_SOURCE_DIR) + "/" + functions->source_file));
    m.interpreted = std::make_unique<model::InterpretedModel>(*m.description);
    machines.push_back(std::move(m));
  }
  return machines;
}

/// Random joint positions inside the limits (swing included).
inline std::vector<double> RandomJoints(const generated::MachineFunctions& g,
                                        std::mt19937_64& rng) {
  std::vector<double> q(g.num_joints);
  for (int j = 0; j < g.num_joints; ++j) {
    q[j] = std::uniform_real_distribution<double>(g.joint_min[j], g.joint_max[j])(rng);
  }
  return q;
}

/// Maximum of |a − b| over entries, relative to max(1, max |b|).
inline double RelativeError(const std::vector<double>& a, const std::vector<double>& b) {
  double scale = 1.0, error = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    scale = std::max(scale, std::abs(b[i]));
    error = std::max(error, std::abs(a[i] - b[i]));
  }
  return error / scale;
}

}  // namespace autoshovel::testing
