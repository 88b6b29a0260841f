// Exchange of material between the terrain and the bucket, and the relaxation of the terrain to
// its angle of repose. Every operation moves volume from one place to another (cell ↔ bucket,
// cell ↔ cell), so terrain volume + bucket volume is conserved to round-off.
//
// The bucket is its profile polygon (description `bucket.profile`, bucket frame, tip first, the
// top of the back wall last) swept across its width in the vertical arm plane:
// - capture: every terrain cell under the bucket whose surface lies above the bucket's lower
//   outline loses the material above that outline to the bucket (the material inside the bucket
//   and heaped on top of it moves with it; a height grid cannot hold an overhang);
// - spill: in the open, the bucket holds what lies below its lower rim (the lower of tip and
//   back-wall top) plus a heap whose size grows as the opening turns upwards, up to the rated
//   heaped capacity (SAE J742); anything beyond pours over the lower rim onto the cells just
//   outside it. The same rule empties the bucket when it is tilted to dump. While the lip is
//   in the pile, the surrounding material retains the load up to the heaped capacity and the
//   excess is pushed ahead of the lip;
// - repose: a neighbour pair steeper than the material's angle of repose exchanges material
//   until it is not (a conservative relaxation of the classic sand-pile kind).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "runtime/model/description.h"
#include "runtime/plant/world.h"

namespace autoshovel::plant {

/// The bucket at one instant. The arm plane is vertical through `plane_origin` (world xy) with
/// horizontal axis along `plane_heading`; plane coordinates (s, z) map to the world point
/// plane_origin + s·(cos h, sin h) at height z.
struct BucketPlacement {
  Eigen::Vector2d plane_origin = Eigen::Vector2d::Zero();
  double plane_heading = 0;                         ///< [rad]
  Eigen::Vector2d pivot = Eigen::Vector2d::Zero();  ///< bucket frame origin (s, z) [m]
  double bucket_angle = 0;                          ///< φ_n of the bucket frame [rad]

  /// A point of the bucket frame in plane coordinates.
  Eigen::Vector2d ToPlane(const Eigen::Vector2d& p_bucket) const;
  /// A plane point in world xy.
  Eigen::Vector2d ToWorldXy(double s) const;
};

/// What the terrain touching the bucket looks like, for the resistance model.
struct BucketContact {
  bool in_contact = false;
  double depth = 0;   ///< free surface above the tip, at the tip [m]
  int material = -1;  ///< material index at the tip (or of the deepest cell)
  Eigen::Vector2d tip = Eigen::Vector2d::Zero();  ///< plane coordinates [m]
  Eigen::Vector2d rim = Eigen::Vector2d::Zero();  ///< top of the back wall, plane coordinates
};

struct ExchangeResult {
  double captured_volume = 0;  ///< moved from terrain into the bucket this call [m³]
  double spilled_volume = 0;   ///< poured from the bucket onto the terrain this call [m³]
};

/// Which way the bucket cuts along the arm plane: a loader's forward, away from the machine; an
/// excavator's dragged in, towards it.
enum class CuttingDirection { kAwayFromMachine, kTowardsMachine };

class BucketTerrain {
 public:
  BucketTerrain(const model::Bucket& bucket, World& world,
                CuttingDirection cutting = CuttingDirection::kAwayFromMachine);

  /// Captures material under the bucket and pours out what it cannot hold.
  ExchangeResult Exchange(const BucketPlacement& placement);
  /// The contact seen at the bucket tip.
  /// The terrain just ahead of the cutting edge, looking away from the machine (a loader's
  /// bucket cutting forward). An excavator's bucket dragged towards the machine is in contact
  /// only through what lies beyond its tip on that side, so the resistance model, which uses
  /// this, gives its drag little or no cutting resistance: a known gap (docs/simulation.md).
  BucketContact Contact(const BucketPlacement& placement) const;
  /// The same looking to one side: `ahead` +1 away from the machine, −1 towards it.
  BucketContact ContactAhead(const BucketPlacement& placement, double ahead) const;
  /// Volume the bucket holds in this orientation [m³]: what lies below a free surface rising
  /// from the lower rim at min(opening inclination, angle of repose), plus the heap the
  /// opening's inclination still supports (rated heaped capacity when the opening is level).
  double HoldableVolume(const BucketPlacement& placement) const;
  /// Relaxes slopes steeper than the angle of repose in a square of half size `half_window`
  /// around `center_xy`; at most `max_iterations` sweeps. Returns the volume moved [m³].
  double RelaxToRepose(const Eigen::Vector2d& center_xy, double half_window,
                       int max_iterations = 30);

  double payload_volume() const { return payload_volume_; }
  double payload_mass() const { return payload_mass_; }
  /// Material index making up most of the payload, or -1 when empty.
  int payload_material() const;
  /// Empties the bucket into nothing (tests and scenario resets only: breaks conservation).
  void ClearPayload();

 private:
  std::vector<Eigen::Vector2d> PlanePolygon(const BucketPlacement& placement) const;
  /// Cells whose centre lies within the bucket's width and the s-range [s0, s1].
  template <typename Visit>
  void ForEachCellInStrip(const BucketPlacement& placement, double s0, double s1,
                          Visit&& visit) const;
  /// The same, skipping cells whose surface is at or below `min_height`.
  template <typename Visit>
  void ForEachCellInStrip(const BucketPlacement& placement, double s0, double s1, double min_height,
                          const std::vector<double>& heights, Visit&& visit) const;
  /// Angle of repose of the payload's main material (a typical 35° when empty) [rad].
  double PayloadAngleOfRepose() const;
  /// Pours up to `volume` over `rim` (plane coordinates) onto the terrain on the `outward` side
  /// (+1 away from the machine): pushed ahead inside the pile (`in_pile`; an excavator's heap
  /// no higher than `top`, the opening's upper edge), or poured out in the open (no higher than
  /// the rim); returns what was poured.
  double Pour(const BucketPlacement& placement, const Eigen::Vector2d& rim, double outward,
              double volume, bool in_pile, double top);

  const model::Bucket& bucket_;
  World& world_;
  CuttingDirection cutting_;
  double struck_area_ = 0;  ///< profile polygon area [m²]
  double payload_volume_ = 0;
  double payload_mass_ = 0;
  std::vector<double> payload_by_material_;
};

}  // namespace autoshovel::plant
