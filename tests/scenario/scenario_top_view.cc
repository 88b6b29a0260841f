// Writes the top view of a scenario and prints how long loading it took.
// usage: scenario_top_view NAME_OR_PATH OUT.png [METRES_PER_PIXEL]
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>

#include "runtime/core/diagnostics.h"
#include "runtime/plant/scenario.h"
#include "runtime/plant/top_view.h"

int main(int argc, char** argv) {
  using namespace autoshovel;
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: %s NAME_OR_PATH OUT.png [METRES_PER_PIXEL]\n", argv[0]);
    return 2;
  }
  try {
    const std::string path =
        plant::ResolveScenario(argv[1], std::string(AUTOSHOVEL_SOURCE_DIR) + "/models");
    const auto start = std::chrono::steady_clock::now();
    const plant::Scenario scenario = plant::LoadScenario(path);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    plant::TopViewOptions options;
    if (argc == 4) options.metres_per_pixel = std::stod(argv[3]);
    options.start = scenario.start;
    plant::WriteTopView(scenario.world, argv[2], options);
    std::printf("%s: %d x %d cells, %zu piles, %zu obstacles, loaded in %.3f s\n",
                scenario.name.c_str(), scenario.world.terrain.nx(), scenario.world.terrain.ny(),
                scenario.piles.size(), scenario.world.obstacles.size(), seconds);
    for (const auto& pile : scenario.piles) {
      std::printf("  %-20s %-12s %-13s bin %2d  %7.2f m3  peak %.2f m\n", pile.name.c_str(),
                  plant::ToString(pile.shape), pile.material.c_str(), pile.bin, pile.volume,
                  pile.peak_height);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
