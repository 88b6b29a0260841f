#include "runtime/app/map_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "generated/registry.h"
#include "runtime/core/diagnostics.h"
#include "runtime/model/description.h"
#include "runtime/perception/elevation_map.h"
#include "runtime/perception/map_render.h"
#include "runtime/perception/pile_extraction.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"
#include "runtime/plant/scenario.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sim/perceive_from_plant.h"

namespace autoshovel::app {

int RunMap(const MapOptions& options, std::ostream& out, std::ostream& err) {
  try {
    plant::ScenarioWithMachine setup =
        plant::LoadScenarioWithMachine(options.scenario, options.models_dir);
    plant::Scenario& scenario = setup.scenario;
    const model::MachineDescription& machine = setup.machine;
    plant::Lighting lighting = scenario.lighting;
    if (!options.lighting.empty()) {
      const auto parsed = plant::ParseLighting(options.lighting);
      if (!parsed) {
        err << "autoshovel map: --lighting must be normal, bright or dim, got '" << options.lighting
            << "'\n";
        return 2;
      }
      lighting = *parsed;
    }
    plant::Plant plant(machine, *setup.functions, scenario.world,
                       plant::StartState(scenario, machine, options.advance));
    sensors::RaycastScene scene(scenario.world, plant.OwnBodies());
    sensors::Rng rng(scenario.seed);

    const auto t0 = std::chrono::steady_clock::now();
    perception::ElevationMap map({}, plant.state().hinge_xy);
    perception::SemanticMap semantic(map);
    sim::PerceptionFromPlantOptions perceive;
    perceive.lidar_frames = options.frames;
    perceive.lighting = lighting;
    perceive.truth_labels = options.truth_labels;
    perceive.segmenter = options.segmenter.empty()
                             ? options.models_dir + "/segmentation/yard_segmenter.onnx"
                             : options.segmenter;
    const sim::PerceptionFromPlantStats stats =
        sim::PerceiveFromPlant(plant, scene, rng, perceive, map, semantic);
    if (!stats.ground_plane_found) {
      err << "autoshovel map: too few ground cells to fit the ground plane\n";
      return 1;
    }
    const long points = stats.returns_fused, dropped = stats.returns_on_machine;
    const long filled = stats.holes_filled;
    const std::string semantics_source =
        options.truth_labels ? "simulator labels (--truth)" : stats.semantics;
    const std::vector<perception::ExtractedPile> piles =
        perception::ExtractPiles(map.map(), semantic.ground_plane());
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    perception::WriteSemanticMapPng(map.map(), piles, options.png);

    char line[200];
    std::snprintf(line, sizeof line,
                  "%s, %s light: %ld returns fused (%ld on the machine dropped), %ld holes "
                  "filled, ground z = %.3f x + %.3f y + %.3f (sigma %.3f m), %.2f s\n",
                  scenario.name.c_str(), plant::ToString(lighting), points, dropped, filled,
                  semantic.ground_plane().x(), semantic.ground_plane().y(),
                  semantic.ground_plane().z(), std::sqrt(semantic.ground_variance()), seconds);
    out << line << "semantics: " << semantics_source << "\n";
    for (const perception::ExtractedPile& pile : piles) {
      int front = 0;
      for (const auto& b : pile.boundary) front += b.front;
      std::snprintf(line, sizeof line,
                    "  pile at (%.1f, %.1f): %zu cells, %.1f m3 seen, peak %.2f m, boundary %zu "
                    "cells (%d front)\n",
                    pile.centroid.x(), pile.centroid.y(), pile.cells.size(), pile.volume,
                    pile.peak_height, pile.boundary.size(), front);
      out << line;
    }
    out << "six layers: " << options.png << "\n";
    return 0;
  } catch (const core::InputError& e) {
    err << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "autoshovel map: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace autoshovel::app
