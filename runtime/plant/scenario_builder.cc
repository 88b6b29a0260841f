#include "runtime/plant/scenario_builder.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace autoshovel::plant {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// SplitMix64 with doubles from the top 53 bits: specified bit for bit, unlike the standard
// distributions, so a seed gives the same pile with every standard library.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  double Uniform() {  // [0, 1)
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  }

 private:
  std::uint64_t state_;
};

struct Lobe {
  int k = 0;
  double amplitude = 0, phase = 0;
};

struct Bump {
  Eigen::Vector2d at = Eigen::Vector2d::Zero();  // pile frame [m]
  double inv_two_sigma2 = 0, amplitude = 0;
};

// The height of one pile above the floor as a function of the world point, and where it may
// exist. Regular shapes are `height − slope · distance to a flat core rectangle` (a point for a
// cone, a segment for a ridge, a rectangle for a low pile); the irregular pile is a cone with a
// lobed rim plus Gaussian bumps and dents.
class PileField {
 public:
  PileField(const Pile& pile, const Bin* bin) : pile_(pile), bin_(bin) {
    c_ = std::cos(pile.yaw);
    s_ = std::sin(pile.yaw);
    const double flank = pile.height / pile.slope;
    switch (pile.shape) {
      case PileShape::kCone:
        break;
      case PileShape::kRidge:
        core_x_ = std::max(0.0, 0.5 * (pile.length - pile.width));
        break;
      case PileShape::kLow:
        core_x_ = std::max(0.0, 0.5 * pile.length - flank);
        core_y_ = std::max(0.0, 0.5 * pile.width - flank);
        break;
      case PileShape::kAgainstWall:
        core_y_ = 0.5 * pile.length;
        break;
      case PileShape::kIrregular:
        MakeIrregular();
        return;
    }
    reach_x_ = core_x_ + flank;
    reach_y_ = core_y_ + flank;
  }

  // Half extents of an axis-aligned world box holding the whole support.
  Eigen::Vector2d WorldHalfExtents() const {
    const double ac = std::abs(c_), as = std::abs(s_);
    return {ac * reach_x_ + as * reach_y_, as * reach_x_ + ac * reach_y_};
  }

  double Height(const Eigen::Vector2d& world) const {
    const Eigen::Vector2d d = world - pile_.center;
    const double x = c_ * d.x() + s_ * d.y(), y = -s_ * d.x() + c_ * d.y();
    if (pile_.shape == PileShape::kAgainstWall && x < 0) return 0;  // behind its wall
    if (bin_ != nullptr && !InsideBin(world)) return 0;
    if (pile_.shape != PileShape::kIrregular) {
      const double qx = std::max(std::abs(x) - core_x_, 0.0);
      const double qy = std::max(std::abs(y) - core_y_, 0.0);
      return pile_.height - pile_.slope * std::hypot(qx, qy);
    }
    const double theta = std::atan2(y, x);
    double rim = 1;
    for (const Lobe& lobe : lobes_) rim += lobe.amplitude * std::cos(lobe.k * theta + lobe.phase);
    double h = pile_.height * (1 - std::hypot(x, y) / (pile_.base_radius * rim));
    for (const Bump& b : bumps_) {
      const double dx = x - b.at.x(), dy = y - b.at.y();
      h += b.amplitude * std::exp(-(dx * dx + dy * dy) * b.inv_two_sigma2);
    }
    return h;
  }

 private:
  // A bin keeps its pile between its side walls and in front of its back wall; in front of the
  // open side the pile may spill out (the repose pass trims what the walls no longer hold).
  bool InsideBin(const Eigen::Vector2d& world) const {
    const Eigen::Vector2d d = world - bin_->front_center;
    const double cb = std::cos(bin_->yaw), sb = std::sin(bin_->yaw);
    const double u = cb * d.x() + sb * d.y(), v = -sb * d.x() + cb * d.y();
    return v < 0 || (std::abs(u) <= 0.5 * bin_->width && v <= bin_->depth);
  }

  void MakeIrregular() {
    Random random(pile_.seed);
    const double r = pile_.base_radius;
    double lobe_sum = 0;
    for (int k = 2; k <= 4; ++k) {
      const Lobe lobe{k, 0.07 * random.Uniform(), kTwoPi * random.Uniform()};
      lobe_sum += lobe.amplitude;
      lobes_.push_back(lobe);
    }
    double positive = 0;  // largest total the bumps can add anywhere
    constexpr int kBumps = 16;
    for (int i = 0; i < kBumps; ++i) {
      const double at_r = 0.8 * r * std::sqrt(random.Uniform());
      const double at_theta = kTwoPi * random.Uniform();
      const double sigma = r * (0.12 + 0.14 * random.Uniform());
      const double amplitude = pile_.roughness * (2 * random.Uniform() - 1);
      bumps_.push_back({at_r * Eigen::Vector2d(std::cos(at_theta), std::sin(at_theta)),
                        1 / (2 * sigma * sigma), amplitude});
      positive += std::max(amplitude, 0.0);
    }
    // Beyond this radius the cone term is below −positive, so the height is negative.
    reach_x_ = reach_y_ = r * (1 + lobe_sum) * (1 + positive / pile_.height);
  }

  const Pile& pile_;
  const Bin* bin_;
  double c_ = 1, s_ = 0;
  double core_x_ = 0, core_y_ = 0;
  double reach_x_ = 0, reach_y_ = 0;
  std::vector<Lobe> lobes_;
  std::vector<Bump> bumps_;
};

// Cell range [first, last] along one axis covering [lo, hi], clamped to the grid and the ring of
// cells just outside it (so that a huge pile costs no more than the grid).
std::pair<int, int> CellRange(double lo, double hi, double origin, double resolution, int n) {
  const auto cell = [&](double v) {
    return static_cast<int>(
        std::clamp(std::floor((v - origin) / resolution), -1.0, static_cast<double>(n)));
  };
  return {cell(lo), cell(hi)};
}

// Piles combine by max: a cell takes the height and material of the highest pile over it.
// Returns false when the pile has material beyond the grid (seen in the ring around it).
bool Rasterise(const PileField& field, const Pile& pile, int index, Terrain& terrain,
               std::vector<int>& owner) {
  const GridGeometry& g = terrain.geometry();
  const Eigen::Vector2d half = field.WorldHalfExtents() + Eigen::Vector2d::Constant(g.resolution);
  const auto [ix0, ix1] = CellRange(pile.center.x() - half.x(), pile.center.x() + half.x(),
                                    g.origin.x(), g.resolution, g.nx);
  const auto [iy0, iy1] = CellRange(pile.center.y() - half.y(), pile.center.y() + half.y(),
                                    g.origin.y(), g.resolution, g.ny);
  bool outside = false;
  for (int iy = iy0; iy <= iy1; ++iy) {
    for (int ix = ix0; ix <= ix1; ++ix) {
      const Eigen::Vector2d p = g.origin + g.resolution * Eigen::Vector2d(ix + 0.5, iy + 0.5);
      const double h = field.Height(p);
      if (!(h > 0)) continue;
      if (!terrain.InBounds(ix, iy)) {
        outside = true;
        continue;
      }
      const double z = terrain.floor(ix, iy) + h;
      if (z > terrain.height(ix, iy)) {
        terrain.SetHeight(ix, iy, z);
        terrain.SetMaterial(ix, iy, static_cast<std::int16_t>(pile.material_index));
        owner[terrain.Index(ix, iy)] = index;
      }
    }
  }
  return !outside;
}

// Bare floor under every wall; returns the mask of wall cells.
std::vector<std::uint8_t> ClearWalls(const World& world, Terrain& terrain,
                                     std::vector<int>& owner) {
  std::vector<std::uint8_t> wall(owner.size(), 0);
  const GridGeometry& g = terrain.geometry();
  for (const OrientedBox& box : world.obstacles) {
    if (box.semantic_class != core::SemanticClass::kWall) continue;
    const double ac = std::abs(std::cos(box.yaw)), as = std::abs(std::sin(box.yaw));
    const double hx = ac * box.half_extents.x() + as * box.half_extents.y();
    const double hy = as * box.half_extents.x() + ac * box.half_extents.y();
    const auto [x0, x1] =
        CellRange(box.center.x() - hx, box.center.x() + hx, g.origin.x(), g.resolution, g.nx);
    const auto [y0, y1] =
        CellRange(box.center.y() - hy, box.center.y() + hy, g.origin.y(), g.resolution, g.ny);
    const int ix0 = std::max(x0, 0), ix1 = std::min(x1, g.nx - 1);
    const int iy0 = std::max(y0, 0), iy1 = std::min(y1, g.ny - 1);
    for (int iy = iy0; iy <= iy1; ++iy) {
      for (int ix = ix0; ix <= ix1; ++ix) {
        if (!FootprintContains(box, terrain.CellCenter(ix, iy))) continue;
        const int i = terrain.Index(ix, iy);
        wall[i] = 1;
        owner[i] = -1;
        terrain.SetHeight(ix, iy, terrain.floor(ix, iy));
      }
    }
  }
  return wall;
}

// Lowers every material cell to at most `neighbour + tan(repose) · distance` over its 8
// neighbours (pairs across a wall cell excepted): chamfer sweeps, forward then backward, until
// nothing changes. Only removes material, so exact cones stay as they are.
void RelaxToRepose(const World& world, Terrain& terrain, const std::vector<std::uint8_t>& wall) {
  std::vector<double> tan_repose;
  for (const auto& material : world.materials) {
    tan_repose.push_back(std::tan(material.angle_of_repose));
  }
  int x0 = terrain.nx(), x1 = -1, y0 = terrain.ny(), y1 = -1;
  for (int iy = 0; iy < terrain.ny(); ++iy) {
    for (int ix = 0; ix < terrain.nx(); ++ix) {
      if (terrain.material(ix, iy) == Terrain::kNoMaterial) continue;
      x0 = std::min(x0, ix), x1 = std::max(x1, ix), y0 = std::min(y0, iy), y1 = std::max(y1, iy);
    }
  }
  if (x1 < 0) return;
  const double r = terrain.resolution(), d = r * std::numbers::sqrt2;
  struct Step {
    int dx, dy;
    double distance;
  };
  const Step forward[4] = {{-1, 0, r}, {-1, -1, d}, {0, -1, r}, {1, -1, d}};
  const Step backward[4] = {{1, 0, r}, {1, 1, d}, {0, 1, r}, {-1, 1, d}};
  constexpr double kSlack = 1e-9;  // [m]: rounding never counts as too steep
  const auto visit = [&](int ix, int iy, const Step* steps) {
    const std::int16_t m = terrain.material(ix, iy);
    if (m == Terrain::kNoMaterial || wall[terrain.Index(ix, iy)]) return false;
    const double h = terrain.height(ix, iy);
    double limit = h;
    for (int k = 0; k < 4; ++k) {
      const int jx = ix + steps[k].dx, jy = iy + steps[k].dy;
      if (!terrain.InBounds(jx, jy) || wall[terrain.Index(jx, jy)]) continue;
      limit = std::min(limit, terrain.height(jx, jy) + tan_repose[m] * steps[k].distance);
    }
    if (limit >= h - kSlack) return false;
    terrain.SetHeight(ix, iy, limit);
    return true;
  };
  for (int pass = 0; pass < 10000; ++pass) {
    bool changed = false;
    for (int iy = y0; iy <= y1; ++iy) {
      for (int ix = x0; ix <= x1; ++ix) changed |= visit(ix, iy, forward);
    }
    for (int iy = y1; iy >= y0; --iy) {
      for (int ix = x1; ix >= x0; --ix) changed |= visit(ix, iy, backward);
    }
    if (!changed) break;
  }
}

}  // namespace

TerrainBuildReport BuildTerrain(World& world, std::vector<Pile>& piles,
                                const std::vector<Bin>& bins) {
  TerrainBuildReport report;
  Terrain& terrain = world.terrain;
  std::vector<int> owner(terrain.heights().size(), -1);
  for (std::size_t i = 0; i < piles.size(); ++i) {
    const Pile& pile = piles[i];
    const Bin* bin = pile.bin >= 0 ? &bins[pile.bin] : nullptr;
    if (!Rasterise(PileField(pile, bin), pile, static_cast<int>(i), terrain, owner)) {
      report.outside_yard.push_back(static_cast<int>(i));
    }
  }
  const std::vector<std::uint8_t> wall = ClearWalls(world, terrain, owner);
  RelaxToRepose(world, terrain, wall);

  for (Pile& pile : piles) {
    pile.volume = 0;
    pile.peak_height = 0;
    pile.cells = 0;
  }
  const double area = terrain.cell_area();
  for (int iy = 0; iy < terrain.ny(); ++iy) {
    for (int ix = 0; ix < terrain.nx(); ++ix) {
      const int who = owner[terrain.Index(ix, iy)];
      if (who < 0 || terrain.material(ix, iy) == Terrain::kNoMaterial) continue;
      Pile& pile = piles[who];
      const double depth = terrain.depth(ix, iy);
      pile.volume += depth * area;
      pile.peak_height = std::max(pile.peak_height, depth);
      ++pile.cells;
    }
  }
  for (std::size_t i = 0; i < piles.size(); ++i) {
    if (piles[i].cells == 0) report.hidden.push_back(static_cast<int>(i));
  }
  return report;
}

void VaryPiles(Scenario& scenario, std::uint64_t seed, double fraction) {
  if (!(fraction >= 0 && fraction <= 0.9)) {
    throw std::invalid_argument("yard variation must be in [0, 0.9], got " +
                                std::to_string(fraction));
  }
  if (fraction == 0) return;
  Random random(seed);
  for (Pile& pile : scenario.piles) {
    pile.height *= 1.0 - fraction * random.Uniform();
    if (pile.shape == PileShape::kIrregular) pile.seed ^= seed;
    if (pile.shape == PileShape::kCone || pile.shape == PileShape::kIrregular) {
      pile.base_radius = pile.height / pile.slope;
    }
  }
  Terrain& terrain = scenario.world.terrain;
  terrain = Terrain(terrain.geometry(), terrain.floor(0, 0));
  BuildTerrain(scenario.world, scenario.piles, scenario.bins);
}

}  // namespace autoshovel::plant
