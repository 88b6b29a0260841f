// Shovel point selection: wheel-loader seed §5, Algorithm 2 and Eq. (12)–(18). The readings of
// what the seed leaves open are listed in shovel_point_selection.h and argued where they are
// implemented below.
#include "runtime/planning/shovel_point_selection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>

#include "runtime/perception/semantic_map.h"

namespace autoshovel::planning {

using perception::CellClass;
using perception::GridMap;
using perception::Index;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Eigen::Vector2d Direction(double heading) { return {std::cos(heading), std::sin(heading)}; }

bool IsClass(const GridMap& map, const Index& i, CellClass c) {
  return map.at("class", i) == static_cast<float>(c);
}

double GroundZ(const Eigen::Vector3d& plane, const Eigen::Vector2d& xy) {
  return plane.x() * xy.x() + plane.y() * xy.y() + plane.z();
}

// A convex polygon of at most 8 vertices: a map cell clipped by up to four half-planes.
struct SmallPolygon {
  std::array<Eigen::Vector2d, 8> p;
  int n = 0;
};

// Sutherland–Hodgman against one half-plane {x : x·normal ≤ offset}. Hand-written rather than
// Boost.Geometry or cv::intersectConvexConvex: it runs for every cell of every candidate's Ω at
// 7 Hz, on squares against parallel strips, where these dozen lines need no allocation.
SmallPolygon ClipHalfPlane(const SmallPolygon& in, const Eigen::Vector2d& normal, double offset) {
  SmallPolygon out;
  for (int k = 0; k < in.n; ++k) {
    const Eigen::Vector2d& a = in.p[k];
    const Eigen::Vector2d& b = in.p[(k + 1) % in.n];
    const double da = a.dot(normal) - offset, db = b.dot(normal) - offset;
    if (da <= 0) out.p[out.n++] = a;
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) out.p[out.n++] = a + (b - a) * (da / (da - db));
  }
  return out;
}

// Area and centroid of a convex polygon (shoelace); area 0 for fewer than three vertices.
double AreaAndCentroid(const SmallPolygon& poly, Eigen::Vector2d* centroid) {
  double twice_area = 0;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int k = 0; k < poly.n; ++k) {
    const Eigen::Vector2d& a = poly.p[k];
    const Eigen::Vector2d& b = poly.p[(k + 1) % poly.n];
    const double cross = a.x() * b.y() - a.y() * b.x();
    twice_area += cross;
    sum += (a + b) * cross;
  }
  if (std::abs(twice_area) < 1e-15) return 0.0;
  *centroid = sum / (3 * twice_area);
  return 0.5 * std::abs(twice_area);
}

// Visits every map cell that overlaps the band ahead of `entry` along `heading` with
// along ∈ [−ε/2, length] and λ ∈ [lambda_min, lambda_max] (λ left of the centre line, in the
// frame of `entry`), with the exact area of the overlap [m²] and the λ of its centroid [m]:
// f(index, area, λ_centroid). Cells count by their share of area, not by where their centres
// fall: on a 0.3 m grid the 1 m sections of a 3 m bucket (Eq. 15) hold three or four cell
// centres depending on where the entry lies, which made the middle section of a level face a
// quarter lighter than its sides and every point of a straight pile front "concave".
template <typename F>
void ForEachCellOverlap(const GridMap& map, const Eigen::Vector2d& entry, double heading,
                        double length, double lambda_min, double lambda_max, F&& f) {
  const Eigen::Vector2d u = Direction(heading), v(-u.y(), u.x());
  const double r = map.resolution();
  const double back = r / 2;
  Eigen::Vector2d lo = entry, hi = entry;
  for (const double a : {-back, length}) {
    for (const double l : {lambda_min, lambda_max}) {
      const Eigen::Vector2d corner = entry + a * u + l * v;
      lo = lo.cwiseMin(corner);
      hi = hi.cwiseMax(corner);
    }
  }
  const Eigen::Vector2d origin = map.position() - map.length() / 2;
  const int x0 = std::max(0, static_cast<int>(std::floor((lo.x() - origin.x()) / r)));
  const int y0 = std::max(0, static_cast<int>(std::floor((lo.y() - origin.y()) / r)));
  const int x1 =
      std::min(map.size().x() - 1, static_cast<int>(std::floor((hi.x() - origin.x()) / r)));
  const int y1 =
      std::min(map.size().y() - 1, static_cast<int>(std::floor((hi.y() - origin.y()) / r)));
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) {
      const Index index(ix, iy);
      // The cell in the frame of the entry: x along the heading, y = λ.
      const Eigen::Vector2d c = map.PositionOf(index) - entry;
      SmallPolygon cell;
      cell.n = 4;
      int k = 0;
      for (const auto& [sx, sy] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        const Eigen::Vector2d corner = c + 0.5 * r * Eigen::Vector2d(sx, sy);
        cell.p[k++] = {corner.dot(u), corner.dot(v)};
      }
      SmallPolygon piece = ClipHalfPlane(cell, {-1, 0}, back);
      piece = ClipHalfPlane(piece, {1, 0}, length);
      piece = ClipHalfPlane(piece, {0, -1}, -lambda_min);
      piece = ClipHalfPlane(piece, {0, 1}, lambda_max);
      Eigen::Vector2d centroid;
      const double area = AreaAndCentroid(piece, &centroid);
      if (area > 1e-12 * r * r) f(index, area, centroid.y());
    }
  }
}

// Bilinear interpolation of a cell-centred field at a world point (clamped at the border).
double Interpolate(const GridMap& map, const Eigen::MatrixXf& field, const Eigen::Vector2d& xy) {
  const double r = map.resolution();
  const Eigen::Vector2d origin = map.position() - map.length() / 2;
  const double fx = std::clamp((xy.x() - origin.x()) / r - 0.5, 0.0, map.size().x() - 1.0);
  const double fy = std::clamp((xy.y() - origin.y()) / r - 0.5, 0.0, map.size().y() - 1.0);
  const int ix = std::min(static_cast<int>(fx), map.size().x() - 2 < 0 ? 0 : map.size().x() - 2);
  const int iy = std::min(static_cast<int>(fy), map.size().y() - 2 < 0 ? 0 : map.size().y() - 2);
  const int jx = std::min(ix + 1, map.size().x() - 1), jy = std::min(iy + 1, map.size().y() - 1);
  const double tx = fx - ix, ty = fy - iy;
  const double a = field(ix, iy), b = field(jx, iy), c = field(ix, jy), d = field(jx, jy);
  if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(c) || !std::isfinite(d)) {
    return std::min({a, b, c, d});  // +inf (no obstacle anywhere) stays +inf
  }
  return (1 - ty) * ((1 - tx) * a + tx * b) + ty * ((1 - tx) * c + tx * d);
}

// Squared 1-D distance transform of f (Felzenszwalb & Huttenlocher 2012), in cells².
void DistanceTransform1d(std::vector<double>& f) {
  const int n = static_cast<int>(f.size());
  std::vector<double> d(n), z(n + 1);
  std::vector<int> v(n);
  int k = 0;
  v[0] = 0;
  z[0] = -kInf;
  z[1] = kInf;
  for (int q = 1; q < n; ++q) {
    if (!std::isfinite(f[q])) continue;
    if (!std::isfinite(f[v[k]])) {  // no finite parabola yet: this one starts the envelope
      v[k] = q;
      continue;
    }
    double s = ((f[q] + q * q) - (f[v[k]] + v[k] * v[k])) / (2.0 * q - 2.0 * v[k]);
    while (s <= z[k]) {
      --k;
      s = ((f[q] + q * q) - (f[v[k]] + v[k] * v[k])) / (2.0 * q - 2.0 * v[k]);
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = kInf;
  }
  if (!std::isfinite(f[v[0]])) return;  // all infinite
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    d[q] = (q - v[k]) * (q - v[k]) + f[v[k]];
  }
  f = d;
}

// The pile height above ground of every cell (0 where not pile or unknown).
Eigen::MatrixXf PileHeightField(const GridMap& map, const Eigen::Vector3d& plane) {
  Eigen::MatrixXf h = Eigen::MatrixXf::Zero(map.size().x(), map.size().y());
  for (perception::GridMapIterator it(map); !it.done(); ++it) {
    h((*it).x(), (*it).y()) = static_cast<float>(PileHeightAboveGround(map, plane, *it));
  }
  return h;
}

// True if a tyre contact or the chassis' centre line stands on pile higher than the limit
// anywhere along the path. The bucket is excepted: it is meant to meet the pile.
bool DrivesOverPile(const GridMap& map, const Eigen::MatrixXf& pile_height,
                    const std::vector<PathSample>& samples, const LoaderGeometry& loader,
                    double limit) {
  const double half_track = loader.track_width / 2;
  for (const PathSample& p : samples) {
    const double gamma = loader.ArticulationFor(p.curvature);
    const Eigen::Vector2d u_front = Direction(p.heading);
    const Eigen::Vector2d hinge = p.xy - loader.hinge_to_front_axle * u_front;
    const Eigen::Vector2d u_rear = Direction(p.heading - gamma);
    const Eigen::Vector2d n_front(-u_front.y(), u_front.x()), n_rear(-u_rear.y(), u_rear.x());
    const Eigen::Vector2d rear_axle = hinge - loader.hinge_to_rear_axle * u_rear;
    auto high = [&](const Eigen::Vector2d& xy) {
      Index i;
      return map.IndexOf(xy, i) && pile_height(i.x(), i.y()) > limit;
    };
    if (high(hinge)) return true;
    for (const double side : {-half_track, 0.0, half_track}) {
      for (const double fore : {-loader.wheel_radius, 0.0, loader.wheel_radius}) {
        if (high(p.xy + fore * u_front + side * n_front)) return true;
        if (high(rear_axle + fore * u_rear + side * n_rear)) return true;
      }
    }
  }
  return false;
}

// The inward normal of the pile at a front point: from the ground cells around it towards the
// pile cells around it (means within `radius`). Falls back on the direction to the centroid.
double InwardNormal(const GridMap& map, const Eigen::Vector2d& xy, double radius,
                    const Eigen::Vector2d& centroid) {
  Eigen::Vector2d pile_sum = Eigen::Vector2d::Zero(), ground_sum = Eigen::Vector2d::Zero();
  int pile_n = 0, ground_n = 0;
  const int reach = static_cast<int>(std::ceil(radius / map.resolution()));
  Index c;
  if (map.IndexOf(xy, c)) {
    for (int dy = -reach; dy <= reach; ++dy) {
      for (int dx = -reach; dx <= reach; ++dx) {
        const Index i(c.x() + dx, c.y() + dy);
        if (!map.IsValid(i)) continue;
        const Eigen::Vector2d p = map.PositionOf(i);
        if ((p - xy).norm() > radius) continue;
        if (IsClass(map, i, CellClass::kPile)) pile_sum += p, ++pile_n;
        if (IsClass(map, i, CellClass::kGround)) ground_sum += p, ++ground_n;
      }
    }
  }
  Eigen::Vector2d n = centroid - xy;
  if (pile_n > 0 && ground_n > 0) {
    const Eigen::Vector2d d = pile_sum / pile_n - ground_sum / ground_n;
    if (d.norm() > 1e-9) n = d;
  }
  return std::atan2(n.y(), n.x());
}

}  // namespace

// --- LoaderGeometry ---

double LoaderGeometry::MaxCurvature() const {
  return std::sin(max_articulation) /
         (hinge_to_front_axle * std::cos(max_articulation) + hinge_to_rear_axle);
}

double LoaderGeometry::ArticulationFor(double curvature) const {
  // κ (l_f cos γ + l_r) = sin γ  ⇔  A sin(γ − φ) = κ l_r with A = √(1 + κ² l_f²), φ = atan(κ l_f).
  const double lf = hinge_to_front_axle, lr = hinge_to_rear_axle;
  const double a = std::sqrt(1 + curvature * curvature * lf * lf);
  const double phi = std::atan(curvature * lf);
  return phi + std::asin(std::clamp(curvature * lr / a, -1.0, 1.0));
}

double LoaderGeometry::HalfWidth() const {
  // Tyres stand out about a third of their radius beyond the track on each side.
  return std::max(bucket_width, track_width + 0.66 * wheel_radius) / 2 + body_margin;
}

LoaderGeometry LoaderGeometryFrom(const model::MachineDescription& machine,
                                  const generated::MachineFunctions& functions) {
  if (machine.links.size() != 2 || machine.bucket.profile.size() < 2 || functions.num_links != 2 ||
      functions.num_angles != 3) {
    throw std::invalid_argument("LoaderGeometryFrom: " + machine.name +
                                " is not a two-link wheel loader with a bucket profile");
  }
  LoaderGeometry g;
  g.hinge_to_front_axle = machine.chassis.hinge_to_front_axle;
  g.hinge_to_rear_axle = machine.chassis.hinge_to_rear_axle;
  g.max_articulation = machine.chassis.max_articulation;
  g.track_width = machine.chassis.track_width;
  g.wheel_radius = machine.chassis.wheel_radius;
  g.bucket_width = machine.bucket.width;
  g.rated_capacity = machine.bucket.rated_capacity;
  // Bucket level on the floor, as when approaching a pile (the plant's BucketOnFloor: the floor
  // edge of the profile horizontal, the tip 5 cm up), then Eq. (2) through the generated code.
  const Eigen::Vector2d floor = machine.bucket.profile[1] - machine.bucket.profile[0];
  const double phi_bucket =
      std::remainder(std::numbers::pi - std::atan2(floor.y(), floor.x()), 2 * std::numbers::pi);
  const double l1 = machine.links[0].length, l2 = machine.links[1].length;
  const double sin_boom = (0.05 - machine.arm_pivot.y() - l2 * std::sin(phi_bucket)) / l1;
  if (std::abs(sin_boom) > 1) {
    throw std::invalid_argument("LoaderGeometryFrom: " + machine.name + " cannot reach the floor");
  }
  const double boom = std::asin(sin_boom);
  // IMU angles (Eq. 1 with the nominal offsets α_k, level chassis): θ_k = φ_k − α_k.
  const double* params = functions.nominal_params;  // l1, l2, α1, α2
  const double angles[3] = {0.0, boom - params[2], phi_bucket - params[3]};
  double pose[4];
  functions.forward_kinematics(angles, params, pose);
  g.tip_reach = pose[0];
  return g;
}

// --- Config ---

std::string ShovelPointConfig::Validate() const {
  for (const auto& [name, k] : {std::pair{"k_t", k_t}, std::pair{"k_s", k_s}, std::pair{"k_c", k_c},
                                std::pair{"k_e", k_e}, std::pair{"k_a", k_a}}) {
    if (!(k >= 0) || !std::isfinite(k)) {
      return std::string(name) + " must be a finite weight >= 0, got " + std::to_string(k);
    }
  }
  if (!(safety_distance > 0)) {
    return "safety_distance (d_res) must be > 0 m, got " + std::to_string(safety_distance);
  }
  if (!(candidate_spacing > 0)) {
    return "candidate_spacing must be > 0 m, got " + std::to_string(candidate_spacing);
  }
  if (entry_angle_offsets.empty()) return "entry_angle_offsets must not be empty";
  for (const double a : entry_angle_offsets) {
    if (!(std::abs(a) < std::numbers::pi / 2)) {
      return "entry_angle_offsets must lie within (-90, 90) deg, got " + std::to_string(a) + " rad";
    }
  }
  if (!(normal_radius > 0)) return "normal_radius must be > 0 m";
  if (!(penetration_length > 0)) return "penetration_length must be > 0 m";
  if (!(scoop_advance >= 0) || !std::isfinite(scoop_advance)) {
    return "scoop_advance must be a finite length >= 0 m, got " + std::to_string(scoop_advance);
  }
  if (!(crowd_stop_distance >= 0) || !std::isfinite(crowd_stop_distance)) {
    return "crowd_stop_distance must be a finite length >= 0 m, got " +
           std::to_string(crowd_stop_distance);
  }
  if (!(concavity_tolerance >= 0 && concavity_tolerance < 1)) {
    return "concavity_tolerance must be in [0, 1), got " + std::to_string(concavity_tolerance);
  }
  if (!(entry_window > 0)) return "entry_window must be > 0 m";
  if (!(path_spacing > 0)) return "path_spacing must be > 0 m";
  if (!(max_drive_over_height >= 0)) return "max_drive_over_height must be >= 0 m";
  if (std::isnan(torque_threshold) || std::isnan(max_curvature)) {
    return "torque_threshold and max_curvature must not be NaN";
  }
  return "";
}

// --- The equations ---

double PileHeightAboveGround(const GridMap& map, const Eigen::Vector3d& plane, const Index& i) {
  const float z = map.at("elevation", i);
  if (std::isnan(z) || !IsClass(map, i, CellClass::kPile)) return 0.0;
  return std::max(0.0, z - GroundZ(plane, map.PositionOf(i)));
}

double TorqueMoment(const GridMap& map, const Eigen::Vector3d& plane, const Eigen::Vector2d& entry,
                    double heading, double width, double length) {
  // Eq. (12): T_c = Σ_{i,j∈Ω} h_ij λ_i; each cell weighted by its area in Ω (a first moment of
  // volume about the bucket's centre line, left positive; λ of the part of the cell inside).
  double torque = 0;
  ForEachCellOverlap(map, entry, heading, length, -width / 2, width / 2,
                     [&](const Index& i, double area, double lambda) {
                       torque += PileHeightAboveGround(map, plane, i) * lambda * area;
                     });
  return torque;
}

double TorqueScore(double torque, double threshold) {
  // Eq. (13), |T_c| against T_res (the seed writes T_c < T_res for a signed T_c).
  if (!(std::abs(torque) < threshold)) return kMinusInfinity;
  const double ratio = torque / threshold;
  return 1 - ratio * ratio;
}

double SafetyScore(double d_min, double d_res) {
  // Eq. (14).
  if (d_min > d_res) return 1.0;
  if (d_min > 0) return d_min / d_res;
  return kMinusInfinity;
}

SectionVolumes ConcavityVolumes(const GridMap& map, const Eigen::Vector3d& plane,
                                const Eigen::Vector2d& entry, double heading, double width,
                                double length) {
  // Eq. (15)'s three-section bucket model: the future shoveling area split evenly by the bucket
  // width into left (λ > w/6), middle and right (λ < −w/6) strips.
  SectionVolumes v;
  const std::array<std::pair<double*, double>, 3> sections = {
      std::pair{&v.right, -width / 2}, {&v.middle, -width / 6}, {&v.left, width / 6}};
  for (const auto& [volume, lambda_min] : sections) {
    ForEachCellOverlap(map, entry, heading, length, lambda_min, lambda_min + width / 3,
                       [&, volume = volume](const Index& i, double area, double) {
                         *volume += PileHeightAboveGround(map, plane, i) * area;
                       });
  }
  return v;
}

double ConcavityScore(const SectionVolumes& v, double tolerance) {
  // Eq. (15): convex (1) if V_m ≥ max{V_l, V_r}, concave (0) otherwise; "≥" within the
  // relative tolerance.
  const double side = std::max(v.left, v.right);
  return v.middle >= (1 - tolerance) * side ? 1.0 : 0.0;
}

double EfficiencyScore(double length, double min_length, double max_length) {
  // Eq. (16).
  if (!(max_length - min_length > 1e-12)) return 1.0;
  return (max_length - length) / (max_length - min_length);
}

double EntryAngleScore(double curvature, double max_curvature) {
  // Eq. (17).
  return 1 - std::abs(curvature) / max_curvature;
}

double WeightedScore(const ScoreBreakdown& s, const ShovelPointConfig& c) {
  // Eq. (18). A −∞ score vetoes the candidate whatever its weight (Algorithm 2's thresholds).
  for (const double x : {s.s_t, s.s_s, s.s_c, s.s_e, s.s_a}) {
    if (x == kMinusInfinity) return kMinusInfinity;
  }
  return c.k_t * s.s_t + c.k_s * s.s_s + c.k_c * s.s_c + c.k_e * s.s_e + c.k_a * s.s_a;
}

double EntryCurvature(const std::vector<PathSample>& samples, double window) {
  // κ_im of Eq. (17): mean |κ| over the last `window` metres (trapezoid rule on the samples;
  // the curvature is piecewise constant, so the rule is exact up to the sample spacing).
  if (samples.size() < 2) return samples.empty() ? 0.0 : std::abs(samples.back().curvature);
  const double end = samples.back().s, from = std::max(0.0, end - window);
  double integral = 0, covered = 0;
  for (std::size_t k = 1; k < samples.size(); ++k) {
    const double a = std::max(samples[k - 1].s, from), b = samples[k].s;
    if (b <= a) continue;
    // Each interval takes the curvature of its start (the segment it lies in).
    integral += std::abs(samples[k - 1].curvature) * (b - a);
    covered += b - a;
  }
  return covered > 0 ? integral / covered : std::abs(samples.back().curvature);
}

Eigen::MatrixXf ObstacleDistanceField(const GridMap& map) {
  const int nx = map.size().x(), ny = map.size().y();
  Eigen::MatrixXd f(nx, ny);
  bool any = false;
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const bool obstacle = IsClass(map, Index(ix, iy), CellClass::kObstacle);
      f(ix, iy) = obstacle ? 0.0 : kInf;
      any |= obstacle;
    }
  }
  Eigen::MatrixXf out(nx, ny);
  if (!any) {
    out.setConstant(std::numeric_limits<float>::infinity());
    return out;
  }
  std::vector<double> line;
  for (int iy = 0; iy < ny; ++iy) {
    line.assign(nx, 0);
    for (int ix = 0; ix < nx; ++ix) line[ix] = f(ix, iy);
    DistanceTransform1d(line);
    for (int ix = 0; ix < nx; ++ix) f(ix, iy) = line[ix];
  }
  for (int ix = 0; ix < nx; ++ix) {
    line.assign(ny, 0);
    for (int iy = 0; iy < ny; ++iy) line[iy] = f(ix, iy);
    DistanceTransform1d(line);
    for (int iy = 0; iy < ny; ++iy) {
      out(ix, iy) = static_cast<float>(std::sqrt(line[iy]) * map.resolution());
    }
  }
  return out;
}

namespace {

// The least distance field along segments of the loader's outline. The distance from a
// rectangle to the obstacle cells outside it is the least distance field on its outline; the
// field is sampled every `step`, so the least sample overestimates it by at most step / 2, which
// `correction` takes off, and half a cell more (the field is between cell centres; an obstacle
// fills its cell). An obstacle inside a rectangle crossed its outline at an earlier pose of the
// sweep (poses a path spacing apart, outline samples a fraction of a cell apart): the swept
// minimum sees it there. (Discs along the centre line, the usual shortcut, either miss the
// corners or reach far beyond the ends: at a bin's mouth both errors matter.)
class OutlineProbe {
 public:
  OutlineProbe(const GridMap& map, const Eigen::MatrixXf& field, double cap)
      : map_(map), field_(field), step_(std::min(0.1, map.resolution())) {
    correction_ = step_ / 2 + map.resolution() / 2;
    // Work in the field's units: exact below the cap.
    d_min_ = std::isfinite(cap) ? cap + correction_ : kInf;
  }

  /// The rectangle [from, to] × [−hw, hw] in the axes (u, n) at `origin`, whole.
  void Rectangle(const Eigen::Vector2d& origin, const Eigen::Vector2d& u, double from, double to,
                 double hw) {
    // The field changes by at most the distance moved (plus a cell's interpolation slack): a
    // rectangle whose centre lies farther than its half diagonal beyond the least distance so
    // far cannot lower it. Most poses of a path are skipped so.
    if (Far(origin + (from + to) / 2 * u, std::hypot((to - from) / 2, hw))) return;
    const Eigen::Vector2d n(-u.y(), u.x());
    const Eigen::Vector2d corners[4] = {origin + from * u - hw * n, origin + to * u - hw * n,
                                        origin + to * u + hw * n, origin + from * u + hw * n};
    for (int e = 0; e < 4; ++e) Segment(corners[e], corners[(e + 1) % 4]);
  }

  /// One straight piece of outline.
  void Segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    // In pieces of at most 1 m, each in sub-pieces of at most `step`, sampled at their middles
    // (every point within step / 2 of a sample). A piece whose middle lies farther than half
    // its length beyond the least distance so far is skipped whole, by the bound above.
    const double length = (b - a).norm();
    const int pieces = std::max(1, static_cast<int>(std::ceil(length / 1.0)));
    const int subs = std::max(1, static_cast<int>(std::ceil(length / pieces / step_)));
    for (int p = 0; p < pieces; ++p) {
      if (Far(a + (b - a) * ((p + 0.5) / pieces), length / pieces / 2)) continue;
      for (int k = 0; k < subs; ++k) {
        const double t = (p + (k + 0.5) / subs) / pieces;
        d_min_ = std::min(d_min_, Interpolate(map_, field_, a + (b - a) * t));
      }
    }
  }

  bool Touching() const { return d_min_ <= correction_; }
  double Distance() const { return d_min_ - correction_; }

 private:
  bool Far(const Eigen::Vector2d& centre, double radius) const {
    return Interpolate(map_, field_, centre) - radius - map_.resolution() > d_min_;
  }

  const GridMap& map_;
  const Eigen::MatrixXf& field_;
  double step_, correction_, d_min_;
};

}  // namespace

double SweptObstacleDistance(const GridMap& map, const Eigen::MatrixXf& field,
                             const std::vector<PathSample>& samples, const LoaderGeometry& loader,
                             double cap) {
  const double hw = loader.HalfWidth();
  const double front = loader.tip_reach + loader.body_margin;
  const double rear = loader.hinge_to_rear_axle + loader.rear_overhang + loader.body_margin;
  OutlineProbe probe(map, field, cap);
  for (const PathSample& p : samples) {
    const double gamma = loader.ArticulationFor(p.curvature);
    const Eigen::Vector2d u_front = Direction(p.heading), u_rear = Direction(p.heading - gamma);
    const Eigen::Vector2d hinge = p.xy - loader.hinge_to_front_axle * u_front;
    probe.Rectangle(hinge, u_front, 0.0, front, hw);
    probe.Rectangle(hinge, u_rear, -rear, 0.0, hw);
    if (probe.Touching()) break;  // the path collides, however much more
  }
  return probe.Distance();
}

double ScoopSideClearance(const GridMap& map, const Eigen::MatrixXf& field,
                          const Pose2& front_axle_goal, const LoaderGeometry& loader,
                          double advance, double spacing, double crowd_stop_distance, double cap) {
  const double hw = loader.HalfWidth();
  const double front = loader.tip_reach + loader.body_margin;
  const double rear = loader.hinge_to_rear_axle + loader.rear_overhang + loader.body_margin;
  const Eigen::Vector2d u = Direction(front_axle_goal.heading), n(-u.y(), u.x());
  const Eigen::Vector2d hinge0 = front_axle_goal.xy - loader.hinge_to_front_axle * u;
  OutlineProbe probe(map, field, cap);
  const int steps = std::max(1, static_cast<int>(std::ceil(advance / spacing)));
  for (int k = 0; k <= steps && advance > 0; ++k) {
    const double s = std::min(k * spacing, advance);
    const Eigen::Vector2d hinge = hinge0 + s * u;
    // The crowd drives on while the nearest obstacle to the front edge's middle stays beyond
    // `crowd_stop_distance`; nearer, the look-ahead ends it (what lies ahead of the bucket, a
    // wall behind a pile, is met head on and never reached) and the machine goes no farther.
    if (k > 0 && Interpolate(map, field, hinge + front * u) < crowd_stop_distance) break;
    // Up to there the whole machine counts, as the look-ahead's "beside" check counts the
    // whole stopped footprint: the front frame to its front edge, the rear frame.
    probe.Rectangle(hinge, u, 0.0, front, hw);
    probe.Rectangle(hinge, u, -rear, 0.0, hw);
    if (probe.Touching()) break;
  }
  return probe.Distance();
}

// --- Candidates ---

std::vector<CandidatePose> GenerateCandidates(const GridMap& map,
                                              const std::vector<perception::ExtractedPile>& piles,
                                              const ShovelPointConfig& config) {
  std::vector<CandidatePose> out;
  for (int p = 0; p < static_cast<int>(piles.size()); ++p) {
    if (config.pile >= 0 && p != config.pile) continue;
    const auto& boundary = piles[p].boundary;
    // Walk the ordered outline; along each run of front cells, keep one point every
    // `candidate_spacing` metres of outline (the first of each run included).
    double since_last = kInf;
    int point = 0;
    for (std::size_t k = 0; k < boundary.size(); ++k) {
      const perception::BoundaryPoint& b = boundary[k];
      if (!b.front) {
        since_last = kInf;
        continue;
      }
      if (k > 0 && boundary[k - 1].front) since_last += (b.xy - boundary[k - 1].xy).norm();
      if (since_last < config.candidate_spacing - 1e-9) continue;
      since_last = 0;
      const double normal = InwardNormal(map, b.xy, config.normal_radius, piles[p].centroid);
      for (const double offset : config.entry_angle_offsets) {
        CandidatePose c;
        c.pile = p;
        c.point = point;
        c.xy = b.xy;
        c.normal_heading = normal;
        c.entry_offset = offset;
        c.entry_heading = std::remainder(normal + offset, 2 * std::numbers::pi);
        out.push_back(c);
      }
      ++point;
    }
  }
  return out;
}

// --- Algorithm 2 ---

ShovelPointResult SelectShovelPoints(const GridMap& map,
                                     const std::vector<perception::ExtractedPile>& piles,
                                     const Eigen::Vector3d& plane, const Pose2& T_world_hinge,
                                     const LoaderGeometry& loader,
                                     const ShovelPointConfig& config) {
  ShovelPointResult result;
  const std::string invalid = config.Validate();
  if (!invalid.empty() || !map.Exists("elevation") || !map.Exists("class") ||
      !(loader.MaxCurvature() > 0) || !(loader.tip_reach > loader.hinge_to_front_axle)) {
    result.status = SelectionStatus::kInvalidInput;
    result.message = !invalid.empty()           ? invalid
                     : !map.Exists("class")     ? "the map has no \"class\" layer"
                     : !map.Exists("elevation") ? "the map has no \"elevation\" layer"
                                                : "loader geometry without a turning radius or "
                                                  "with the tip behind the front axle";
    return result;
  }
  result.max_curvature = config.max_curvature > 0 ? config.max_curvature : loader.MaxCurvature();
  result.torque_threshold = config.torque_threshold > 0
                                ? config.torque_threshold
                                : loader.rated_capacity * loader.bucket_width / 4;
  const std::vector<CandidatePose> poses = GenerateCandidates(map, piles, config);
  if (poses.empty()) {
    result.status = SelectionStatus::kNoCandidates;
    result.message = "no pile front to shovel from";
    return result;
  }
  const Eigen::MatrixXf distance_field = ObstacleDistanceField(map);
  const Eigen::MatrixXf pile_height = PileHeightField(map, plane);
  // The path is planned for the front axle (dubins_path.h): it starts lf ahead of the hinge and
  // ends where the bucket tip, reaching tip_reach − lf ahead of it, meets the pile.
  const double lf = loader.hinge_to_front_axle;
  const Pose2 start{T_world_hinge.xy + lf * Direction(T_world_hinge.heading),
                    T_world_hinge.heading};
  const double axle_to_tip = loader.tip_reach - lf;
  // Eq. (14) needs d_min exactly only below d_res (s_s = 1 above it); 1 m beyond is kept for
  // the logs and figures, farther is reported as that much.
  const double clearance_cap = config.safety_distance + 1.0;

  std::vector<ShovelCandidate> candidates;
  candidates.reserve(poses.size());
  for (const CandidatePose& pose : poses) {
    ShovelCandidate c;
    c.pose = pose;
    c.front_axle_goal = {pose.xy - axle_to_tip * Direction(pose.entry_heading), pose.entry_heading};
    ScoreBreakdown& s = c.scores;
    // PlanPath(p0, (x_i, y_i), δ_m): of the six Dubins words, shortest first, the first that
    // keeps the chassis off the pile and d_min > d_res; failing that, the first off the pile
    // with d_min > 0; failing that the shortest (scored, and vetoed by s_s or the pile check).
    const std::vector<DubinsPath> words =
        AllDubinsPaths(start, c.front_axle_goal, result.max_curvature);
    // Eq. (14)'s A goes on past the contact: the scoop drives straight in by scoop_advance.
    // What it passes beside counts; what it meets head on (the pile's far side, a wall behind
    // a pile) ends the crowd first (the main job's look-ahead). The same for every word here.
    const double d_scoop =
        ScoopSideClearance(map, distance_field, c.front_axle_goal, loader, config.scoop_advance,
                           config.path_spacing, config.crowd_stop_distance, clearance_cap);
    int chosen = -1, rank = 3;  // 0: clear of d_res, 1: not touching, 2: neither
    double chosen_d_min = 0;
    std::vector<PathSample> chosen_samples;
    bool chosen_over_pile = true;
    for (int w = 0; w < static_cast<int>(words.size()) && rank > 0; ++w) {
      std::vector<PathSample> samples = SamplePath(words[w], config.path_spacing);
      const bool over_pile =
          DrivesOverPile(map, pile_height, samples, loader, config.max_drive_over_height);
      const double d_min =
          SweptObstacleDistance(map, distance_field, samples, loader, clearance_cap);
      const int r = over_pile ? 2 : d_min > config.safety_distance ? 0 : d_min > 0 ? 1 : 2;
      if (r < rank) {
        chosen = w, rank = r, chosen_d_min = d_min, chosen_over_pile = over_pile;
        chosen_samples = std::move(samples);
      }
    }
    c.path = words[chosen];
    s.path_length = c.path.length();
    s.approach_obstacle_distance = chosen_d_min;
    s.min_obstacle_distance = std::min(chosen_d_min, d_scoop);
    s.end_curvature = chosen_samples.back().curvature;
    s.entry_curvature = EntryCurvature(chosen_samples, config.entry_window);
    s.entry_articulation = loader.ArticulationFor(s.entry_curvature);
    // Eq. (12)–(13), (14), (15), (17); (16) once every path on the pile is known.
    s.torque = TorqueMoment(map, plane, pose.xy, pose.entry_heading, loader.bucket_width,
                            config.penetration_length);
    s.s_t = TorqueScore(s.torque, result.torque_threshold);
    s.s_s = SafetyScore(s.min_obstacle_distance, config.safety_distance);
    const SectionVolumes v = ConcavityVolumes(map, plane, pose.xy, pose.entry_heading,
                                              loader.bucket_width, config.penetration_length);
    s.volume_left = v.left, s.volume_middle = v.middle, s.volume_right = v.right;
    s.s_c = ConcavityScore(v, config.concavity_tolerance);
    s.s_a = EntryAngleScore(s.entry_curvature, result.max_curvature);
    if (s.s_t == kMinusInfinity) {
      c.infeasible = "torque |T_c| >= T_res";
    } else if (s.s_s == kMinusInfinity) {
      c.infeasible = "path collides with an obstacle";
    } else if (chosen_over_pile) {
      c.infeasible = "path drives over the pile";
    }
    c.feasible = c.infeasible.empty();
    candidates.push_back(std::move(c));
  }
  // Eq. (16): l_max and l_min over the feasible paths to the same pile.
  std::map<int, std::pair<double, double>> range;
  for (const ShovelCandidate& c : candidates) {
    if (!c.feasible) continue;
    auto [it, inserted] = range.try_emplace(c.pose.pile, kInf, -kInf);
    it->second.first = std::min(it->second.first, c.scores.path_length);
    it->second.second = std::max(it->second.second, c.scores.path_length);
  }
  for (ShovelCandidate& c : candidates) {
    const auto it = range.find(c.pose.pile);
    c.scores.s_e = it == range.end()
                       ? 0.0
                       : EfficiencyScore(c.scores.path_length, it->second.first, it->second.second);
    c.score = c.feasible ? WeightedScore(c.scores, config) : kMinusInfinity;
    result.feasible += c.feasible;
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const ShovelCandidate& a, const ShovelCandidate& b) {
                     if (a.feasible != b.feasible) return a.feasible;
                     return a.score > b.score;
                   });
  result.ranked = std::move(candidates);
  if (result.feasible == 0) {
    result.status = SelectionStatus::kNoFeasibleCandidate;
    // Why, tallied: a user needs to know whether the pile is too lopsided, boxed in, or in
    // the way of every path.
    std::map<std::string, int> reasons;
    for (const ShovelCandidate& c : result.ranked) ++reasons[c.infeasible];
    std::string why;
    for (const auto& [reason, count] : reasons) {
      why += (why.empty() ? "" : ", ") + reason + ": " + std::to_string(count);
    }
    result.message =
        std::to_string(result.ranked.size()) + " candidates, none feasible (" + why + ")";
  } else {
    result.status = SelectionStatus::kSelected;
    result.message = std::to_string(result.feasible) + " of " +
                     std::to_string(result.ranked.size()) + " candidates feasible";
  }
  return result;
}

const char* ToString(SelectionStatus status) {
  switch (status) {
    case SelectionStatus::kSelected:
      return "selected";
    case SelectionStatus::kNoCandidates:
      return "no candidates";
    case SelectionStatus::kNoFeasibleCandidate:
      return "no feasible candidate";
    case SelectionStatus::kInvalidInput:
      return "invalid input";
  }
  return "?";
}

}  // namespace autoshovel::planning
