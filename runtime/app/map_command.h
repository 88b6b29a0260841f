// `autoshovel map SCENARIO`: the semantic elevation map the loader builds from its start pose in
// a simulated yard (LiDAR frames, one camera frame, fusion, pile extraction), drawn as the six
// layers of the wheel-loader seed's Fig. 5.
#pragma once

#include <iosfwd>
#include <string>

namespace autoshovel::app {

struct MapOptions {
  std::string scenario;
  std::string models_dir;
  std::string png = "semantic_map.png";
  std::string lighting;  ///< overrides the scenario's: normal | bright | dim
  int frames = 5;        ///< LiDAR frames per sensor
  double advance = 0.0;  ///< drive the start pose this far ahead first [m]
  /// ONNX segmentation network; empty: models/segmentation/yard_segmenter.onnx.
  std::string segmenter;
  bool truth_labels = false;  ///< use the simulator's labels instead of the network
};

int RunMap(const MapOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app
