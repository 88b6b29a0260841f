#include "runtime/planning/dump/dump_template.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace autoshovel::planning {
namespace {

// 6 cells is the midpoint between the seed's two template sides (5 and 7 cells).
constexpr double kSevenCellThreshold = 6.0;
constexpr int kMinTemplateSize = 3;
constexpr int kMaxTemplateSize = 15;

}  // namespace

int ChooseTemplateSize(double bucket_footprint_m, double cell_size_m) {
  if (!std::isfinite(bucket_footprint_m) || !(bucket_footprint_m > 0) ||
      !std::isfinite(cell_size_m) || !(cell_size_m > 0)) {
    throw std::invalid_argument(
        "ChooseTemplateSize: bucket footprint and cell size must be finite and positive");
  }
  return bucket_footprint_m / cell_size_m < kSevenCellThreshold ? 5 : 7;
}

Eigen::MatrixXd MakeDumpTemplate(DumpTemplateShape shape, int size) {
  if (size % 2 == 0 || size < kMinTemplateSize || size > kMaxTemplateSize) {
    throw std::invalid_argument("MakeDumpTemplate: size must be odd and in [3, 15], got " +
                                std::to_string(size));
  }
  const double n = size;
  switch (shape) {
    case DumpTemplateShape::kFlat:
      return Eigen::MatrixXd::Constant(size, size, -1.0 / (n * n));
    case DumpTemplateShape::kHole: {
      const double inner = n - 2;
      Eigen::MatrixXd weights = Eigen::MatrixXd::Constant(size, size, 1.0 / (4.0 * (n - 1)));
      weights.block(1, 1, size - 2, size - 2).setConstant(-1.0 / (inner * inner));
      return weights;
    }
  }
  throw std::invalid_argument("MakeDumpTemplate: unknown shape");
}

}  // namespace autoshovel::planning
