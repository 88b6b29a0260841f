#include "runtime/planning/shovel_weights_file.h"

#include "runtime/core/diagnostics.h"
#include "runtime/core/yaml_reader.h"

namespace autoshovel::planning {

void ReadShovelWeights(const std::string& path, ShovelPointConfig& config) {
  core::DiagnosticSink sink;
  const core::YamlFile file(path, sink);
  if (file.ok()) {
    core::MapReader root = core::MapReader::Root(file, nullptr);
    const core::NumberRule rule = core::NumberRule::NonNegative("");
    const double k_t = root.Number("k_t", rule), k_s = root.Number("k_s", rule);
    const double k_c = root.Number("k_c", rule), k_e = root.Number("k_e", rule);
    const double k_a = root.Number("k_a", rule);
    root.Finish();
    if (sink.empty() && !(k_t + k_s + k_c + k_e + k_a > 0)) {
      root.Error("k_t", "all five weights are zero: Eq. (18) would rank nothing");
    }
    if (sink.empty()) {
      config.k_t = k_t, config.k_s = k_s, config.k_c = k_c, config.k_e = k_e, config.k_a = k_a;
    }
  }
  sink.ThrowIfAny();
}

}  // namespace autoshovel::planning
