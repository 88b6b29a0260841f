// Randomised test scenes for truck recognition: a truck of a given size at a random pose beside
// the excavator, with clutter, or a scene that holds no truck at all. Test-only.
#pragma once

#include <optional>
#include <string_view>

#include "truck_scan_simulation.h"

namespace autoshovel::perception::truck_sim {

struct TestScene {
  SimScene scene;
  ScannerSpec scanner;
  std::optional<TruckTruth> truth;  ///< set when the scene holds a truck
};

struct SceneOptions {
  /// The scanner's height above the ground is drawn from this range [m].
  double sensor_height_min = 4.5;
  double sensor_height_max = 5.0;
  /// Range noise σ and dropout probability are drawn from these ranges [m, -].
  double noise_sigma_min = 0.02;
  double noise_sigma_max = 0.03;
  double dropout_min = 0.01;
  double dropout_max = 0.05;
  /// Pan per scanline and beam step within it [deg].
  double pan_step_deg = 0.6;
  double elevation_step_deg = 0.45;
  /// Truck scenes: add a dirt pile, a retaining wall and a non-truck box, clear of the truck.
  bool clutter = true;
};

/// A truck with its bed centre 6–8 m to the excavator's left and up to 2 m fore or aft, heading
/// forward or backward (even chance) turned by up to ±30°, scanned by the left scanner panning
/// from 35° to 145° (0° is the excavator's forward direction).
TestScene MakeTruckScene(const TruckSpec& spec, Rng& rng, const SceneOptions& options = {});

enum class NegativeKind {
  kGround,         ///< bare ground
  kPile,           ///< two dirt piles
  kWall,           ///< a retaining wall
  kBox,            ///< a solid box of truck-like size (a container, a site cabin)
  kAllClutter,     ///< box, pile and wall together
  kParallelWalls,  ///< two walls a bed width apart, rims level: a bed's sides without a bed
  kOpenSkip,       ///< an open-topped skip standing on the ground: a bed without a truck
};
std::string_view NegativeKindName(NegativeKind kind);

/// A scene with no truck (see NegativeKind).
TestScene MakeNegativeScene(NegativeKind kind, Rng& rng, const SceneOptions& options = {});

inline constexpr NegativeKind kAllNegativeKinds[] = {
    NegativeKind::kGround,  NegativeKind::kPile,       NegativeKind::kWall,
    NegativeKind::kBox,     NegativeKind::kAllClutter, NegativeKind::kParallelWalls,
    NegativeKind::kOpenSkip};

}  // namespace autoshovel::perception::truck_sim
