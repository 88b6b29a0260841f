#include "runtime/sensors/raycast.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace autoshovel::sensors {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr float kNoSurface = -std::numeric_limits<float>::infinity();

// A height rounded up to float, so that the pyramid never claims a cell lower than it is.
float RoundUp(double h) {
  float f = static_cast<float>(h);
  if (static_cast<double>(f) < h) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// Slab test in the frame of a box turned by yaw (cos c, sin s) about world z.
bool SlabTest(const Eigen::Vector3d& center, const Eigen::Vector3d& half, double c, double s,
              const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double max_range,
              double& range, Eigen::Vector3d& normal) {
  const Eigen::Vector3d v = origin - center;
  const Eigen::Vector3d o(c * v.x() + s * v.y(), -s * v.x() + c * v.y(), v.z());
  const Eigen::Vector3d d(c * direction.x() + s * direction.y(),
                          -s * direction.x() + c * direction.y(), direction.z());
  double t_near = -kInf, t_far = kInf;
  int axis = -1;
  double sign = 0;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) {
      if (std::abs(o[i]) > half[i]) return false;
      continue;
    }
    const double inv = 1.0 / d[i];
    double t1 = (-half[i] - o[i]) * inv;
    double t2 = (half[i] - o[i]) * inv;
    if (t1 > t2) std::swap(t1, t2);
    if (t1 > t_near) {
      t_near = t1;
      axis = i;
      sign = d[i] > 0 ? -1.0 : 1.0;  // entering through the face facing the ray
    }
    t_far = std::min(t_far, t2);
  }
  if (axis < 0 || t_near > t_far || t_near < 0 || t_near > max_range) return false;
  range = t_near;
  Eigen::Vector3d n_local = Eigen::Vector3d::Zero();
  n_local[axis] = sign;
  normal = Eigen::Vector3d(c * n_local.x() - s * n_local.y(), s * n_local.x() + c * n_local.y(),
                           n_local.z());
  return true;
}

// Restricts [t_lo, t_hi] to the t where p0 + d·t lies in [lo, hi].
bool ClipSlab(double p0, double d, double lo, double hi, double& t_lo, double& t_hi) {
  if (d == 0.0) return p0 >= lo && p0 <= hi;
  double ta = (lo - p0) / d, tb = (hi - p0) / d;
  if (ta > tb) std::swap(ta, tb);
  t_lo = std::max(t_lo, ta);
  t_hi = std::min(t_hi, tb);
  return t_lo <= t_hi;
}

// Rectangles (lo_x, lo_y, hi_x, hi_y) binned on a uniform grid over [x_lo, x_hi] × [y_lo, y_hi]
// in compressed rows: the rectangles touching cell k are index[cell_start[k] .. cell_start[k+1]).
// Cells of `min_cell`, larger where the extent would need more than 256 per side. Shared by the
// scene's box grid (footprints) and ParallelRayBoxes (shadows on the plane across the sun).
struct UniformBins {
  double x0 = 0, y0 = 0, cell = 1;  // corner of cell (0, 0), cell size
  int nx = 0, ny = 0;
  std::vector<int> cell_start, index;
};

UniformBins BinRectangles(const std::vector<Eigen::Vector4d>& rects, double x_lo, double y_lo,
                          double x_hi, double y_hi, double min_cell) {
  UniformBins b;
  const double margin = 1e-6;
  b.cell = std::max(min_cell, std::max(x_hi - x_lo, y_hi - y_lo) / 256.0);
  b.x0 = x_lo - margin, b.y0 = y_lo - margin;
  b.nx = std::max(1, static_cast<int>(std::ceil((x_hi - x_lo + 2 * margin) / b.cell)));
  b.ny = std::max(1, static_cast<int>(std::ceil((y_hi - y_lo + 2 * margin) / b.cell)));
  auto span = [&](const Eigen::Vector4d& f, int& ix0, int& iy0, int& ix1, int& iy1) {
    ix0 = std::clamp(static_cast<int>(std::floor((f[0] - b.x0) / b.cell)), 0, b.nx - 1);
    iy0 = std::clamp(static_cast<int>(std::floor((f[1] - b.y0) / b.cell)), 0, b.ny - 1);
    ix1 = std::clamp(static_cast<int>(std::floor((f[2] - b.x0) / b.cell)), 0, b.nx - 1);
    iy1 = std::clamp(static_cast<int>(std::floor((f[3] - b.y0) / b.cell)), 0, b.ny - 1);
  };
  std::vector<int> count(static_cast<std::size_t>(b.nx) * b.ny + 1, 0);
  for (const Eigen::Vector4d& f : rects) {
    int ix0, iy0, ix1, iy1;
    span(f, ix0, iy0, ix1, iy1);
    for (int iy = iy0; iy <= iy1; ++iy) {
      for (int ix = ix0; ix <= ix1; ++ix) ++count[iy * b.nx + ix + 1];
    }
  }
  for (std::size_t k = 1; k < count.size(); ++k) count[k] += count[k - 1];
  b.cell_start = count;
  b.index.resize(count.back());
  for (std::size_t i = 0; i < rects.size(); ++i) {
    int ix0, iy0, ix1, iy1;
    span(rects[i], ix0, iy0, ix1, iy1);
    for (int iy = iy0; iy <= iy1; ++iy) {
      for (int ix = ix0; ix <= ix1; ++ix) b.index[count[iy * b.nx + ix]++] = static_cast<int>(i);
    }
  }
  return b;
}

}  // namespace

bool IntersectBox(const plant::OrientedBox& box, const Eigen::Vector3d& origin,
                  const Eigen::Vector3d& direction, double max_range, double& range,
                  Eigen::Vector3d& normal) {
  return SlabTest(box.center, box.half_extents, std::cos(box.yaw), std::sin(box.yaw), origin,
                  direction, max_range, range, normal);
}

RaycastScene::RaycastScene(const plant::World& world, std::vector<plant::OrientedBox> extra_boxes)
    : world_(&world), extra_boxes_(std::move(extra_boxes)) {
  Update();
}

void RaycastScene::Update() {
  BuildPyramid();
  UpdateBoxes();
}

void RaycastScene::SetExtraBoxes(std::vector<plant::OrientedBox> extra_boxes) {
  extra_boxes_ = std::move(extra_boxes);
  UpdateBoxes();
}

void RaycastScene::UpdateBoxes() {
  boxes_ = world_->obstacles;
  boxes_.insert(boxes_.end(), extra_boxes_.begin(), extra_boxes_.end());
  prepared_.clear();
  prepared_.reserve(boxes_.size());
  for (const auto& b : boxes_) {
    PreparedBox p;
    p.center = b.center;
    p.half = b.half_extents.cwiseAbs();
    p.c = std::cos(b.yaw);
    p.s = std::sin(b.yaw);
    p.radius = p.half.norm();
    prepared_.push_back(p);
  }
  BuildBoxGrid();
}

void RaycastScene::BuildBoxGrid() {
  BoxGrid& g = box_grid_;
  g = BoxGrid{};
  if (prepared_.empty()) return;
  // World-axis footprint of each box.
  std::vector<Eigen::Vector4d> footprint(prepared_.size());  // x_lo, y_lo, x_hi, y_hi
  double x_lo = kInf, y_lo = kInf, x_hi = -kInf, y_hi = -kInf;
  g.z_lo = kInf, g.z_hi = -kInf;
  for (std::size_t i = 0; i < prepared_.size(); ++i) {
    const PreparedBox& p = prepared_[i];
    const double ex = std::abs(p.c) * p.half.x() + std::abs(p.s) * p.half.y();
    const double ey = std::abs(p.s) * p.half.x() + std::abs(p.c) * p.half.y();
    footprint[i] = {p.center.x() - ex, p.center.y() - ey, p.center.x() + ex, p.center.y() + ey};
    x_lo = std::min(x_lo, footprint[i][0]), y_lo = std::min(y_lo, footprint[i][1]);
    x_hi = std::max(x_hi, footprint[i][2]), y_hi = std::max(y_hi, footprint[i][3]);
    g.z_lo = std::min(g.z_lo, p.center.z() - p.half.z());
    g.z_hi = std::max(g.z_hi, p.center.z() + p.half.z());
  }
  if (!std::isfinite(x_lo + y_lo + x_hi + y_hi + g.z_lo + g.z_hi)) {
    // A box with a non-finite coordinate: one cell of infinite size holding every box keeps
    // the result the linear scan's (the slab test rejects what it cannot hit).
    g.nx = g.ny = 1, g.cell = kInf;
    g.cell_start = {0, static_cast<int>(prepared_.size())};
    g.box_index.resize(prepared_.size());
    for (std::size_t i = 0; i < prepared_.size(); ++i) g.box_index[i] = static_cast<int>(i);
    return;
  }
  // Cells of 2 m (a wall's thickness to a machine's length), larger for a huge yard.
  const UniformBins bins = BinRectangles(footprint, x_lo, y_lo, x_hi, y_hi, 2.0);
  g.x0 = bins.x0, g.y0 = bins.y0, g.cell = bins.cell, g.nx = bins.nx, g.ny = bins.ny;
  g.cell_start = bins.cell_start;
  g.box_index = bins.index;
}

float RaycastScene::PatchMax(int px, int py) const {
  // Patch (px, py) spans the cell centres of cells px−1..px and py−1..py (clamped at the border,
  // which extends the surface flat over the outer half cells).
  const plant::Terrain& t = world_->terrain;
  const int x0 = std::max(px - 1, 0), x1 = std::min(px, grid_nx_ - 1);
  const int y0 = std::max(py - 1, 0), y1 = std::min(py, grid_ny_ - 1);
  const double m = std::max(std::max(t.height(x0, y0), t.height(x1, y0)),
                            std::max(t.height(x0, y1), t.height(x1, y1)));
  return RoundUp(m);
}

void RaycastScene::BuildPyramid() {
  const plant::Terrain& t = world_->terrain;
  grid_nx_ = t.nx();
  grid_ny_ = t.ny();
  levels_.clear();
  if (grid_nx_ <= 0 || grid_ny_ <= 0) return;
  Level base;
  base.nx = grid_nx_ + 1;
  base.ny = grid_ny_ + 1;
  base.max.resize(static_cast<std::size_t>(base.nx) * base.ny);
  levels_.push_back(std::move(base));
  while (levels_.back().nx > 1 || levels_.back().ny > 1) {
    Level next;
    next.nx = (levels_.back().nx + 1) / 2;
    next.ny = (levels_.back().ny + 1) / 2;
    next.max.resize(static_cast<std::size_t>(next.nx) * next.ny);
    levels_.push_back(std::move(next));
  }
  RefreshLevels(0, 0, grid_nx_, grid_ny_);
}

void RaycastScene::RefreshLevels(int px0, int py0, int px1, int py1) {
  Level& base = levels_[0];
  for (int py = py0; py <= py1; ++py) {
    for (int px = px0; px <= px1; ++px) base.max[py * base.nx + px] = PatchMax(px, py);
  }
  for (std::size_t l = 1; l < levels_.size(); ++l) {
    const Level& child = levels_[l - 1];
    Level& parent = levels_[l];
    px0 >>= 1, py0 >>= 1, px1 >>= 1, py1 >>= 1;
    for (int py = py0; py <= py1; ++py) {
      for (int px = px0; px <= px1; ++px) {
        float m = kNoSurface;
        for (int cy = 2 * py; cy <= std::min(2 * py + 1, child.ny - 1); ++cy) {
          for (int cx = 2 * px; cx <= std::min(2 * px + 1, child.nx - 1); ++cx) {
            m = std::max(m, child.max[cy * child.nx + cx]);
          }
        }
        parent.max[py * parent.nx + px] = m;
      }
    }
  }
}

void RaycastScene::UpdateTerrain(int ix0, int iy0, int ix1, int iy1) {
  const plant::Terrain& t = world_->terrain;
  if (t.nx() != grid_nx_ || t.ny() != grid_ny_ || levels_.empty()) {
    BuildPyramid();
    return;
  }
  ix0 = std::clamp(ix0, 0, grid_nx_ - 1), ix1 = std::clamp(ix1, 0, grid_nx_ - 1);
  iy0 = std::clamp(iy0, 0, grid_ny_ - 1), iy1 = std::clamp(iy1, 0, grid_ny_ - 1);
  if (ix0 > ix1 || iy0 > iy1) return;
  // Cell i is a corner of patches i and i + 1.
  RefreshLevels(ix0, iy0, ix1 + 1, iy1 + 1);
}

double RaycastScene::max_terrain_height() const {
  return levels_.empty() ? -kInf : static_cast<double>(levels_.back().max[0]);
}

bool RaycastScene::IntersectPatch(int px, int py, double u0, double v0, double z0, double du,
                                  double dv, double dz, double t_in, double t_out, double& t_hit,
                                  double& a_hit, double& b_hit) const {
  const plant::Terrain& t = world_->terrain;
  const int x0 = std::max(px - 1, 0), x1 = std::min(px, grid_nx_ - 1);
  const int y0 = std::max(py - 1, 0), y1 = std::min(py, grid_ny_ - 1);
  const double h00 = t.height(x0, y0), h10 = t.height(x1, y0);
  const double h01 = t.height(x0, y1), h11 = t.height(x1, y1);
  // z_s(a, b) = A + B a + C b + D a b with a, b the patch coordinates; along the ray, measured
  // from the patch entry (s = t − t_in, which keeps the coefficients well conditioned):
  // a = a0 + du s, b = b0 + dv s, z = zr + dz s; g(s) = z_s − z is quadratic in s.
  const double A = h00, B = h10 - h00, C = h01 - h00, D = h00 - h10 - h01 + h11;
  const double a0 = u0 + du * t_in - px, b0 = v0 + dv * t_in - py, zr = z0 + dz * t_in;
  const double len = t_out - t_in;
  const double c0 = A + B * a0 + C * b0 + D * a0 * b0 - zr;
  double s;
  if (c0 >= 0) {
    s = 0;  // at or below the surface on entry: the crossing is on the patch edge
  } else {
    const double c1 = B * du + C * dv + D * (a0 * dv + b0 * du) - dz;
    const double c2 = D * du * dv;
    s = kInf;
    if (c2 == 0.0) {
      if (c1 > 0) s = -c0 / c1;
    } else {
      const double disc = c1 * c1 - 4 * c2 * c0;
      if (disc < 0) return false;
      // Numerically stable roots (Numerical Recipes §5.6).
      const double q = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
      const double r1 = q / c2;
      const double r2 = q != 0.0 ? c0 / q : kInf;
      constexpr double kSlack = -1e-12;  // a root a rounding error before the entry
      for (const double r : {r1, r2}) {
        if (r >= kSlack && r < s) s = r;
      }
      s = std::max(s, 0.0);
    }
    if (!(s <= len)) return false;
  }
  t_hit = t_in + s;
  a_hit = std::clamp(a0 + du * s, 0.0, 1.0);
  b_hit = std::clamp(b0 + dv * s, 0.0, 1.0);
  return true;
}

void RaycastScene::FillTerrainHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                  double t_hit, int px, int py, double a, double b,
                                  RayHit& hit) const {
  const plant::Terrain& t = world_->terrain;
  const double h = t.resolution();
  const int x0 = std::max(px - 1, 0), x1 = std::min(px, grid_nx_ - 1);
  const int y0 = std::max(py - 1, 0), y1 = std::min(py, grid_ny_ - 1);
  const double h00 = t.height(x0, y0), h10 = t.height(x1, y0);
  const double h01 = t.height(x0, y1), h11 = t.height(x1, y1);
  const double B = h10 - h00, C = h01 - h00, D = h00 - h10 - h01 + h11;
  // Border patches span half a cell; their clamped corners make B or C zero there, so the
  // gradient below is right with the full cell width.
  const double gx = (B + D * b) / h, gy = (C + D * a) / h;
  hit.hit = true;
  hit.range = t_hit;
  hit.point = origin + t_hit * direction;
  hit.normal = Eigen::Vector3d(-gx, -gy, 1.0).normalized();
  hit.box = -1;
  const auto& g = t.geometry();
  hit.cell_x =
      std::clamp(static_cast<int>(std::floor((hit.point.x() - g.origin.x()) / h)), 0, grid_nx_ - 1);
  hit.cell_y =
      std::clamp(static_cast<int>(std::floor((hit.point.y() - g.origin.y()) / h)), 0, grid_ny_ - 1);
  const bool pile = t.depth(hit.cell_x, hit.cell_y) > kPileDepthThreshold;
  hit.semantic_class = pile ? core::SemanticClass::kPile : core::SemanticClass::kGround;
  hit.reflectivity = world_->ground_reflectivity;
  const int m = t.material(hit.cell_x, hit.cell_y);
  if (pile && m >= 0 && m < static_cast<int>(world_->materials.size())) {
    hit.reflectivity = world_->materials[m].reflectivity;
  }
}

bool RaycastScene::TraverseTerrain(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                   double max_range, RayHit& hit) const {
  if (levels_.empty() || !origin.allFinite() || !direction.allFinite()) return false;
  const auto& g = world_->terrain.geometry();
  const double h = g.resolution;
  // Patch coordinates: u = (x − x_origin)/h + 1/2, so patch p spans u ∈ [p, p + 1) and cell i's
  // centre lies at u = i + 1. The grid's rectangle is u ∈ [1/2, nx + 1/2].
  const double u0 = (origin.x() - g.origin.x()) / h + 0.5;
  const double v0 = (origin.y() - g.origin.y()) / h + 0.5;
  const double z0 = origin.z();
  const double du = direction.x() / h, dv = direction.y() / h, dz = direction.z();
  double t_lo = 0, t_hi = max_range;
  if (!ClipSlab(u0, du, 0.5, grid_nx_ + 0.5, t_lo, t_hi)) return false;
  if (!ClipSlab(v0, dv, 0.5, grid_ny_ + 0.5, t_lo, t_hi)) return false;
  if (!ClipSlab(z0, dz, -kInf, max_terrain_height(), t_lo, t_hi)) return false;

  const int sx = du > 0 ? 1 : -1, sy = dv > 0 ? 1 : -1;
  const double inv_du = du != 0.0 ? 1.0 / du : kInf;
  const double inv_dv = dv != 0.0 ? 1.0 / dv : kInf;
  const int top = static_cast<int>(levels_.size()) - 1;
  int level = top, cx = 0, cy = 0;
  double t = t_lo;
  // Each iteration either descends a level (at most `top` times in a row) or steps to the next
  // cell along the ray, so the loop ends.
  for (;;) {
    const Level& lev = levels_[level];
    const double size = static_cast<double>(1 << level);  // cell edge in patches
    double tx = kInf, ty = kInf;
    if (du > 0) tx = ((cx + 1) * size - u0) * inv_du;
    if (du < 0) tx = (cx * size - u0) * inv_du;
    if (dv > 0) ty = ((cy + 1) * size - v0) * inv_dv;
    if (dv < 0) ty = (cy * size - v0) * inv_dv;
    const double t_exit = std::max(t, std::min(std::min(tx, ty), t_hi));
    const float cell_max = lev.max[cy * lev.nx + cx];
    const double z_low = z0 + dz * (dz < 0 ? t_exit : t);  // the ray's lowest point in the cell
    if (!(z_low > cell_max)) {
      if (level > 0) {
        --level;
        const Level& child = levels_[level];
        const double child_size = size * 0.5;
        // The child of (cx, cy) holding the ray at t: compare with the parent's midlines (no
        // division, and a point on a boundary stays inside the parent).
        const double uc = u0 + du * t, vc = v0 + dv * t;
        cx = std::min(2 * cx + (uc >= (2 * cx + 1) * child_size ? 1 : 0), child.nx - 1);
        cy = std::min(2 * cy + (vc >= (2 * cy + 1) * child_size ? 1 : 0), child.ny - 1);
        continue;
      }
      double t_hit, a, b;
      if (IntersectPatch(cx, cy, u0, v0, z0, du, dv, dz, t, t_exit, t_hit, a, b)) {
        FillTerrainHit(origin, direction, t_hit, cx, cy, a, b, hit);
        return true;
      }
    }
    if (t_exit >= t_hi) return false;
    const int ocx = cx, ocy = cy;
    if (tx <= ty) {
      cx += sx;
    } else {
      cy += sy;
    }
    if (cx < 0 || cy < 0 || cx >= lev.nx || cy >= lev.ny) return false;  // left the grid
    t = t_exit;
    if (level < top && ((cx >> 1) != (ocx >> 1) || (cy >> 1) != (ocy >> 1))) {
      ++level;
      cx >>= 1;
      cy >>= 1;
    }
  }
}

RayHit RaycastScene::CastTerrain(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                 double max_range) const {
  RayHit hit;
  TraverseTerrain(origin, direction, max_range, hit);
  return hit;
}

RayHit RaycastScene::CastBoxes(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                               double max_range) const {
  RayHit hit;
  if (!origin.allFinite() || !direction.allFinite() || prepared_.empty()) return hit;
  const BoxGrid& g = box_grid_;
  double best = max_range;
  auto test_cell = [&](int cell) {
    for (int k = g.cell_start[cell]; k < g.cell_start[cell + 1]; ++k) {
      const int i = g.box_index[k];
      const PreparedBox& p = prepared_[i];
      // Bounding-sphere reject: the ray passes farther from the centre than the half diagonal.
      const Eigen::Vector3d v = p.center - origin;
      const double along = v.dot(direction);
      if (along + p.radius < 0 || v.squaredNorm() - along * along > p.radius * p.radius) continue;
      double range;
      Eigen::Vector3d normal;
      // SlabTest accepts range <= best. Of boxes at equal range the highest index wins, as in
      // a scan of all boxes in order, whatever order the cells meet them in.
      if (SlabTest(p.center, p.half, p.c, p.s, origin, direction, best, range, normal) &&
          (!hit.hit || range < best || i > hit.box)) {
        best = range;
        hit.hit = true;
        hit.range = range;
        hit.normal = normal;
        hit.box = i;
      }
    }
  };
  // The part of the ray inside the grid's box [x0, x0 + nx·cell] × [y0, …] × [z_lo, z_hi].
  double t_lo = 0, t_hi = max_range;
  const bool single = !std::isfinite(g.cell);
  if (!single && (!ClipSlab(origin.x(), direction.x(), g.x0, g.x0 + g.nx * g.cell, t_lo, t_hi) ||
                  !ClipSlab(origin.y(), direction.y(), g.y0, g.y0 + g.ny * g.cell, t_lo, t_hi) ||
                  !ClipSlab(origin.z(), direction.z(), g.z_lo, g.z_hi, t_lo, t_hi))) {
    return hit;
  }
  if (single) {
    test_cell(0);
  } else {
    // 2-D DDA (Amanatides & Woo) from where the ray enters the grid.
    const double px = origin.x() + t_lo * direction.x() - g.x0;
    const double py = origin.y() + t_lo * direction.y() - g.y0;
    int ix = std::clamp(static_cast<int>(std::floor(px / g.cell)), 0, g.nx - 1);
    int iy = std::clamp(static_cast<int>(std::floor(py / g.cell)), 0, g.ny - 1);
    const int step_x = direction.x() > 0 ? 1 : -1, step_y = direction.y() > 0 ? 1 : -1;
    const double dt_x = direction.x() != 0 ? g.cell / std::abs(direction.x()) : kInf;
    const double dt_y = direction.y() != 0 ? g.cell / std::abs(direction.y()) : kInf;
    double next_x =
        direction.x() != 0 ? t_lo + ((ix + (step_x > 0)) * g.cell - px) / direction.x() : kInf;
    double next_y =
        direction.y() != 0 ? t_lo + ((iy + (step_y > 0)) * g.cell - py) / direction.y() : kInf;
    double t_cell = t_lo;  // where the ray enters the current cell
    while (t_cell <= std::min(best, t_hi)) {
      test_cell(iy * g.nx + ix);
      if (next_x < next_y) {
        t_cell = next_x, next_x += dt_x, ix += step_x;
        if (ix < 0 || ix >= g.nx) break;
      } else {
        t_cell = next_y, next_y += dt_y, iy += step_y;
        if (iy < 0 || iy >= g.ny) break;
      }
    }
  }
  if (hit.hit) return BoxHit(hit.box, origin, direction, hit.range, hit.normal);
  return hit;
}

bool RaycastScene::IntersectBoxAt(int index, const Eigen::Vector3d& origin,
                                  const Eigen::Vector3d& direction, double max_range, double& range,
                                  Eigen::Vector3d& normal) const {
  const PreparedBox& p = prepared_[static_cast<std::size_t>(index)];
  return SlabTest(p.center, p.half, p.c, p.s, origin, direction, max_range, range, normal);
}

RayHit RaycastScene::BoxHit(int index, const Eigen::Vector3d& origin,
                            const Eigen::Vector3d& direction, double range,
                            const Eigen::Vector3d& normal) const {
  RayHit hit;
  hit.hit = true;
  hit.range = range;
  hit.point = origin + range * direction;
  hit.normal = normal;
  hit.box = index;
  hit.semantic_class = boxes_[static_cast<std::size_t>(index)].semantic_class;
  hit.reflectivity = boxes_[static_cast<std::size_t>(index)].reflectivity;
  return hit;
}

RayHit RaycastScene::Cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                          double max_range) const {
  // The boxes first: the sensors sit on the machine, whose own boxes stop many rays within a
  // few metres, and the terrain walk is then cut short at them. (Terrain first was measured
  // 20 % slower in the closed loop: the box walk is cheap for a ray that looks down, since it
  // ends where the ray leaves the boxes' height band.)
  RayHit box = CastBoxes(origin, direction, max_range);
  RayHit terrain;
  if (TraverseTerrain(origin, direction, box.hit ? box.range : max_range, terrain)) return terrain;
  return box;
}

ParallelRayBoxes::ParallelRayBoxes(const RaycastScene& scene, const Eigen::Vector3d& direction)
    : scene_(&scene) {
  if (!direction.allFinite() || !(direction.norm() > 0)) {
    throw std::invalid_argument("ParallelRayBoxes: the direction must be finite and non-zero");
  }
  direction_ = direction.normalized();
  // An orthonormal basis of the plane across the rays.
  e1_ = direction_.unitOrthogonal();
  e2_ = direction_.cross(e1_);
  const std::vector<plant::OrientedBox>& boxes = scene.boxes();
  if (boxes.empty()) return;
  // Each box's shadow bounds on the plane: its eight corners projected.
  std::vector<Eigen::Vector4d> bounds(boxes.size());  // lo1, lo2, hi1, hi2
  double lo1 = kInf, lo2 = kInf, hi1 = -kInf, hi2 = -kInf;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const plant::OrientedBox& b = boxes[i];
    const double c = std::cos(b.yaw), s = std::sin(b.yaw);
    const Eigen::Vector3d h = b.half_extents.cwiseAbs();
    Eigen::Vector4d& f = bounds[i];
    f << kInf, kInf, -kInf, -kInf;
    for (int k = 0; k < 8; ++k) {
      const double x = (k & 1 ? 1 : -1) * h.x(), y = (k & 2 ? 1 : -1) * h.y();
      const double z = (k & 4 ? 1 : -1) * h.z();
      const Eigen::Vector3d p = b.center + Eigen::Vector3d(c * x - s * y, s * x + c * y, z);
      const double a = p.dot(e1_), d = p.dot(e2_);
      f[0] = std::min(f[0], a), f[1] = std::min(f[1], d);
      f[2] = std::max(f[2], a), f[3] = std::max(f[3], d);
    }
    if (!f.allFinite()) everywhere_ = true;
    lo1 = std::min(lo1, f[0]), lo2 = std::min(lo2, f[1]);
    hi1 = std::max(hi1, f[2]), hi2 = std::max(hi2, f[3]);
  }
  if (everywhere_) return;
  // Cells of 1 m (most boxes are walls and machine parts a few metres long), larger for a
  // huge yard.
  UniformBins bins = BinRectangles(bounds, lo1, lo2, hi1, hi2, 1.0);
  x0_ = bins.x0, y0_ = bins.y0, cell_ = bins.cell, nx_ = bins.nx, ny_ = bins.ny;
  cell_start_ = std::move(bins.cell_start);
  box_index_ = std::move(bins.index);
}

bool ParallelRayBoxes::Occluded(const Eigen::Vector3d& origin, double max_range) const {
  if (!origin.allFinite()) return false;
  const int n_boxes = static_cast<int>(scene_->boxes().size());
  double range;
  Eigen::Vector3d normal;
  if (everywhere_) {
    for (int i = 0; i < n_boxes; ++i) {
      if (scene_->IntersectBoxAt(i, origin, direction_, max_range, range, normal)) return true;
    }
    return false;
  }
  if (n_boxes == 0) return false;
  // A ray's shadow-plane coordinates are its origin's: a box it meets casts its shadow there.
  const double a = origin.dot(e1_), d = origin.dot(e2_);
  const int ix = static_cast<int>(std::floor((a - x0_) / cell_));
  const int iy = static_cast<int>(std::floor((d - y0_) / cell_));
  if (ix < 0 || iy < 0 || ix >= nx_ || iy >= ny_) return false;
  const int cell = iy * nx_ + ix;
  for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
    if (scene_->IntersectBoxAt(box_index_[k], origin, direction_, max_range, range, normal)) {
      return true;
    }
  }
  return false;
}

}  // namespace autoshovel::sensors
