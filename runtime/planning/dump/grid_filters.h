// The small grid operations of template dump planning (excavator seed §4.3): the Gaussian filter
// that removes scanner noise from the truck-bed terrain map, the fill of unseen cells with the
// mean of the seen ones, and the 2-D correlation that slides a terrain template over the map.
//
// They are written here over Eigen matrices instead of taken from OpenCV on purpose: a truck bed
// at 15 cm is on the order of 500 cells (§4.3; even a 9 m × 3.75 m bed is 60 × 25), so each
// operation is a few thousand multiply-adds, and doing them by hand lets the smoothing honour the
// known/unknown mask (OpenCV's filters would smear the stored 0 m of unseen cells into
// their neighbours) and keeps the dump planner free of an image library.
#pragma once

#include <Eigen/Core>

#include "runtime/planning/dump/cell_mask.h"

namespace autoshovel::planning {

/// Sampled, normalised 1-D Gaussian of standard deviation `sigma_cells` (in cells), truncated at
/// radius ⌈3σ⌉ (2⌈3σ⌉ + 1 taps, summing to 1). σ = 0 gives the identity [1]. Throws
/// std::invalid_argument for a negative or non-finite σ, or σ above 50 cells.
Eigen::VectorXd GaussianKernel1d(double sigma_cells);

/// The 2-D Gaussian, the outer product of two GaussianKernel1d (square, odd, sums to 1).
Eigen::MatrixXd GaussianKernel(double sigma_cells);

/// §4.3's Gaussian smoothing, restricted to the known cells: each known cell becomes the
/// kernel-weighted mean of the known cells around it (weights renormalised over the known cells
/// inside the grid), so unknown cells and the grid's edge never pull heights toward their
/// stored values. A constant field stays exactly constant. Unknown cells come out 0 and stay
/// unknown: filling them is FillUnknownWithKnownMean's job. Throws std::invalid_argument on a
/// size mismatch or a non-finite height in a known cell (unknown cells' values are ignored).
Eigen::MatrixXd SmoothKnown(const Eigen::MatrixXd& heights, const CellMask& known,
                            double sigma_cells);

/// §4.3's occlusion rule: every unknown cell takes the mean height of the known cells (rather
/// than being taken as empty); known cells are copied. With no known cell at all there is no mean
/// and every cell becomes 0 (a flat bed at the bed frame's z = 0). Throws std::invalid_argument
/// on a size mismatch or a non-finite height in a known cell.
Eigen::MatrixXd FillUnknownWithKnownMean(const Eigen::MatrixXd& heights, const CellMask& known);

/// Mean of the known cells; 0 when none is known.
double KnownMean(const Eigen::MatrixXd& heights, const CellMask& known);

/// 2-D correlation out(i, j) = Σ_ab kernel(a, b) · field(i + a − ra, j + b − rb) with (ra, rb) the
/// kernel's centre, same size as `field`, cells beyond the grid replicating the nearest edge cell.
/// (§4.3 calls it a convolution; for the symmetric dump templates the two are the same.) Throws
/// std::invalid_argument for an empty or even-sized kernel or a non-finite value.
Eigen::MatrixXd Correlate(const Eigen::MatrixXd& field, const Eigen::MatrixXd& kernel);

}  // namespace autoshovel::planning
