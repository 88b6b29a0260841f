#include "runtime/plant/terrain.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace autoshovel::plant {

Terrain::Terrain(const GridGeometry& geometry, double floor_height) : geometry_(geometry) {
  if (!(geometry.resolution > 0) || geometry.nx <= 0 || geometry.ny <= 0) {
    throw std::invalid_argument("Terrain: resolution and cell counts must be positive");
  }
  const std::size_t n = static_cast<std::size_t>(geometry.nx) * geometry.ny;
  height_.assign(n, floor_height);
  floor_.assign(n, floor_height);
  material_.assign(n, kNoMaterial);
}

bool Terrain::CellOf(double x, double y, int& ix, int& iy) const {
  const double fx = (x - geometry_.origin.x()) / geometry_.resolution;
  const double fy = (y - geometry_.origin.y()) / geometry_.resolution;
  if (!(fx >= 0 && fy >= 0 && fx < geometry_.nx && fy < geometry_.ny)) return false;
  ix = static_cast<int>(fx);
  iy = static_cast<int>(fy);
  return true;
}

Eigen::Vector2d Terrain::CellCenter(int ix, int iy) const {
  return geometry_.origin + geometry_.resolution * Eigen::Vector2d(ix + 0.5, iy + 0.5);
}

void Terrain::SetHeight(int ix, int iy, double height) {
  const int i = Index(ix, iy);
  if (height <= floor_[i]) {
    height_[i] = floor_[i];
    material_[i] = kNoMaterial;
  } else {
    height_[i] = height;
  }
}

void Terrain::SetFloor(int ix, int iy, double floor) {
  const int i = Index(ix, iy);
  floor_[i] = floor;
  height_[i] = std::max(height_[i], floor);
}

double Terrain::HeightAt(double x, double y) const {
  const double fx = (x - geometry_.origin.x()) / geometry_.resolution - 0.5;
  const double fy = (y - geometry_.origin.y()) / geometry_.resolution - 0.5;
  if (!(fx >= -0.5 && fy >= -0.5 && fx < geometry_.nx - 0.5 && fy < geometry_.ny - 0.5)) {
    // Outside: the floor of the nearest border cell.
    const int ix = std::clamp(static_cast<int>(std::floor(fx + 0.5)), 0, geometry_.nx - 1);
    const int iy = std::clamp(static_cast<int>(std::floor(fy + 0.5)), 0, geometry_.ny - 1);
    return floor(ix, iy);
  }
  const int x0 = std::clamp(static_cast<int>(std::floor(fx)), 0, geometry_.nx - 1);
  const int y0 = std::clamp(static_cast<int>(std::floor(fy)), 0, geometry_.ny - 1);
  const int x1 = std::min(x0 + 1, geometry_.nx - 1);
  const int y1 = std::min(y0 + 1, geometry_.ny - 1);
  const double tx = std::clamp(fx - x0, 0.0, 1.0);
  const double ty = std::clamp(fy - y0, 0.0, 1.0);
  const double h00 = height(x0, y0), h10 = height(x1, y0);
  const double h01 = height(x0, y1), h11 = height(x1, y1);
  return (1 - ty) * ((1 - tx) * h00 + tx * h10) + ty * ((1 - tx) * h01 + tx * h11);
}

double Terrain::MaterialVolume() const {
  double sum = 0;
  for (std::size_t i = 0; i < height_.size(); ++i) sum += height_[i] - floor_[i];
  return sum * cell_area();
}

double Terrain::MaterialVolume(std::int16_t material) const {
  double sum = 0;
  for (std::size_t i = 0; i < height_.size(); ++i) {
    if (material_[i] == material) sum += height_[i] - floor_[i];
  }
  return sum * cell_area();
}

double Terrain::MaxHeight() const {
  return height_.empty() ? 0.0 : *std::max_element(height_.begin(), height_.end());
}

}  // namespace autoshovel::plant
