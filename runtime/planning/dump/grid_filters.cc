#include "runtime/planning/dump/grid_filters.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace autoshovel::planning {
namespace {

// A σ of 50 cells (7.5 m at 15 cm) is already larger than any truck bed; beyond it the request
// is a units mistake, not a filter.
constexpr double kMaxSigmaCells = 50.0;

void CheckKnownField(const Eigen::MatrixXd& heights, const CellMask& known, const char* who) {
  if (heights.rows() != known.rows() || heights.cols() != known.cols()) {
    throw std::invalid_argument(
        std::string(who) + ": heights are " + std::to_string(heights.rows()) + " x " +
        std::to_string(heights.cols()) + " but the mask is " + std::to_string(known.rows()) +
        " x " + std::to_string(known.cols()));
  }
  for (Eigen::Index i = 0; i < heights.rows(); ++i) {
    for (Eigen::Index j = 0; j < heights.cols(); ++j) {
      if (known(i, j) && !std::isfinite(heights(i, j))) {
        throw std::invalid_argument(std::string(who) + ": non-finite height in known cell (" +
                                    std::to_string(i) + ", " + std::to_string(j) + ")");
      }
    }
  }
}

}  // namespace

Eigen::VectorXd GaussianKernel1d(double sigma_cells) {
  if (!std::isfinite(sigma_cells) || sigma_cells < 0 || sigma_cells > kMaxSigmaCells) {
    throw std::invalid_argument("GaussianKernel1d: sigma must be in [0, 50] cells, got " +
                                std::to_string(sigma_cells));
  }
  if (sigma_cells == 0) return Eigen::VectorXd::Ones(1);
  // ±3σ keeps all but 0.3 % of the weight; the renormalisation below gives that back evenly.
  const int radius = static_cast<int>(std::ceil(3.0 * sigma_cells));
  Eigen::VectorXd kernel(2 * radius + 1);
  for (int k = -radius; k <= radius; ++k) {
    kernel(k + radius) = std::exp(-0.5 * (k * k) / (sigma_cells * sigma_cells));
  }
  return kernel / kernel.sum();
}

Eigen::MatrixXd GaussianKernel(double sigma_cells) {
  const Eigen::VectorXd g = GaussianKernel1d(sigma_cells);
  const Eigen::MatrixXd kernel = g * g.transpose();
  return kernel / kernel.sum();
}

Eigen::MatrixXd SmoothKnown(const Eigen::MatrixXd& heights, const CellMask& known,
                            double sigma_cells) {
  CheckKnownField(heights, known, "SmoothKnown");
  const Eigen::MatrixXd kernel = GaussianKernel(sigma_cells);
  const int radius = static_cast<int>(kernel.rows() / 2);
  const Eigen::Index rows = heights.rows();
  const Eigen::Index cols = heights.cols();
  Eigen::MatrixXd smoothed = Eigen::MatrixXd::Zero(rows, cols);
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (Eigen::Index j = 0; j < cols; ++j) {
      if (!known(i, j)) continue;
      double weighted = 0;
      double weight = 0;
      for (int a = -radius; a <= radius; ++a) {
        for (int b = -radius; b <= radius; ++b) {
          const Eigen::Index u = i + a;
          const Eigen::Index v = j + b;
          if (u < 0 || u >= rows || v < 0 || v >= cols || !known(u, v)) continue;
          const double w = kernel(a + radius, b + radius);
          weighted += w * heights(u, v);
          weight += w;
        }
      }
      // The cell itself is known and carries the kernel's largest weight, so weight > 0.
      smoothed(i, j) = weighted / weight;
    }
  }
  return smoothed;
}

double KnownMean(const Eigen::MatrixXd& heights, const CellMask& known) {
  CheckKnownField(heights, known, "KnownMean");
  double sum = 0;
  long count = 0;
  for (Eigen::Index i = 0; i < heights.rows(); ++i) {
    for (Eigen::Index j = 0; j < heights.cols(); ++j) {
      if (!known(i, j)) continue;
      sum += heights(i, j);
      ++count;
    }
  }
  return count == 0 ? 0.0 : sum / static_cast<double>(count);
}

Eigen::MatrixXd FillUnknownWithKnownMean(const Eigen::MatrixXd& heights, const CellMask& known) {
  const double mean = KnownMean(heights, known);  // checks sizes and finiteness
  return known.select(heights, Eigen::MatrixXd::Constant(heights.rows(), heights.cols(), mean));
}

Eigen::MatrixXd Correlate(const Eigen::MatrixXd& field, const Eigen::MatrixXd& kernel) {
  if (kernel.size() == 0 || kernel.rows() % 2 == 0 || kernel.cols() % 2 == 0) {
    throw std::invalid_argument("Correlate: the kernel must be non-empty with odd sides, got " +
                                std::to_string(kernel.rows()) + " x " +
                                std::to_string(kernel.cols()));
  }
  if (!kernel.allFinite() || !field.allFinite()) {
    throw std::invalid_argument("Correlate: non-finite value in the field or the kernel");
  }
  const Eigen::Index rows = field.rows();
  const Eigen::Index cols = field.cols();
  const Eigen::Index ra = kernel.rows() / 2;
  const Eigen::Index rb = kernel.cols() / 2;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(rows, cols);
  if (field.size() == 0) return out;
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (Eigen::Index j = 0; j < cols; ++j) {
      double sum = 0;
      for (Eigen::Index a = 0; a < kernel.rows(); ++a) {
        const Eigen::Index u = std::clamp<Eigen::Index>(i + a - ra, 0, rows - 1);
        for (Eigen::Index b = 0; b < kernel.cols(); ++b) {
          const Eigen::Index v = std::clamp<Eigen::Index>(j + b - rb, 0, cols - 1);
          sum += kernel(a, b) * field(u, v);
        }
      }
      out(i, j) = sum;
    }
  }
  return out;
}

}  // namespace autoshovel::planning
