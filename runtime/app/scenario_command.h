// `autoshovel scenario NAME`: load a yard scenario, print what it holds, draw its top view.
#pragma once

#include <iosfwd>
#include <string>

namespace autoshovel::app {

struct ScenarioOptions {
  std::string scenario;  ///< name (models/scenarios/<name>.yaml) or path
  std::string models_dir;
  std::string png;                ///< top view to write; empty: none
  double metres_per_pixel = 0.1;  ///< of the top view
};

/// Returns a process exit code (diagnostics on `err`).
int RunScenario(const ScenarioOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app
