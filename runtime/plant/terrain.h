// The yard's ground: a regular height grid with one material per cell, over a hard floor that
// no bucket digs into (the concrete of a mixing station). The plant cuts it, fills buckets from
// it, dumps onto it and relaxes it to the angle of repose; the simulated sensors ray cast it.
//
// Cell (ix, iy) covers [origin.x + ix·r, origin.x + (ix+1)·r) × [origin.y + iy·r, …) in the
// world frame (x east, y north, z up); its height is the surface z at the cell centre [m]. The
// material volume of a cell is (height − floor)·r², so conservation is checked on heights alone.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace autoshovel::plant {

struct GridGeometry {
  double resolution = 0.05;                          ///< cell edge [m]
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  ///< world xy of cell (0, 0)'s corner [m]
  int nx = 0, ny = 0;                                ///< cells along x and y
};

class Terrain {
 public:
  /// Material index of a cell with no material above the floor.
  static constexpr std::int16_t kNoMaterial = -1;

  Terrain() = default;
  /// A flat floor at `floor_height` everywhere, no material.
  Terrain(const GridGeometry& geometry, double floor_height);

  const GridGeometry& geometry() const { return geometry_; }
  double resolution() const { return geometry_.resolution; }
  int nx() const { return geometry_.nx; }
  int ny() const { return geometry_.ny; }
  double cell_area() const { return geometry_.resolution * geometry_.resolution; }

  bool InBounds(int ix, int iy) const { return ix >= 0 && iy >= 0 && ix < nx() && iy < ny(); }
  /// Cell containing world point (x, y); false outside the grid.
  bool CellOf(double x, double y, int& ix, int& iy) const;
  /// World xy of a cell's centre.
  Eigen::Vector2d CellCenter(int ix, int iy) const;

  double height(int ix, int iy) const { return height_[Index(ix, iy)]; }
  double floor(int ix, int iy) const { return floor_[Index(ix, iy)]; }
  std::int16_t material(int ix, int iy) const { return material_[Index(ix, iy)]; }
  /// Material depth above the floor [m].
  double depth(int ix, int iy) const { return height(ix, iy) - floor(ix, iy); }

  /// Sets a cell's surface; a height below the floor is clamped to it (and the material
  /// cleared when nothing is left).
  void SetHeight(int ix, int iy, double height);
  void SetMaterial(int ix, int iy, std::int16_t material) { material_[Index(ix, iy)] = material; }
  void SetFloor(int ix, int iy, double floor);

  /// Surface height at a world point by bilinear interpolation of the cell centres (clamped at
  /// the border); the floor height outside the grid.
  double HeightAt(double x, double y) const;

  /// Total material volume above the floor [m³].
  double MaterialVolume() const;
  /// Material volume above the floor in the cells of one material [m³].
  double MaterialVolume(std::int16_t material) const;

  /// Largest surface height of the whole grid [m] (ray casters bound their march with it).
  double MaxHeight() const;

  const std::vector<double>& heights() const { return height_; }
  const std::vector<double>& floors() const { return floor_; }
  const std::vector<std::int16_t>& materials() const { return material_; }

  int Index(int ix, int iy) const { return iy * geometry_.nx + ix; }

 private:
  GridGeometry geometry_;
  std::vector<double> height_;
  std::vector<double> floor_;
  std::vector<std::int16_t> material_;
};

}  // namespace autoshovel::plant
