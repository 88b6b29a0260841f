// A function sampled at even spacing, made smooth for an optimiser: interpolated by a
// Catmull–Rom cubic (C¹: the slope is continuous, which Ipopt's Newton steps need) and held at
// the end samples' values outside the sampled stretch. Used for the free surface of a pile
// along the line of a scoop (heights every `spacing` metres from `start` along the arm plane)
// and for McKyes' factors over the rake angle.
//
// Why not the plant's height grid itself: its cells are piecewise constant, so the depth of a
// tip moving through them has no useful derivative; the profile sampled along the scoop line is
// the part of it the scoop meets (the optimal scoop is planned in the arm plane).
#pragma once

#include <cmath>
#include <string>
#include <vector>

namespace autoshovel::optimal {

class SampledCurve {
 public:
  SampledCurve() = default;
  /// `heights` at start, start + spacing, … (at least 2, all finite; spacing > 0).
  SampledCurve(double start, double spacing, std::vector<double> heights);

  /// A pile on flat ground: the floor at `ground` up to `toe`, rising at `face_angle` [rad] to
  /// `height` above the floor, flat on top; sampled every `spacing` up to `toe + length`.
  static SampledCurve Ramp(double ground, double toe, double face_angle, double height,
                           double length, double spacing = 0.1);

  /// The value at x (any scalar type: double or ceres::Jet).
  template <typename T>
  T Height(const T& x) const {
    using std::floor;
    const double n = static_cast<double>(heights_.size());
    T u = (x - start_) / spacing_;
    // Outside the samples the surface stays level at the end heights.
    if (u <= 0.0) return T(heights_.front());
    if (u >= n - 1.0) return T(heights_.back());
    int i = static_cast<int>(floor(Value(u)));
    if (i > static_cast<int>(heights_.size()) - 2) i = static_cast<int>(heights_.size()) - 2;
    const T t = u - double(i);
    const double p0 = Sample(i - 1), p1 = Sample(i), p2 = Sample(i + 1), p3 = Sample(i + 2);
    // Catmull–Rom: tangents (p2 − p0)/2 and (p3 − p1)/2 in sample units.
    const double m1 = 0.5 * (p2 - p0), m2 = 0.5 * (p3 - p1);
    const T t2 = t * t, t3 = t2 * t;
    return (2.0 * t3 - 3.0 * t2 + 1.0) * p1 + (t3 - 2.0 * t2 + t) * m1 +
           (-2.0 * t3 + 3.0 * t2) * p2 + (t3 - t2) * m2;
  }

  double start() const { return start_; }
  double spacing() const { return spacing_; }
  double end() const { return start_ + spacing_ * double(heights_.size() - 1); }
  const std::vector<double>& heights() const { return heights_; }

 private:
  double Sample(int i) const {
    const int last = static_cast<int>(heights_.size()) - 1;
    return heights_[i < 0 ? 0 : (i > last ? last : i)];
  }
  static double Value(double v) { return v; }
  template <typename J>
  static double Value(const J& jet) {
    return jet.a;
  }

  double start_ = 0, spacing_ = 0.1;
  std::vector<double> heights_{0.0, 0.0};
};

/// The free surface of a pile along the scoop's line: heights [m] over the distance [m].
using PileProfile = SampledCurve;

}  // namespace autoshovel::optimal
