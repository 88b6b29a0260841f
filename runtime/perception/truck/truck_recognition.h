// Truck recognition (excavator seed §4.1): from the scanlines of one pan across the truck to
// "loadable truck here, this big, this pose" or "no truck". The pipeline, one file per step:
//   scanlines → line segments (line_segmentation.h)
//             → coplanar planar regions, and the ground among them (planar_regions.h)
//             → interpretation-tree match of the parametric bed model (interpretation_tree.h,
//               truck_model.h), each complete interpretation fitted (bed_fit.h) and verified
//               (bed_verification.h)
//             → the best verified interpretation: bed corner points, pose and dimensions.
// docs/truck_recognition.md describes the steps, the model's ranges and the measured accuracy.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "runtime/perception/truck/bed_fit.h"
#include "runtime/perception/truck/bed_verification.h"
#include "runtime/perception/truck/interpretation_tree.h"
#include "runtime/perception/truck/line_segmentation.h"
#include "runtime/perception/truck/planar_regions.h"
#include "runtime/perception/truck/scanline.h"
#include "runtime/perception/truck/truck_model.h"

namespace autoshovel::perception {

struct TruckRecognitionParams {
  LineSegmentationParams segmentation;
  PlanarRegionParams regions;
  double ground_max_tilt_deg = 5;
  TruckBedModel model;
  InterpretationTreeParams tree;
  VerificationParams verification;
};

/// Throws std::invalid_argument naming the offending field.
void Validate(const TruckRecognitionParams& params);

struct TruckBedDimensions {
  double length = 0;  ///< inside, along the bed [m]
  double width = 0;   ///< inside, across the bed [m]
  /// Floor to rim [m]; NaN when the floor was not seen (high walls, low scanner).
  double wall_height = std::numeric_limits<double>::quiet_NaN();
  /// Floor above the ground [m]; NaN when the floor or the ground was not seen.
  double floor_height = std::numeric_limits<double>::quiet_NaN();
  /// Rim above the ground [m]; NaN when the ground was not seen.
  double rim_height = std::numeric_limits<double>::quiet_NaN();
};

struct TruckRecognitionResult {
  bool found = false;
  /// Bed frame: origin at the centre of the bed opening on the rim plane, x along the bed toward
  /// the cab, y to its left, z up. Pose (x, y, z, yaw) = translation and yaw of this frame.
  Eigen::Isometry3d T_world_bed = Eigen::Isometry3d::Identity();
  /// Inside corners of the opening at rim height (world): front-left, front-right, rear-right,
  /// rear-left.
  std::array<Eigen::Vector3d, 4> p_world_corners{};
  TruckBedDimensions dimensions;
  /// Model face → region (index into `regions`), -1 where the face was not matched.
  Interpretation interpretation;
  int matched_faces = 0;
  bool front_from_end_wall = false;  ///< else from the cab (bed_verification.h)
  double score = 0;                  ///< verification score of the selected interpretation
  int support_points = 0;
  int free_space_violations = 0;
  /// Why nothing was found (empty when found).
  std::string reason;
  // Diagnostics.
  int num_segments = 0;
  int num_regions = 0;
  long tree_nodes = 0;
  /// Regions passing each face's unary constraints (kAllBedFaces order).
  std::array<int, kNumBedFaces> face_candidates{0, 0, 0, 0, 0};
  int interpretations_verified = 0;
  int interpretations_complete = 0;
  bool search_truncated = false;

  double YawRad() const;
  /// The frame of the dump planner's bed map (runtime/planning/dump/bed_height_map.h): origin at
  /// the rear-right corner of the opening, same axes, so the opening is [0, length] × [0, width].
  Eigen::Isometry3d T_world_bed_corner() const;
};

/// Intermediate products, for tests, plots and diagnosis.
struct TruckRecognitionTrace {
  std::vector<LineSegment> segments;
  std::vector<PlanarRegion> regions;
  GroundEstimate ground;
};

class TruckRecognizer {
 public:
  /// Throws std::invalid_argument when `params` are invalid.
  explicit TruckRecognizer(const TruckRecognitionParams& params = {});

  /// Recognises at most one truck in the scanlines of one pan. Throws std::invalid_argument on a
  /// scanline with a non-finite sensor origin; unusable returns are skipped.
  TruckRecognitionResult Recognize(const std::vector<Scanline>& scanlines,
                                   TruckRecognitionTrace* trace = nullptr) const;

  const TruckRecognitionParams& params() const { return params_; }

 private:
  TruckRecognitionParams params_;
};

}  // namespace autoshovel::perception
