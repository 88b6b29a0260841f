#include "runtime/planning/dump/bed_height_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace autoshovel::planning {
namespace {

// A guard against a mistyped cell size (1.5 mm instead of 15 cm) allocating gigabytes: a real
// bed at 15 cm is on the order of 500 cells (§4.3).
constexpr double kMaxCells = 1e6;

// Cells along one side. The small slack keeps a side that is a whole number of cells (4.8 m at
// 0.15 m, whose quotient rounds to 32.000000000000004) from gaining an empty sliver cell.
int CellsAlong(double side_m, double cell_size_m) {
  return std::max(1, static_cast<int>(std::ceil(side_m / cell_size_m - 1e-9)));
}

void CheckFinitePositive(double value, const char* what) {
  if (!std::isfinite(value) || !(value > 0)) {
    throw std::invalid_argument(std::string("BedHeightMap: ") + what +
                                " must be finite and positive, got " + std::to_string(value));
  }
}

}  // namespace

BedHeightMap::BedHeightMap(const BedGeometry& bed, double cell_size_m)
    : bed_(bed), cell_size_m_(cell_size_m) {
  CheckFinitePositive(cell_size_m, "cell size");
  CheckFinitePositive(bed.length_m, "bed length");
  CheckFinitePositive(bed.width_m, "bed width");
  const double nx = std::ceil(bed.length_m / cell_size_m);
  const double ny = std::ceil(bed.width_m / cell_size_m);
  if (nx * ny > kMaxCells) {
    throw std::invalid_argument("BedHeightMap: " + std::to_string(nx) + " x " + std::to_string(ny) +
                                " cells is far more than a truck bed needs; check the cell size");
  }
  const int cells_x = CellsAlong(bed.length_m, cell_size_m);
  const int cells_y = CellsAlong(bed.width_m, cell_size_m);
  heights_ = Eigen::MatrixXd::Zero(cells_x, cells_y);
  known_ = CellMask::Constant(cells_x, cells_y, false);
}

BedHeightMap BedHeightMap::FromWorldPoints(const BedGeometry& bed,
                                           const Eigen::Isometry3d& T_world_bed,
                                           std::span<const Eigen::Vector3d> p_world,
                                           const BedHeightMapConfig& config) {
  if (!T_world_bed.matrix().allFinite()) {
    throw std::invalid_argument("BedHeightMap: T_world_bed is not finite");
  }
  const Eigen::Isometry3d T_bed_world = T_world_bed.inverse();
  std::vector<Eigen::Vector3d> p_bed;
  p_bed.reserve(p_world.size());
  for (const Eigen::Vector3d& p : p_world) {
    // Checked here as well so that the message names the frame the caller passed.
    if (!p.allFinite()) throw std::invalid_argument("BedHeightMap: non-finite world point");
    p_bed.push_back(T_bed_world * p);
  }
  return FromBedPoints(bed, p_bed, config);
}

BedHeightMap BedHeightMap::FromBedPoints(const BedGeometry& bed,
                                         std::span<const Eigen::Vector3d> p_bed,
                                         const BedHeightMapConfig& config) {
  if (std::isnan(config.min_height_m) || std::isnan(config.max_height_m)) {
    throw std::invalid_argument("BedHeightMap: height window bounds must not be NaN");
  }
  BedHeightMap map(bed, config.cell_size_m);
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(map.cells_x(), map.cells_y());
  Eigen::MatrixXi count = Eigen::MatrixXi::Zero(map.cells_x(), map.cells_y());
  for (const Eigen::Vector3d& p : p_bed) {
    if (!p.allFinite()) throw std::invalid_argument("BedHeightMap: non-finite bed point");
    if (p.z() < config.min_height_m || p.z() > config.max_height_m) continue;
    const std::optional<Eigen::Vector2i> cell = map.CellOf(p.head<2>());
    if (!cell) continue;  // §4.3: data outside the truck bed is irrelevant to the dump
    const int ix = cell->x();
    const int iy = cell->y();
    if (config.reduction == CellReduction::kMax) {
      sum(ix, iy) = count(ix, iy) == 0 ? p.z() : std::max(sum(ix, iy), p.z());
    } else {
      sum(ix, iy) += p.z();
    }
    ++count(ix, iy);
  }
  for (int ix = 0; ix < map.cells_x(); ++ix) {
    for (int iy = 0; iy < map.cells_y(); ++iy) {
      if (count(ix, iy) == 0) continue;
      map.SetHeight(
          ix, iy,
          config.reduction == CellReduction::kMax ? sum(ix, iy) : sum(ix, iy) / count(ix, iy));
    }
  }
  return map;
}

Eigen::Vector2d BedHeightMap::CellCentre(int ix, int iy) const {
  CheckCell(ix, iy);
  return {(ix + 0.5) * cell_size_m_, (iy + 0.5) * cell_size_m_};
}

std::optional<Eigen::Vector2i> BedHeightMap::CellOf(const Eigen::Vector2d& p_bed_xy) const {
  const double x = p_bed_xy.x();
  const double y = p_bed_xy.y();
  // Written so that NaN compares false and lands outside.
  if (!(x >= 0 && x <= bed_.length_m && y >= 0 && y <= bed_.width_m)) return std::nullopt;
  const int ix = std::min(cells_x() - 1, static_cast<int>(x / cell_size_m_));
  const int iy = std::min(cells_y() - 1, static_cast<int>(y / cell_size_m_));
  return Eigen::Vector2i(ix, iy);
}

void BedHeightMap::SetHeight(int ix, int iy, double height_m) {
  CheckCell(ix, iy);
  if (!std::isfinite(height_m)) {
    throw std::invalid_argument("BedHeightMap: non-finite height for cell (" + std::to_string(ix) +
                                ", " + std::to_string(iy) + ")");
  }
  heights_(ix, iy) = height_m;
  known_(ix, iy) = true;
}

void BedHeightMap::SetUnknown(int ix, int iy) {
  CheckCell(ix, iy);
  heights_(ix, iy) = 0;
  known_(ix, iy) = false;
}

void BedHeightMap::CheckCell(int ix, int iy) const {
  if (ix < 0 || ix >= cells_x() || iy < 0 || iy >= cells_y()) {
    throw std::out_of_range("BedHeightMap: cell (" + std::to_string(ix) + ", " +
                            std::to_string(iy) + ") outside the " + std::to_string(cells_x()) +
                            " x " + std::to_string(cells_y()) + " grid");
  }
}

}  // namespace autoshovel::planning
