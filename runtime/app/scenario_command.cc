#include "runtime/app/scenario_command.h"

#include <chrono>
#include <cstdio>
#include <iostream>

#include "runtime/core/diagnostics.h"
#include "runtime/plant/scenario.h"
#include "runtime/plant/top_view.h"

namespace autoshovel::app {

int RunScenario(const ScenarioOptions& options, std::ostream& out, std::ostream& err) {
  try {
    const std::string path = plant::ResolveScenario(options.scenario, options.models_dir);
    const auto start = std::chrono::steady_clock::now();
    const plant::Scenario scenario = plant::LoadScenario(path);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const plant::Terrain& terrain = scenario.world.terrain;
    char line[256];
    std::snprintf(line, sizeof line,
                  "%s (%s): %d x %d cells of %.2f m, %zu piles, %zu obstacles, machine %s, "
                  "lighting %s, seed %u; built in %.2f s\n",
                  scenario.name.c_str(), scenario.source_file.c_str(), terrain.nx(), terrain.ny(),
                  terrain.resolution(), scenario.piles.size(), scenario.world.obstacles.size(),
                  scenario.machine.c_str(), plant::ToString(scenario.lighting), scenario.seed,
                  seconds);
    out << line;
    for (const plant::Pile& pile : scenario.piles) {
      std::snprintf(line, sizeof line, "  %-20s %-12s %-13s bin %2d  %8.2f m3  peak %.2f m\n",
                    pile.name.c_str(), plant::ToString(pile.shape), pile.material.c_str(), pile.bin,
                    pile.volume, pile.peak_height);
      out << line;
    }
    for (const plant::OrientedBox& box : scenario.world.obstacles) {
      std::snprintf(line, sizeof line, "  %-20s %-12s at (%.1f, %.1f)\n", box.name.c_str(),
                    std::string(core::ToString(box.semantic_class)).c_str(), box.center.x(),
                    box.center.y());
      out << line;
    }
    if (!options.png.empty()) {
      plant::TopViewOptions view;
      view.metres_per_pixel = options.metres_per_pixel;
      view.start = scenario.start;
      plant::WriteTopView(scenario.world, options.png, view);
      out << "top view: " << options.png << "\n";
    }
    return 0;
  } catch (const core::InputError& e) {
    err << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "autoshovel scenario: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace autoshovel::app
