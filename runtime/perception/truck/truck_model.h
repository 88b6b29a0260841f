// The parametric truck-bed model of truck recognition (excavator seed §4.1, Figure 10): a few
// planar faces whose sizes, relative positions and mutual angles are given as ranges rather than
// single values, so that one model covers a class of trucks. The ranges are checked at every level
// of the interpretation tree (interpretation_tree.h) to prune it.
//
// Faces, as the scanner on the excavator sees them (it looks down into the bed from beside it):
//   kNearSide   the outside of the side wall facing the excavator,
//   kFarSide    the inside of the opposite side wall, seen over the near wall,
//   kFloor      the bed floor (hidden when the walls are high and the scanner low),
//   kHeadboard  the inside of the front wall (between bed and cab),
//   kTailgate   the inside of the rear wall (absent on some bodies, e.g. articulated haulers).
// Every region's normal points toward the scanner, so the near side's normal points out of the
// bed, the far side's into it, the headboard's rearward and the tailgate's forward.
//
// Default ranges, chosen to contain road tippers of roughly 15 t to 20 t payload (bodies about
// 4.5–6 m long, 2.3–2.4 m wide inside, 0.8–1.3 m sides, floors 1.3–1.7 m up) and 35–40 t
// articulated or small rigid haulers (about 5.5–6.5 m long, 3–3.6 m wide, 1.4–1.8 m sides,
// floors near 2 m), with margin. They are rounded figures of the kind published in
// manufacturers' body data sheets, not the values of any one model.
#pragma once

#include <array>
#include <string_view>

#include "runtime/perception/truck/planar_regions.h"

namespace autoshovel::perception {

enum class BedFace { kNearSide = 0, kFarSide = 1, kFloor = 2, kHeadboard = 3, kTailgate = 4 };
inline constexpr int kNumBedFaces = 5;
inline constexpr std::array<BedFace, kNumBedFaces> kAllBedFaces{
    BedFace::kNearSide, BedFace::kFarSide, BedFace::kFloor, BedFace::kHeadboard,
    BedFace::kTailgate};

std::string_view BedFaceName(BedFace face);
inline int FaceIndex(BedFace face) { return static_cast<int>(face); }

struct ParameterRange {
  double min = 0;
  double max = 0;
  bool Contains(double value, double tolerance = 0) const {
    return value >= min - tolerance && value <= max + tolerance;
  }
};

struct TruckBedModel {
  ParameterRange inner_length{3.5, 8.0};     ///< headboard to tailgate, inside [m]
  ParameterRange inner_width{2.0, 3.8};      ///< side wall to side wall, inside [m]
  ParameterRange wall_height{0.6, 2.0};      ///< floor to rim [m]
  ParameterRange floor_height{0.9, 2.5};     ///< floor above the ground [m]
  ParameterRange wall_thickness{0.03, 0.2};  ///< plate plus outside stiffeners [m]
  /// Used to step from the near wall's outside (seen) to its inside (the bed's edge) [m].
  double nominal_wall_thickness = 0.08;
  double max_headboard_rise = 1.0;  ///< headboard top above the rim (cab guards) [m]
  /// Tailgates do not rise above the sides, and no higher than the headboard: this tells the two
  /// end walls apart where the cab is not seen [m].
  double max_tailgate_rise = 0.15;
  double min_near_side_length = 1.0;  ///< the near outside face is seen whole: not a fragment [m]
  /// Slack on every angle (walls vertical, floor level, faces parallel or perpendicular) [deg]:
  /// trucks stand on gently sloping ground and many bodies have flared sides.
  double angle_tolerance_deg = 12;
  /// Slack on every distance and size [m]: region extents are cut by occlusion and scanline
  /// spacing, and centroids of partly seen faces are off their face's centre.
  double distance_tolerance = 0.3;
  /// A complete interpretation needs at least this many faces, both side walls among them (they
  /// fix the bed's width and lateral position; without the far wall nothing shows the bed is
  /// open). Two is enough: a scanner ahead of the headboard of a body without tailgate, looking
  /// over walls too high to see the floor, sees the two sides only. Verification then asks for
  /// the cab to tell front from rear (bed_verification.h).
  int min_matched_faces = 2;
};

/// Throws std::invalid_argument naming the offending field (empty or inverted range, non-finite
/// or negative value, min_matched_faces outside [2, 5]).
void Validate(const TruckBedModel& model);

/// Whether `face` is a required face of every interpretation (the two side walls).
bool IsRequired(BedFace face);

/// Unary constraint: could `region` be `face` (orientation, size, height above the ground when the
/// ground is known)?
bool UnaryConsistent(const TruckBedModel& model, BedFace face, const PlanarRegion& region,
                     const GroundEstimate& ground);

/// Binary constraint: can `a` be `face_a` while `b` is `face_b` (angle between the normals,
/// relative position of the centroids, overlap of the extents, heights)? Symmetric in its
/// arguments; faces must differ.
bool PairConsistent(const TruckBedModel& model, BedFace face_a, const PlanarRegion& a,
                    BedFace face_b, const PlanarRegion& b);

}  // namespace autoshovel::perception
