#include "runtime/perception/grid_map.h"

#include <cmath>
#include <stdexcept>

namespace autoshovel::perception {

GridMap::GridMap(double resolution, const Eigen::Vector2d& length, const Eigen::Vector2d& position)
    : resolution_(resolution), position_(position) {
  if (!(resolution > 0) || !(length.array() > 0).all()) {
    throw std::invalid_argument("GridMap: resolution and length must be positive");
  }
  size_ = (length.array() / resolution).round().cast<int>().max(1);
}

void GridMap::Add(const std::string& layer, float value) {
  layers_[layer] = Eigen::MatrixXf::Constant(size_.x(), size_.y(), value);
  fill_[layer] = value;
}

Eigen::MatrixXf& GridMap::operator[](const std::string& layer) {
  const auto it = layers_.find(layer);
  if (it == layers_.end()) throw std::out_of_range("GridMap: no layer '" + layer + "'");
  return it->second;
}

const Eigen::MatrixXf& GridMap::operator[](const std::string& layer) const {
  const auto it = layers_.find(layer);
  if (it == layers_.end()) throw std::out_of_range("GridMap: no layer '" + layer + "'");
  return it->second;
}

std::vector<std::string> GridMap::layers() const {
  std::vector<std::string> names;
  for (const auto& [name, data] : layers_) names.push_back(name);
  return names;
}

bool GridMap::IndexOf(const Eigen::Vector2d& position, Index& index) const {
  const Eigen::Array2d corner = position_.array() - 0.5 * length().array();
  const Eigen::Array2d f = (position.array() - corner) / resolution_;
  if (!(f >= 0).all() || !(f < size_.cast<double>()).all()) return false;
  index = f.floor().cast<int>();
  return true;
}

Eigen::Vector2d GridMap::PositionOf(const Index& index) const {
  const Eigen::Array2d corner = position_.array() - 0.5 * length().array();
  return (corner + (index.cast<double>() + 0.5) * resolution_).matrix();
}

bool GridMap::IsInside(const Eigen::Vector2d& position) const {
  Index index;
  return IndexOf(position, index);
}

Index GridMap::Move(const Eigen::Vector2d& position) {
  const Index shift = ((position - position_).array() / resolution_).round().cast<int>();
  if ((shift == 0).all()) return shift;
  for (auto& [name, data] : layers_) {
    Eigen::MatrixXf moved = Eigen::MatrixXf::Constant(size_.x(), size_.y(), fill_[name]);
    // New cell (ix, iy) is old cell (ix + shift.x, iy + shift.y).
    const int x0 = std::max(0, -shift.x()), x1 = std::min(size_.x(), size_.x() - shift.x());
    const int y0 = std::max(0, -shift.y()), y1 = std::min(size_.y(), size_.y() - shift.y());
    if (x1 > x0 && y1 > y0) {
      moved.block(x0, y0, x1 - x0, y1 - y0) =
          data.block(x0 + shift.x(), y0 + shift.y(), x1 - x0, y1 - y0);
    }
    data.swap(moved);
  }
  position_ += shift.cast<double>().matrix() * resolution_;
  return shift;
}

}  // namespace autoshovel::perception
