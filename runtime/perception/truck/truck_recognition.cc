#include "runtime/perception/truck/truck_recognition.h"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

namespace autoshovel::perception {

void Validate(const TruckRecognitionParams& params) {
  Validate(params.segmentation);
  Validate(params.regions);
  if (!std::isfinite(params.ground_max_tilt_deg) || params.ground_max_tilt_deg <= 0 ||
      params.ground_max_tilt_deg >= 90) {
    throw std::invalid_argument("TruckRecognitionParams: ground_max_tilt_deg must lie in (0, 90)");
  }
  Validate(params.model);
  if (params.tree.max_nodes <= 0) {
    throw std::invalid_argument("InterpretationTreeParams: max_nodes must be positive");
  }
  Validate(params.verification);
}

double TruckRecognitionResult::YawRad() const {
  const Eigen::Vector3d x = T_world_bed.linear().col(0);
  return std::atan2(x.y(), x.x());
}

Eigen::Isometry3d TruckRecognitionResult::T_world_bed_corner() const {
  Eigen::Isometry3d T_bed_corner = Eigen::Isometry3d::Identity();
  T_bed_corner.translation() =
      Eigen::Vector3d(-0.5 * dimensions.length, -0.5 * dimensions.width, 0.0);
  return T_world_bed * T_bed_corner;
}

TruckRecognizer::TruckRecognizer(const TruckRecognitionParams& params) : params_(params) {
  Validate(params_);
}

// §4.1, end to end: segments, planar regions, interpretation tree with verification.
TruckRecognitionResult TruckRecognizer::Recognize(const std::vector<Scanline>& scanlines,
                                                  TruckRecognitionTrace* trace) const {
  TruckRecognitionTrace local;
  TruckRecognitionTrace& t = trace != nullptr ? *trace : local;
  t.segments = SegmentScanlines(scanlines, params_.segmentation);
  t.regions = GroupPlanarRegions(t.segments, params_.regions);
  t.ground = EstimateGround(t.regions, params_.ground_max_tilt_deg);

  TruckRecognitionResult result;
  result.num_segments = static_cast<int>(t.segments.size());
  result.num_regions = static_cast<int>(t.regions.size());

  // Each complete interpretation is fitted and verified; the selected one's fit is kept (the
  // verifier may have turned it round to put the cab ahead).
  std::optional<BedFit> best_fit;
  BedVerification best_verification;
  std::string last_rejection;
  const auto verify = [&](const Interpretation& interpretation) -> std::optional<double> {
    BedFit fit = FitBed(interpretation, t.regions, t.segments, params_.model, t.ground);
    BedVerification v = VerifyBed(fit, t.segments, scanlines, params_.model, params_.verification);
    if (!v.passed) {
      last_rejection = v.reason;
      return std::nullopt;
    }
    const bool better = !best_fit ||
                        interpretation.NumMatched() > result.interpretation.NumMatched() ||
                        (interpretation.NumMatched() == result.interpretation.NumMatched() &&
                         v.score > best_verification.score);
    if (better) {
      best_fit = fit;
      best_verification = v;
      result.interpretation = interpretation;
    }
    return v.score;
  };
  const InterpretationSearchResult search =
      SearchInterpretationTree(t.regions, params_.model, t.ground, verify, params_.tree);
  result.tree_nodes = search.nodes;
  result.face_candidates = search.candidates;
  result.interpretations_complete = search.complete;
  result.interpretations_verified = search.verified;
  result.search_truncated = search.truncated;

  if (!search.found || !best_fit) {
    result.reason = search.complete == 0
                        ? "no set of planar regions fits the truck-bed model"
                        : "no interpretation survived verification (last: " + last_rejection + ")";
    return result;
  }
  const BedFit& fit = *best_fit;
  result.found = true;
  result.matched_faces = result.interpretation.NumMatched();
  result.T_world_bed = fit.T_world_bed;
  result.p_world_corners = fit.CornersWorld();
  result.dimensions.length = fit.length;
  result.dimensions.width = fit.width;
  result.dimensions.wall_height = fit.rim_z - fit.floor_z;  // NaN when the floor was unseen
  result.dimensions.floor_height = fit.floor_z - fit.ground_z;
  result.dimensions.rim_height = fit.rim_z - fit.ground_z;
  result.front_from_end_wall = fit.front_from_end_wall;
  result.score = best_verification.score;
  result.support_points = best_verification.support_points;
  result.free_space_violations = best_verification.free_space_violations;
  return result;
}

}  // namespace autoshovel::perception
