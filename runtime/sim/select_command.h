// `autoshovel select SCENARIO`: the semantic elevation map of a simulated yard, shovel point
// selection on it (wheel-loader seed §5, Algorithm 2) and the Chen et al. (2024) baseline, drawn
// as the seed's Fig. 19.
//
// The simulation side (runtime/sim, docs/architecture.md): it builds the map from the simulator
// (runtime/plant, runtime/sensors), which the planner library autoshovel_planning never sees.
#pragma once

#include <Eigen/Core>
#include <iosfwd>
#include <string>
#include <vector>

#include "runtime/perception/grid_map.h"
#include "runtime/perception/pile_extraction.h"
#include "runtime/plant/scenario.h"

namespace autoshovel::sim {

struct SelectOptions {
  std::string scenario;    ///< name under <models_dir>/scenarios, or a path
  std::string models_dir;  ///< the models/ folder
  std::string png = "shovel_points.png";
  /// Rasterise the simulator's terrain and obstacles into the map (every side of every pile
  /// known) instead of perceiving it from the start pose with the LiDARs and the camera.
  bool truth_map = false;
  bool truth_labels = false;  ///< perception with the simulator's labels, not the network
  std::string segmenter;      ///< ONNX network; empty: models/segmentation/yard_segmenter.onnx
  int frames = 5;             ///< LiDAR frames per sensor
  double advance = 0.0;       ///< drive the start pose this far ahead first [m]
  double spacing = 1.0;       ///< candidate spacing along the pile front [m]
  /// Entry headings relative to the pile's inward normal [deg].
  std::vector<double> entry_angles_deg = {-30, -15, 0, 15, 30};
  double safety_distance = 1.0;  ///< d_res [m]
  int top = 20;                  ///< candidates listed and drawn
  int pile = -1;                 ///< select on this pile only (index, largest first); −1: all
  bool baseline = true;          ///< also rank by Chen et al. (2024) and draw it beside
};

/// Runs the command: prints the map summary, the ranked top candidates with their five scores,
/// the baseline's best, and writes the PNG. Returns 0 on success, 1 when nothing could be
/// selected, 2 on bad input.
int RunSelect(const SelectOptions& options, std::ostream& out, std::ostream& err);

/// The map of a yard from the simulator's truth, at `resolution` [m]: layers "elevation" (the
/// terrain's mean height over the cell, an obstacle's top), "variance" (1e-4 m²) and "class"
/// (obstacle where an obstacle's footprint comes within the cell's circumradius of its centre,
/// pile where most of the cell holds ≥ 1 cm of material, ground elsewhere). The ground plane is the
/// floor: (0, 0, floor height).
perception::GridMap TruthMap(const plant::Scenario& scenario, double resolution = 0.3);

}  // namespace autoshovel::sim
