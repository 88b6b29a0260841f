// The terrain-shape templates of dump planning (excavator seed §4.3). A small square template,
// 5 × 5 or 7 × 7 cells, is slid over the whole truck-bed terrain map; at each cell the weighted
// sum of the heights under it is a score of how well the terrain there has the profile the
// template looks for, and the best-scoring cell is where the next bucket goes.
//
// Reading of the seed (it names the sizes and the kinds of profile, not the weights):
// - Sign: every template here is built so that a HIGHER score is a better place to dump.
// - kFlat is §4.3's "simple template of constant elevation": all weights −1/n², so the score is
//   minus the mean height under the template [m] and the best cell is the centre of the lowest
//   n × n patch of the bed. This is the default: it puts each load in the lowest region, which is
//   what loading "evenly and completely" needs.
// - kHole looks for §4.3's "hole": the inner (n−2) × (n−2) block weighs −1/(n−2)², the one-cell
//   ring around it +1/(4(n−1)); the weights sum to 0, so the score is the ring's mean height
//   minus the inner block's [m], the depth of a local depression whatever its absolute level
//   (e.g. the gap between two earlier loads).
// - Size: the template stands for the patch one bucket load lands on, so the size follows the
//   bucket: the seed's two sizes are 0.75 m and 1.05 m at 15 cm; a bucket whose larger plan side
//   spans fewer than 6 cells (0.9 m at 15 cm) gets 5 × 5, a larger one 7 × 7.
#pragma once

#include <Eigen/Core>

namespace autoshovel::planning {

enum class DumpTemplateShape {
  kFlat,  ///< constant elevation: finds the lowest region (default)
  kHole,  ///< depression: finds a patch lower than its rim
};

/// §4.3's template size for a bucket whose larger plan side is `bucket_footprint_m`: 5 when it
/// spans fewer than 6 cells, else 7. Throws std::invalid_argument unless both are finite and > 0.
int ChooseTemplateSize(double bucket_footprint_m, double cell_size_m);

/// The n × n template of `shape` (weights as in the file comment). `size` must be odd and in
/// [3, 15] (the seed uses 5 and 7); otherwise std::invalid_argument.
Eigen::MatrixXd MakeDumpTemplate(DumpTemplateShape shape, int size);

}  // namespace autoshovel::planning
