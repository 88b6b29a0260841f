// The grid operations of §4.3 (excavator seed): Gaussian smoothing, the mean fill of unseen
// cells, the template correlation.
#include "runtime/planning/dump/grid_filters.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace autoshovel::planning {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double Std(const Eigen::MatrixXd& m) { return std::sqrt((m.array() - m.mean()).square().mean()); }

TEST(GridFilters, GaussianKernelSumsToOneAndHasTheRequestedSpread) {
  for (const double sigma : {0.0, 0.5, 1.0, 1.7, 2.5}) {
    SCOPED_TRACE(sigma);
    const Eigen::VectorXd g = GaussianKernel1d(sigma);
    const int radius = static_cast<int>(std::ceil(3 * sigma));
    ASSERT_EQ(g.size(), 2 * radius + 1);
    EXPECT_NEAR(g.sum(), 1.0, 1e-12);
    EXPECT_TRUE(g.isApprox(g.reverse()));
    EXPECT_EQ(g.maxCoeff(), g(radius));
    if (sigma > 0) {
      EXPECT_NEAR(g(radius + 1) / g(radius), std::exp(-0.5 / (sigma * sigma)), 1e-12);
    }

    const Eigen::MatrixXd k = GaussianKernel(sigma);
    EXPECT_EQ(k.rows(), g.size());
    EXPECT_EQ(k.cols(), g.size());
    EXPECT_NEAR(k.sum(), 1.0, 1e-12);
    EXPECT_TRUE(k.isApprox(k.transpose()));
  }
  // Truncated at 3σ, the sampled kernel's variance is that of the continuous Gaussian.
  const Eigen::VectorXd g = GaussianKernel1d(2.0);
  double variance = 0;
  for (int k = 0; k < g.size(); ++k) variance += g(k) * (k - 6) * (k - 6);
  EXPECT_NEAR(variance, 4.0, 0.1);
}

TEST(GridFilters, SmoothingKeepsAConstantFieldAndItsMeanEvenAroundUnknownCellsAndEdges) {
  const double level = 0.73;
  Eigen::MatrixXd heights = Eigen::MatrixXd::Constant(32, 16, level);
  CellMask known = CellMask::Constant(32, 16, true);
  // Unseen cells hold junk that must not leak: a strip along one wall and a hole in the middle.
  known.block(0, 0, 32, 3).setConstant(false);
  known.block(14, 7, 3, 3).setConstant(false);
  heights.block(0, 0, 32, 3).setConstant(1e6);
  heights(15, 8) = kNaN;
  for (const double sigma : {0.5, 1.0, 2.0}) {
    SCOPED_TRACE(sigma);
    const Eigen::MatrixXd smoothed = SmoothKnown(heights, known, sigma);
    EXPECT_TRUE(smoothed.allFinite());
    for (int i = 0; i < 32; ++i) {
      for (int j = 0; j < 16; ++j) {
        EXPECT_NEAR(smoothed(i, j), known(i, j) ? level : 0.0, 1e-12) << i << ", " << j;
      }
    }
    EXPECT_NEAR(KnownMean(smoothed, known), level, 1e-12);
  }
}

TEST(GridFilters, SmoothingRemovesRangeNoise) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.03);
  Eigen::MatrixXd heights(32, 16);
  for (int i = 0; i < heights.size(); ++i) heights(i) = 0.4 + noise(rng);
  const CellMask known = CellMask::Constant(32, 16, true);
  const Eigen::MatrixXd smoothed = SmoothKnown(heights, known, 1.0);
  // A σ = 1 cell Gaussian averages about 4π cells' worth of independent noise: std / ~3.5.
  EXPECT_LT(Std(smoothed), 0.4 * Std(heights));
  EXPECT_NEAR(smoothed.mean(), heights.mean(), 0.002);
  // σ = 0 is the identity.
  EXPECT_TRUE(SmoothKnown(heights, known, 0.0).isApprox(heights, 0.0));
}

TEST(GridFilters, UnknownCellsBecomeExactlyTheMeanOfTheKnownCells) {
  Eigen::MatrixXd heights = Eigen::MatrixXd::Zero(6, 5);
  CellMask known = CellMask::Constant(6, 5, false);
  const double values[] = {0.10, 0.45, 0.30, 0.82};
  const int cells[][2] = {{0, 0}, {2, 3}, {5, 4}, {3, 1}};
  double sum = 0;
  for (int k = 0; k < 4; ++k) {
    heights(cells[k][0], cells[k][1]) = values[k];
    known(cells[k][0], cells[k][1]) = true;
    sum += values[k];
  }
  heights(1, 1) = kNaN;  // an unknown cell's value is ignored, even NaN
  const double mean = sum / 4;

  const Eigen::MatrixXd filled = FillUnknownWithKnownMean(heights, known);
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 5; ++j) {
      EXPECT_DOUBLE_EQ(filled(i, j), known(i, j) ? heights(i, j) : mean) << i << ", " << j;
    }
  }
  EXPECT_DOUBLE_EQ(KnownMean(heights, known), mean);

  // No data at all: no mean, and no NaN either: a flat bed at z = 0.
  const Eigen::MatrixXd none = FillUnknownWithKnownMean(heights, CellMask::Constant(6, 5, false));
  EXPECT_TRUE(none.isZero(0.0));
}

TEST(GridFilters, CorrelationWeighsTheNeighbourhoodAndReplicatesTheEdges) {
  Eigen::MatrixXd field(3, 4);
  field << 1, 2, 3, 4,  //
      5, 6, 7, 8,       //
      9, 10, 11, 12;
  Eigen::MatrixXd kernel = Eigen::MatrixXd::Zero(3, 3);
  kernel(0, 1) = 1.0;   // the cell above
  kernel(2, 2) = 10.0;  // the cell below right
  const Eigen::MatrixXd out = Correlate(field, kernel);
  EXPECT_DOUBLE_EQ(out(1, 1), 2 + 10 * 11);
  EXPECT_DOUBLE_EQ(out(0, 0), 1 + 10 * 6);   // above row 0 replicates row 0
  EXPECT_DOUBLE_EQ(out(2, 3), 8 + 10 * 12);  // below-right of the corner is the corner
  // A uniform kernel on a constant field returns the constant everywhere, edges included.
  const Eigen::MatrixXd flat =
      Correlate(Eigen::MatrixXd::Constant(8, 5, 0.3), Eigen::MatrixXd::Constant(5, 5, 1.0 / 25));
  EXPECT_TRUE(flat.isApprox(Eigen::MatrixXd::Constant(8, 5, 0.3), 1e-12));
}

TEST(GridFilters, BadInputIsRejectedWithAClearError) {
  EXPECT_THROW(GaussianKernel1d(-1.0), std::invalid_argument);
  EXPECT_THROW(GaussianKernel1d(kNaN), std::invalid_argument);
  EXPECT_THROW(GaussianKernel1d(1e3), std::invalid_argument);
  const Eigen::MatrixXd heights = Eigen::MatrixXd::Zero(4, 4);
  EXPECT_THROW(SmoothKnown(heights, CellMask::Constant(4, 3, true), 1.0), std::invalid_argument);
  Eigen::MatrixXd nan_known = heights;
  nan_known(2, 2) = kNaN;
  EXPECT_THROW(SmoothKnown(nan_known, CellMask::Constant(4, 4, true), 1.0), std::invalid_argument);
  EXPECT_THROW(FillUnknownWithKnownMean(nan_known, CellMask::Constant(4, 4, true)),
               std::invalid_argument);
  EXPECT_THROW(Correlate(heights, Eigen::MatrixXd::Ones(4, 4)), std::invalid_argument);
  EXPECT_THROW(Correlate(heights, Eigen::MatrixXd(0, 0)), std::invalid_argument);
  EXPECT_THROW(Correlate(nan_known, Eigen::MatrixXd::Ones(3, 3)), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::planning
