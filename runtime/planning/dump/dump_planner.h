// Template based dump planning (excavator seed §4.3): after each bucket load the truck bed is
// scanned again and the next dump point is chosen afresh, because the soil settles unpredictably
// and a fixed loading pattern would not stay even. The steps, in the seed's order:
//   1. the truck-bed terrain map (bed_height_map.h: 15 cm cells, points outside the bed dropped);
//   2. Gaussian smoothing against sensor noise (grid_filters.h: σ in cells, known cells only);
//   3. cells the walls hid are set to the mean height of the seen cells, not to "empty";
//   4. a 5 × 5 or 7 × 7 terrain template is correlated with the whole map (dump_template.h);
//   5. the best-scoring cell is the dump point.
//
// What the seed leaves open, decided here (docs/dump_planning.md explains each):
// - Step 5 only considers cells where the bucket's plan footprint, grown by `wall_margin_m`, lies
//   inside the bed, so a load is never released over or against a wall. The footprint is an
//   axis-aligned rectangle in the bed frame: with the truck parked beside the excavator (§4.2)
//   the arm reaches across the bed and the bucket's cutting edge, tangent to the swing arc, lies
//   along it.
// - Scores within `tie_tolerance_m` of the best count as equal. A flat low region wider than the
//   template (an empty bed, the empty end of one) is all ties, and the seed's small templates
//   cannot see past 1 m: among the ties the cell whose wider surroundings (a Gaussian mean of
//   σ = `surroundings_sigma_m`, about a settled load's spread) are lowest, within
//   `surroundings_tolerance_m`, wins, so the load goes to the middle of the empty region instead of
//   onto the toe of the last heap; if still tied, the cell nearest the bed's centre (then the
//   lowest index): on an empty bed the first load goes to the middle, over the truck's axles.
// - The dump point's height is the smoothed, filled surface height of the chosen cell.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "runtime/planning/dump/bed_height_map.h"
#include "runtime/planning/dump/cell_mask.h"
#include "runtime/planning/dump/dump_template.h"

namespace autoshovel::planning {

struct DumpPlannerConfig {
  /// σ of the §4.3 Gaussian filter [cells]; 1 cell = 15 cm removes centimetre range noise and
  /// leaves a bucket-sized heap's shape; 0 turns smoothing off.
  double smoothing_sigma_cells = 1.0;
  DumpTemplateShape shape = DumpTemplateShape::kFlat;
  /// Template side in cells (odd, 3 to 15; the seed uses 5 or 7). 0: ChooseTemplateSize from the
  /// bucket footprint's larger side.
  int template_size = 0;
  double footprint_along_bed_m = 1.2;   ///< bucket plan size along bed x (its width) [m]
  double footprint_across_bed_m = 1.0;  ///< bucket plan size along bed y [m]
  double wall_margin_m = 0.15;          ///< clearance, footprint to the walls' inside [m]
  /// Scores closer than this to the best are ties, broken as the file comment says [score units:
  /// metres of height for both shapes]. Above the scan noise left after smoothing and the
  /// template's averaging (4.6 to 6.9 mm from lowest to highest allowed cell on empty beds scanned
  /// with 3 cm range noise at ~7 returns per cell).
  double tie_tolerance_m = 0.01;
  /// σ of the Gaussian "surroundings" height that breaks ties [m]: about half the radius a
  /// poured load spreads over (a 1 m³ cone at a 35° angle of repose is 2.2 m across). 0: no
  /// surroundings stage, ties go straight to the centre rule.
  double surroundings_sigma_m = 0.6;
  /// Surroundings closer than this to the lowest are ties, left to the centre rule [m]. On an
  /// empty bed scanned with 3 cm range noise the wide mean still varies by 1.7 to 3.3 mm over the
  /// allowed cells (slow noise, edge renormalisation): 3 mm put the first load at a centre cell
  /// in 30 of 30 such scans, 2 mm up to 0.7 m off; 4 mm and more cost evenness (the load creeps
  /// back toward earlier heaps; docs/dump_planning.md).
  double surroundings_tolerance_m = 0.003;
};

struct DumpPlan {
  Eigen::Vector2i cell{0, 0};                              ///< (ix, iy) of the chosen cell
  Eigen::Vector3d p_bed_dump = Eigen::Vector3d::Zero();    ///< cell centre, surface z [m]
  Eigen::Vector3d p_world_dump = Eigen::Vector3d::Zero();  ///< T_world_bed · p_bed_dump [m]
  double score = 0;       ///< the template's score at the chosen cell
  int template_size = 0;  ///< the n of the n × n template used
  int known_cells = 0;    ///< cells the scan saw
  int filled_cells = 0;   ///< cells set to the known mean (§4.3 occlusion rule)
  /// For plotting (rows along the bed, columns across): the map the template saw (smoothed,
  /// unknown cells filled), the score of every cell (finite everywhere; cells beyond the grid
  /// replicate the edge) and the cells where the bucket footprint keeps the wall margin.
  Eigen::MatrixXd prepared_heights;
  Eigen::MatrixXd score_map;
  CellMask feasible;
  Eigen::MatrixXd surroundings;  ///< the tie-break's wide Gaussian mean of prepared_heights [m]
};

class DumpPlanner {
 public:
  /// Throws std::invalid_argument on a negative or non-finite σ, a template size that is not 0 or
  /// odd in [3, 15], a non-positive footprint side, or a negative margin or tolerance.
  explicit DumpPlanner(const DumpPlannerConfig& config = {});

  /// The next dump point on `map` (a scan taken after the last load). Throws
  /// std::invalid_argument when T_world_bed is not finite or when the footprint with its margins
  /// fits nowhere in the bed.
  DumpPlan Plan(const BedHeightMap& map, const Eigen::Isometry3d& T_world_bed) const;

  /// The cells where the footprint with `wall_margin_m` lies inside `map`'s bed.
  CellMask FeasibleCells(const BedHeightMap& map) const;
  /// The template size Plan uses at `cell_size_m`.
  int TemplateSize(double cell_size_m) const;

  const DumpPlannerConfig& config() const { return config_; }

 private:
  DumpPlannerConfig config_;
};

}  // namespace autoshovel::planning
