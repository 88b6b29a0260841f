// A 2.5D grid map in the style of ANYbotics' grid_map (Fankhauser & Hutter 2016): named float
// layers over one regular grid, world ↔ index conversion, cell iteration, and a map that moves
// with the machine. Written here rather than taken from grid_map because that library is a ROS
// package (not in Debian) and the part needed is small; the API keeps its vocabulary so that a
// user of grid_map reads this at once.
//
// Index (ix, iy): ix along world x, iy along world y; cell (0, 0) has the smallest x and y. The
// map is centred on `position()`; a layer is an Eigen matrix indexed (ix, iy). Unknown is NaN.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace autoshovel::perception {

using Index = Eigen::Array2i;

class GridMap {
 public:
  GridMap() = default;
  /// A map of `length` (x, y) metres centred on `position`, cells of `resolution` metres.
  GridMap(double resolution, const Eigen::Vector2d& length, const Eigen::Vector2d& position);

  double resolution() const { return resolution_; }
  const Eigen::Array2i& size() const { return size_; }  ///< cells along x and y
  Eigen::Vector2d length() const { return size_.cast<double>() * resolution_; }
  const Eigen::Vector2d& position() const { return position_; }  ///< centre, world [m]

  /// Adds a layer filled with `value` (replaces an existing one of that name).
  void Add(const std::string& layer, float value = std::numeric_limits<float>::quiet_NaN());
  bool Exists(const std::string& layer) const { return layers_.count(layer) != 0; }
  /// Throws std::out_of_range naming the layer if it does not exist.
  Eigen::MatrixXf& operator[](const std::string& layer);
  const Eigen::MatrixXf& operator[](const std::string& layer) const;
  std::vector<std::string> layers() const;

  float& at(const std::string& layer, const Index& index) {
    return (*this)[layer](index.x(), index.y());
  }
  float at(const std::string& layer, const Index& index) const {
    return (*this)[layer](index.x(), index.y());
  }

  /// World xy → the cell containing it; false outside the map.
  bool IndexOf(const Eigen::Vector2d& position, Index& index) const;
  /// Centre of a cell in the world.
  Eigen::Vector2d PositionOf(const Index& index) const;
  bool IsInside(const Eigen::Vector2d& position) const;
  bool IsValid(const Index& index) const { return (index >= 0).all() && (index < size_).all(); }

  /// Moves the map so that its centre is near `position` (by whole cells, so that cell
  /// boundaries stay where they are in the world); data of cells still inside is kept, cells
  /// that enter the map take each layer's fill value. Returns the shift in cells.
  Index Move(const Eigen::Vector2d& position);

  /// All cells, ix fastest: `for (GridMapIterator it(map); !it.done(); ++it) map.at(l, *it)`.
  class Iterator {
   public:
    explicit Iterator(const GridMap& map) : size_(map.size()) {}
    const Index& operator*() const { return index_; }
    Iterator& operator++() {
      if (++index_.x() >= size_.x()) index_.x() = 0, ++index_.y();
      return *this;
    }
    bool done() const { return index_.y() >= size_.y(); }

   private:
    Index size_;
    Index index_ = Index::Zero();
  };

 private:
  double resolution_ = 0.3;
  Eigen::Array2i size_ = Eigen::Array2i::Zero();
  Eigen::Vector2d position_ = Eigen::Vector2d::Zero();
  std::map<std::string, Eigen::MatrixXf> layers_;
  std::map<std::string, float> fill_;
};

using GridMapIterator = GridMap::Iterator;

}  // namespace autoshovel::perception
