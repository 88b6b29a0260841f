#include "truck_bed_sim.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace autoshovel::planning::dump_sim {

Eigen::Isometry3d ExampleBedPose() {
  Eigen::Isometry3d T_world_bed = Eigen::Isometry3d::Identity();
  T_world_bed.translate(Eigen::Vector3d(6.5, 4.0, 1.6));
  T_world_bed.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitX()));
  return T_world_bed;
}

SimulatedBed::SimulatedBed(const BedGeometry& bed, double raster_m, double repose_deg)
    : bed_(bed),
      raster_m_(raster_m),
      tan_repose_(std::tan(repose_deg * std::numbers::pi / 180.0)),
      heights_(Eigen::MatrixXd::Zero(static_cast<int>(std::round(bed.length_m / raster_m)),
                                     static_cast<int>(std::round(bed.width_m / raster_m)))) {}

void SimulatedBed::AddCone(const Eigen::Vector2d& p_bed_xy, double peak_m, double radius_m) {
  for (Eigen::Index i = 0; i < heights_.rows(); ++i) {
    for (Eigen::Index j = 0; j < heights_.cols(); ++j) {
      const Eigen::Vector2d c((i + 0.5) * raster_m_, (j + 0.5) * raster_m_);
      const double r = (c - p_bed_xy).norm();
      heights_(i, j) += std::max(0.0, peak_m * (1.0 - r / radius_m));
    }
  }
}

void SimulatedBed::Pour(const Eigen::Vector2d& p_bed_xy, double volume_m3) {
  // A cone at the angle of repose: V = π H³ / (3 tan²α), r = H / tanα.
  const double peak = std::cbrt(3.0 * volume_m3 * tan_repose_ * tan_repose_ / std::numbers::pi);
  Eigen::MatrixXd before = heights_;
  AddCone(p_bed_xy, peak, peak / tan_repose_);
  // Whatever of the cone fell beyond the walls is poured back in proportion, so that each load
  // adds exactly its volume to the bed.
  const double added = (heights_ - before).sum() * raster_m_ * raster_m_;
  if (added > 0) heights_ = before + (heights_ - before) * (volume_m3 / added);
  Settle();
}

void SimulatedBed::Settle() {
  // Sandpile relaxation: between 4-neighbours whose height difference exceeds the repose slope
  // over one raster step, move a quarter of the excess downhill (a quarter: a cell may shed to
  // four neighbours in one sweep without overshooting). Stops when no pair exceeds the slope by
  // more than a millimetre.
  const double max_step = tan_repose_ * raster_m_;
  const Eigen::Index rows = heights_.rows();
  const Eigen::Index cols = heights_.cols();
  for (int sweep = 0; sweep < 20000; ++sweep) {
    double worst = 0;
    for (Eigen::Index i = 0; i < rows; ++i) {
      for (Eigen::Index j = 0; j < cols; ++j) {
        const Eigen::Index neighbours[2][2] = {{i + 1, j}, {i, j + 1}};
        for (const auto& n : neighbours) {
          if (n[0] >= rows || n[1] >= cols) continue;
          double& a = heights_(i, j);
          double& b = heights_(n[0], n[1]);
          const double excess = std::abs(a - b) - max_step;
          if (excess <= 0) continue;
          worst = std::max(worst, excess);
          const double move = 0.25 * excess;
          if (a > b) {
            a -= move;
            b += move;
          } else {
            a += move;
            b -= move;
          }
        }
      }
    }
    if (worst < 1e-3) return;
  }
}

void SimulatedBed::Dig(const Eigen::Vector2d& min_xy, const Eigen::Vector2d& max_xy,
                       double depth_m) {
  for (Eigen::Index i = 0; i < heights_.rows(); ++i) {
    for (Eigen::Index j = 0; j < heights_.cols(); ++j) {
      const Eigen::Vector2d c((i + 0.5) * raster_m_, (j + 0.5) * raster_m_);
      if ((c.array() >= min_xy.array()).all() && (c.array() <= max_xy.array()).all()) {
        heights_(i, j) -= depth_m;
      }
    }
  }
}

void SimulatedBed::Tilt(double slope_x) {
  for (Eigen::Index i = 0; i < heights_.rows(); ++i) {
    heights_.row(i).array() += slope_x * (i + 0.5) * raster_m_;
  }
}

double SimulatedBed::Height(const Eigen::Vector2d& p_bed_xy) const {
  const auto i = std::clamp<Eigen::Index>(static_cast<Eigen::Index>(p_bed_xy.x() / raster_m_), 0,
                                          heights_.rows() - 1);
  const auto j = std::clamp<Eigen::Index>(static_cast<Eigen::Index>(p_bed_xy.y() / raster_m_), 0,
                                          heights_.cols() - 1);
  return heights_(i, j);
}

double SimulatedBed::MeanHeight(const Eigen::Vector2d& p_bed_xy, double side_m) const {
  double sum = 0;
  int count = 0;
  for (Eigen::Index i = 0; i < heights_.rows(); ++i) {
    for (Eigen::Index j = 0; j < heights_.cols(); ++j) {
      const Eigen::Vector2d c((i + 0.5) * raster_m_, (j + 0.5) * raster_m_);
      if (((c - p_bed_xy).array().abs() <= 0.5 * side_m).all()) {
        sum += heights_(i, j);
        ++count;
      }
    }
  }
  return count == 0 ? Height(p_bed_xy) : sum / count;
}

std::vector<Eigen::Vector3d> SimulatedBed::Scan(const Eigen::Isometry3d& T_world_bed,
                                                const ScanConfig& config, std::mt19937& rng) const {
  std::uniform_real_distribution<double> along(0.0, bed_.length_m);
  std::uniform_real_distribution<double> across(0.0, bed_.width_m);
  std::normal_distribution<double> noise(0.0, config.noise_m);
  const int count = static_cast<int>(config.points_per_m2 * bed_.length_m * bed_.width_m);
  std::vector<Eigen::Vector3d> p_world;
  p_world.reserve(count);
  for (int k = 0; k < count; ++k) {
    const Eigen::Vector2d xy(along(rng), across(rng));
    const double z = Height(xy) + noise(rng);
    if (xy.y() < config.occluded_y_m) continue;
    p_world.push_back(T_world_bed * Eigen::Vector3d(xy.x(), xy.y(), z));
  }
  return p_world;
}

BedHeightMap SimulatedBed::Truth() const {
  BedHeightMap truth({raster_m_ * heights_.rows(), raster_m_ * heights_.cols()}, raster_m_);
  for (int i = 0; i < truth.cells_x(); ++i) {
    for (int j = 0; j < truth.cells_y(); ++j) truth.SetHeight(i, j, heights_(i, j));
  }
  return truth;
}

}  // namespace autoshovel::planning::dump_sim
