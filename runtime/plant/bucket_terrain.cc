#include "runtime/plant/bucket_terrain.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace autoshovel::plant {

namespace {

double PolygonArea(const std::vector<Eigen::Vector2d>& polygon) {
  double twice = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return std::abs(twice) / 2.0;
}

Eigen::Vector2d Centroid(const std::vector<Eigen::Vector2d>& polygon) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const auto& p : polygon) sum += p;
  return sum / static_cast<double>(polygon.size());
}

// Sutherland–Hodgman clip of a polygon against the half-plane z ≤ level.
std::vector<Eigen::Vector2d> ClipBelow(const std::vector<Eigen::Vector2d>& polygon, double level) {
  std::vector<Eigen::Vector2d> out;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    const bool a_in = a.y() <= level, b_in = b.y() <= level;
    if (a_in) out.push_back(a);
    if (a_in != b_in) {
      const double t = (level - a.y()) / (b.y() - a.y());
      out.push_back(a + t * (b - a));
    }
  }
  return out;
}

// Sutherland–Hodgman clip against the half-plane below the line through `point` with `slope`
// (z ≤ point.z + slope·(s − point.s)).
std::vector<Eigen::Vector2d> ClipBelowLine(const std::vector<Eigen::Vector2d>& polygon,
                                           const Eigen::Vector2d& point, double slope) {
  auto above = [&](const Eigen::Vector2d& p) {
    return p.y() - (point.y() + slope * (p.x() - point.x()));
  };
  std::vector<Eigen::Vector2d> out;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    const double fa = above(a), fb = above(b);
    if (fa <= 0) out.push_back(a);
    if ((fa <= 0) != (fb <= 0)) out.push_back(a + fa / (fa - fb) * (b - a));
  }
  return out;
}

// Lowest crossing of the vertical line at s with the polygon's edges; false if none.
bool LowerOutline(const std::vector<Eigen::Vector2d>& polygon, double s, double& z_low) {
  bool found = false;
  z_low = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    const double lo = std::min(a.x(), b.x()), hi = std::max(a.x(), b.x());
    if (s < lo || s > hi || hi - lo < 1e-12) continue;
    const double t = (s - a.x()) / (b.x() - a.x());
    z_low = std::min(z_low, a.y() + t * (b.y() - a.y()));
    found = true;
  }
  return found;
}

}  // namespace

Eigen::Vector2d BucketPlacement::ToPlane(const Eigen::Vector2d& p_bucket) const {
  const double c = std::cos(bucket_angle), s = std::sin(bucket_angle);
  return pivot +
         Eigen::Vector2d(c * p_bucket.x() - s * p_bucket.y(), s * p_bucket.x() + c * p_bucket.y());
}

Eigen::Vector2d BucketPlacement::ToWorldXy(double s) const {
  return plane_origin + s * Eigen::Vector2d(std::cos(plane_heading), std::sin(plane_heading));
}

BucketTerrain::BucketTerrain(const model::Bucket& bucket, World& world, CuttingDirection cutting)
    : bucket_(bucket), world_(world), cutting_(cutting), struck_area_(PolygonArea(bucket.profile)) {
  payload_by_material_.assign(world.materials.size(), 0.0);
}

std::vector<Eigen::Vector2d> BucketTerrain::PlanePolygon(const BucketPlacement& placement) const {
  std::vector<Eigen::Vector2d> polygon;
  polygon.reserve(bucket_.profile.size());
  for (const auto& p : bucket_.profile) polygon.push_back(placement.ToPlane(p));
  return polygon;
}

template <typename Visit>
void BucketTerrain::ForEachCellInStrip(const BucketPlacement& placement, double s0, double s1,
                                       Visit&& visit) const {
  ForEachCellInStrip(placement, s0, s1, -std::numeric_limits<double>::infinity(),
                     world_.terrain.heights(), std::forward<Visit>(visit));
}

template <typename Visit>
void BucketTerrain::ForEachCellInStrip(const BucketPlacement& placement, double s0, double s1,
                                       double min_height, const std::vector<double>& heights,
                                       Visit&& visit) const {
  const Terrain& terrain = world_.terrain;
  const Eigen::Vector2d axis(std::cos(placement.plane_heading), std::sin(placement.plane_heading));
  const Eigen::Vector2d lateral(-axis.y(), axis.x());
  const double half_width = bucket_.width / 2.0;
  // World bounding box of the strip's rectangle.
  Eigen::Vector2d lo(std::numeric_limits<double>::infinity(),
                     std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (double s : {s0, s1}) {
    for (double l : {-half_width, half_width}) {
      const Eigen::Vector2d p = placement.plane_origin + s * axis + l * lateral;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  const GridGeometry& g = terrain.geometry();
  const int ix0 = std::max(0, static_cast<int>(std::floor((lo.x() - g.origin.x()) / g.resolution)));
  const int iy0 = std::max(0, static_cast<int>(std::floor((lo.y() - g.origin.y()) / g.resolution)));
  const int ix1 =
      std::min(g.nx - 1, static_cast<int>(std::floor((hi.x() - g.origin.x()) / g.resolution)));
  const int iy1 =
      std::min(g.ny - 1, static_cast<int>(std::floor((hi.y() - g.origin.y()) / g.resolution)));
  for (int iy = iy0; iy <= iy1; ++iy) {
    for (int ix = ix0; ix <= ix1; ++ix) {
      if (heights[terrain.Index(ix, iy)] <= min_height) continue;
      const Eigen::Vector2d d = terrain.CellCenter(ix, iy) - placement.plane_origin;
      const double s = d.dot(axis), l = d.dot(lateral);
      if (std::abs(l) > half_width || s < s0 || s > s1) continue;
      visit(ix, iy, s);
    }
  }
}

double BucketTerrain::HoldableVolume(const BucketPlacement& placement) const {
  const std::vector<Eigen::Vector2d> polygon = PlanePolygon(placement);
  const Eigen::Vector2d& tip = polygon.front();
  const Eigen::Vector2d& back_top = polygon.back();
  const bool tip_lower = tip.y() <= back_top.y();
  const Eigen::Vector2d& low_rim = tip_lower ? tip : back_top;
  const Eigen::Vector2d& high_rim = tip_lower ? back_top : tip;
  // The opening (tip to back-wall top) faces up when its outward normal has a positive z.
  const Eigen::Vector2d chord = (back_top - tip).normalized();
  Eigen::Vector2d normal(-chord.y(), chord.x());
  if (normal.dot(Centroid(polygon) - tip) > 0) normal = -normal;  // away from the interior
  if (normal.y() <= 0) return PolygonArea(ClipBelow(polygon, low_rim.y())) * bucket_.width;

  // Loose material stands at up to its angle of repose ρ: the free surface rises from the lower
  // rim towards the higher one at the opening's inclination β, or at ρ when the opening is
  // steeper (the rest runs out over the lower rim). A level surface through the lower rim, the
  // earlier model, lost a third of a heaped load to a racked-back bucket, which a real loader
  // carries at full rack without spilling.
  const double repose = PayloadAngleOfRepose();
  const double run = std::abs(high_rim.x() - low_rim.x());
  const double beta = std::atan2(high_rim.y() - low_rim.y(), run);
  const double toward_high = high_rim.x() >= low_rim.x() ? 1.0 : -1.0;
  const double slope = toward_high * std::tan(std::min(beta, repose));
  const double below_surface = PolygonArea(ClipBelowLine(polygon, low_rim, slope)) * bucket_.width;
  // The heap above the opening: the rated (heaped) capacity less the struck volume when the
  // opening is level. On an opening inclined by β its cross-section is a triangle on the chord
  // with sides at ρ to the horizontal, i.e. base angles ρ − β and ρ + β; relative to the level
  // opening's triangle its area is 2·cot ρ / (cot(ρ − β) + cot(ρ + β)), which falls to 0 at
  // β = ρ, where the surface model above takes over continuously.
  const double heap = std::max(0.0, bucket_.rated_capacity - struck_area_ * bucket_.width);
  double heap_fraction = 0;
  if (beta < repose) {
    const double cot_repose = 1.0 / std::tan(repose);
    const double cot_down = 1.0 / std::tan(repose - beta);
    const double cot_up = 1.0 / std::tan(std::min(repose + beta, M_PI / 2 - 1e-9));
    heap_fraction = 2.0 * cot_repose / (cot_down + cot_up);
  }
  return below_surface + heap * heap_fraction;
}

double BucketTerrain::PayloadAngleOfRepose() const {
  const int material = payload_material();
  // An empty bucket: any loose material; 35° is typical of sand and gravel.
  constexpr double kTypicalRepose = 35.0 * M_PI / 180.0;
  if (material < 0) return kTypicalRepose;
  return world_.materials[material].angle_of_repose;
}

ExchangeResult BucketTerrain::Exchange(const BucketPlacement& placement) {
  ExchangeResult result;
  Terrain& terrain = world_.terrain;
  const std::vector<Eigen::Vector2d> polygon = PlanePolygon(placement);
  double s_min = std::numeric_limits<double>::infinity(), s_max = -s_min;
  for (const auto& p : polygon) s_min = std::min(s_min, p.x()), s_max = std::max(s_max, p.x());
  const double cell_area = terrain.cell_area();

  // Only cells whose surface rises above the bucket's lowest point can meet it: test the height
  // first (one load), the geometry after. Most cells under a bucket are below it.
  double z_min = std::numeric_limits<double>::infinity();
  for (const auto& p : polygon) z_min = std::min(z_min, p.y());
  const std::vector<double>& heights = terrain.heights();
  ForEachCellInStrip(placement, s_min, s_max, z_min, heights, [&](int ix, int iy, double s) {
    double z_low = 0;
    if (!LowerOutline(polygon, s, z_low)) return;
    const double h = terrain.height(ix, iy);
    const double new_height = std::max(z_low, terrain.floor(ix, iy));
    if (h <= new_height) return;
    const double volume = (h - new_height) * cell_area;
    const int material = terrain.material(ix, iy);
    if (material >= 0) {
      payload_mass_ += volume * world_.materials[material].density;
      payload_by_material_[material] += volume;
    }
    payload_volume_ += volume;
    result.captured_volume += volume;
    terrain.SetHeight(ix, iy, new_height);
  });

  // Inside the pile the material around the lip holds what the bucket carries in place: it
  // can take up to its heaped capacity and pushes the rest ahead. In the open it holds what
  // its attitude allows (HoldableVolume), which is why it must be curled before it leaves.
  //
  // "Inside the pile" looks ahead of the cutting edge: away from the machine for a loader's
  // bucket, towards it for an excavator's dragging its bucket in. Looking away from the machine,
  // an excavator's bucket saw only the cut it had left behind, was never "inside", and poured
  // what it took while penetrating onto the strip behind its rim: a column several metres high
  // on the face (found in the truck-loading job). The resistance model keeps Contact()'s loader
  // convention (see bucket_terrain.h).
  const double ahead = cutting_ == CuttingDirection::kTowardsMachine ? -1.0 : 1.0;
  const bool in_pile = ContactAhead(placement, ahead).in_contact;
  const double holdable = in_pile ? std::max(bucket_.rated_capacity, HoldableVolume(placement))
                                  : HoldableVolume(placement);
  if (payload_volume_ > holdable) {
    // Pour over the lower rim, onto the strip just outside it.
    const Eigen::Vector2d& tip = polygon.front();
    const Eigen::Vector2d& back_top = polygon.back();
    const Eigen::Vector2d rim = tip.y() <= back_top.y() ? tip : back_top;
    const double outward = rim.x() >= Centroid(polygon).x() ? 1.0 : -1.0;
    const double excess = payload_volume_ - holdable;
    const double poured =
        Pour(placement, rim, outward, excess, in_pile, std::max(tip.y(), back_top.y()));
    if (poured > 0) {
      const double fraction = poured / payload_volume_;
      payload_mass_ *= 1.0 - fraction;
      for (double& v : payload_by_material_) v *= 1.0 - fraction;
      payload_volume_ -= poured;
      result.spilled_volume = poured;
    }
  }
  return result;
}

double BucketTerrain::Pour(const BucketPlacement& placement, const Eigen::Vector2d& rim,
                           double outward, double volume, bool in_pile, double top) {
  constexpr double kStrip = 0.3, kMaxDistance = 3.0;
  const int material = payload_material();
  Terrain& terrain = world_.terrain;
  if (cutting_ == CuttingDirection::kAwayFromMachine) {
    // A loader's bucket pushes what it cannot hold ahead of its lip inside the pile (the
    // surcharge) and pours it over its lower rim in the open, onto the strip beyond it, above
    // the lip if need be. Kept as the loader's model was when its penetration predictor was
    // trained and its results recorded; the excavator's below bounds the heap (moving the loader
    // to it is open: it needs the predictor retrained and the comparisons rerun).
    const double a = rim.x(), b = rim.x() + outward * kStrip;
    int cells = 0;
    ForEachCellInStrip(placement, std::min(a, b), std::max(a, b),
                       [&](int, int, double) { ++cells; });
    if (cells == 0) return 0.0;  // outside the yard: the bucket keeps it
    const double dh = volume / (cells * terrain.cell_area());
    ForEachCellInStrip(placement, std::min(a, b), std::max(a, b), [&](int ix, int iy, double) {
      if (terrain.material(ix, iy) == Terrain::kNoMaterial && material >= 0) {
        terrain.SetMaterial(ix, iy, static_cast<std::int16_t>(material));
      }
      terrain.SetHeight(ix, iy, terrain.height(ix, iy) + dh);
    });
    return volume;
  }
  // Inside the pile (an excavator's bucket) the pushed material heaps ahead of the lip up to the
  // top of the opening at most; poured out in the open, it falls from the rim and comes to rest
  // at or below it.
  const double ceiling = in_pile ? top : rim.y();
  // No cell rises above that ceiling. It lands in 0.3 m strips across the bucket's width,
  // the nearest first, each filled up to the rim before the next one out; what finds no room
  // within 3 m stays in the bucket. The relaxation to repose spreads it further. (Before, all of
  // it went into the first strip whatever its height: an excavator bucket tipping 0.9 m³ out in
  // one step over a face built a column 2.5 m above its own rim, which the look-ahead then saw
  // as an obstacle.)
  double left = volume;
  for (double d = 0; d < kMaxDistance - 1e-9 && left > 1e-12; d += kStrip) {
    const double a = rim.x() + outward * d, b = rim.x() + outward * (d + kStrip);
    double room = 0;
    int cells = 0;
    ForEachCellInStrip(placement, std::min(a, b), std::max(a, b), [&](int ix, int iy, double) {
      room += std::max(0.0, ceiling - terrain.height(ix, iy));
      ++cells;
    });
    if (cells == 0) break;  // outside the yard
    room *= terrain.cell_area();
    if (room <= 1e-12) continue;
    const double fraction = std::min(1.0, left / room);
    ForEachCellInStrip(placement, std::min(a, b), std::max(a, b), [&](int ix, int iy, double) {
      const double gap = std::max(0.0, ceiling - terrain.height(ix, iy));
      if (gap <= 0) return;
      if (terrain.material(ix, iy) == Terrain::kNoMaterial && material >= 0) {
        terrain.SetMaterial(ix, iy, static_cast<std::int16_t>(material));
      }
      terrain.SetHeight(ix, iy, terrain.height(ix, iy) + fraction * gap);
    });
    left -= fraction * room;
  }
  return volume - std::max(0.0, left);
}

BucketContact BucketTerrain::Contact(const BucketPlacement& placement) const {
  return ContactAhead(placement, 1.0);
}

BucketContact BucketTerrain::ContactAhead(const BucketPlacement& placement, double ahead) const {
  BucketContact contact;
  const std::vector<Eigen::Vector2d> polygon = PlanePolygon(placement);
  contact.tip = polygon.front();
  contact.rim = polygon.back();
  // The uncut surface just ahead of the cutting edge (the cells under the bucket have already
  // been cut down to its outline), averaged across the bucket width; `ahead` +1: away from the
  // machine, −1: towards it.
  const Terrain& terrain = world_.terrain;
  double sum = 0;
  int cells = 0;
  int material_cells[16] = {};
  ForEachCellInStrip(placement,
                     std::min(contact.tip.x() + ahead * 0.05, contact.tip.x() + ahead * 0.30),
                     std::max(contact.tip.x() + ahead * 0.05, contact.tip.x() + ahead * 0.30),
                     [&](int ix, int iy, double) {
                       sum += terrain.height(ix, iy);
                       ++cells;
                       const int m = terrain.material(ix, iy);
                       if (m >= 0 && m < 16) ++material_cells[m];
                     });
  if (cells == 0) return contact;
  contact.depth = std::max(0.0, sum / cells - contact.tip.y());
  int best = 0;
  for (int m = 0; m < 16; ++m) {
    if (material_cells[m] > best) best = material_cells[m], contact.material = m;
  }
  contact.in_contact = contact.depth > 0.01 && contact.material >= 0;
  return contact;
}

int BucketTerrain::payload_material() const {
  int best = -1;
  double most = 0;
  for (std::size_t m = 0; m < payload_by_material_.size(); ++m) {
    if (payload_by_material_[m] > most) most = payload_by_material_[m], best = static_cast<int>(m);
  }
  return best;
}

void BucketTerrain::ClearPayload() {
  payload_volume_ = payload_mass_ = 0;
  std::fill(payload_by_material_.begin(), payload_by_material_.end(), 0.0);
}

double BucketTerrain::RelaxToRepose(const Eigen::Vector2d& center_xy, double half_window,
                                    int max_iterations) {
  Terrain& terrain = world_.terrain;
  const GridGeometry& g = terrain.geometry();
  const int ix0 =
      std::max(0, static_cast<int>((center_xy.x() - half_window - g.origin.x()) / g.resolution));
  const int iy0 =
      std::max(0, static_cast<int>((center_xy.y() - half_window - g.origin.y()) / g.resolution));
  const int ix1 = std::min(
      g.nx - 1, static_cast<int>((center_xy.x() + half_window - g.origin.x()) / g.resolution));
  const int iy1 = std::min(
      g.ny - 1, static_cast<int>((center_xy.y() + half_window - g.origin.y()) / g.resolution));
  if (ix1 <= ix0 || iy1 <= iy0) return 0.0;
  const int w = ix1 - ix0 + 1, h = iy1 - iy0 + 1;
  std::vector<double> delta(static_cast<std::size_t>(w) * h);
  std::vector<double> max_drop(world_.materials.size());
  for (std::size_t m = 0; m < max_drop.size(); ++m) {
    max_drop[m] = g.resolution * std::tan(world_.materials[m].angle_of_repose);
  }
  constexpr double kTolerance = 1e-3;  // [m] steeper than repose by less is left alone
  double moved_total = 0;
  // Sweep only the box of cells that moved in the previous sweep, grown by one cell: the
  // disturbance spreads by at most one cell per sweep.
  int bx0 = 0, by0 = 0, bx1 = w - 1, by1 = h - 1;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    double moved = 0;
    int nx0 = w, ny0 = h, nx1 = -1, ny1 = -1;
    for (int y = by0; y <= by1; ++y) {
      for (int x = bx0; x <= bx1; ++x) delta[y * w + x] = 0.0;
    }
    for (int y = by0; y <= by1; ++y) {
      for (int x = bx0; x <= bx1; ++x) {
        const int ix = ix0 + x, iy = iy0 + y;
        const int material = terrain.material(ix, iy);
        if (material < 0) continue;
        const double hi = terrain.height(ix, iy);
        const double available = terrain.depth(ix, iy);
        double out[4] = {}, total = 0;
        const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
        for (int k = 0; k < 4; ++k) {
          if (nx[k] < bx0 || ny[k] < by0 || nx[k] > bx1 || ny[k] > by1) continue;
          const double excess = hi - terrain.height(ix0 + nx[k], iy0 + ny[k]) - max_drop[material];
          // 1/5 of the excess per neighbour and sweep keeps the explicit scheme from
          // overshooting when all four neighbours take material at once.
          if (excess > kTolerance) out[k] = 0.2 * excess, total += out[k];
        }
        if (total <= 0) continue;
        const double scale = total > available ? available / total : 1.0;
        for (int k = 0; k < 4; ++k) {
          if (out[k] <= 0) continue;
          const double dz = out[k] * scale;
          delta[y * w + x] -= dz;
          delta[ny[k] * w + nx[k]] += dz;
          moved += dz;
        }
        nx0 = std::min(nx0, x), ny0 = std::min(ny0, y);
        nx1 = std::max(nx1, x), ny1 = std::max(ny1, y);
      }
    }
    if (moved == 0) break;
    for (int y = by0; y <= by1; ++y) {
      for (int x = bx0; x <= bx1; ++x) {
        const double d = delta[y * w + x];
        if (d == 0) continue;
        const int ix = ix0 + x, iy = iy0 + y;
        if (d > 0 && terrain.material(ix, iy) == Terrain::kNoMaterial) {
          // Take the material of the highest neighbour that has one (the donor).
          int donor = -1;
          double top = -std::numeric_limits<double>::infinity();
          const int nx[4] = {ix - 1, ix + 1, ix, ix}, ny[4] = {iy, iy, iy - 1, iy + 1};
          for (int k = 0; k < 4; ++k) {
            if (!terrain.InBounds(nx[k], ny[k]) || terrain.material(nx[k], ny[k]) < 0) continue;
            if (terrain.height(nx[k], ny[k]) > top) {
              top = terrain.height(nx[k], ny[k]), donor = terrain.material(nx[k], ny[k]);
            }
          }
          terrain.SetMaterial(ix, iy, static_cast<std::int16_t>(donor));
        }
        terrain.SetHeight(ix, iy, terrain.height(ix, iy) + d);
      }
    }
    moved_total += moved * terrain.cell_area();
    bx0 = std::max(0, nx0 - 2), by0 = std::max(0, ny0 - 2);
    bx1 = std::min(w - 1, nx1 + 2), by1 = std::min(h - 1, ny1 + 2);
  }
  return moved_total;
}

}  // namespace autoshovel::plant
