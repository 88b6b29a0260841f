// RunSelect from the command line (the lead wires `autoshovel select` into the CLI later):
//   build/planning_demo SCENARIO PNG [--truth-map] [--truth-labels] [--pile N] [--advance M]
#include <cstdlib>
#include <iostream>
#include <string>

#include "runtime/sim/select_command.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: planning_demo SCENARIO PNG [--truth-map] [--truth-labels] [--pile N] "
                 "[--advance M] [--no-baseline]\n";
    return 2;
  }
  autoshovel::sim::SelectOptions options;
  options.scenario = argv[1];
  options.png = argv[2];
  options.models_dir = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
  for (int i = 3; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--truth-map") {
      options.truth_map = true;
    } else if (arg == "--truth-labels") {
      options.truth_labels = true;
    } else if (arg == "--no-baseline") {
      options.baseline = false;
    } else if (arg == "--pile" && i + 1 < argc) {
      options.pile = std::atoi(argv[++i]);
    } else if (arg == "--advance" && i + 1 < argc) {
      options.advance = std::atof(argv[++i]);
    } else {
      std::cerr << "planning_demo: unknown argument '" << arg << "'\n";
      return 2;
    }
  }
  return autoshovel::sim::RunSelect(options, std::cout, std::cerr);
}
