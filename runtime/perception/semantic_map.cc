#include "runtime/perception/semantic_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "runtime/core/semantic_class.h"
#include "runtime/perception/ground_plane.h"

namespace autoshovel::perception {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int kBlock = 4;  // pixels per side of an occlusion-buffer block

// Semantic class → the three confidences of Eq. (11). The own machine is neither: its pixels
// carry no information about the cell behind them (and its returns were removed from the map).
struct Confidences {
  float ground, pile, obstacle;
  float hard;  // the part of `obstacle` that is a machine, a person or a wall
};

Confidences Collapse(const ClassProbabilities& p, int pixel) {
  const std::size_t plane = static_cast<std::size_t>(p.width) * p.height;
  auto at = [&](core::SemanticClass c) { return p.planes[static_cast<int>(c) * plane + pixel]; };
  using core::SemanticClass;
  const float ground = at(SemanticClass::kGround), pile = at(SemanticClass::kPile);
  const float hard =
      at(SemanticClass::kOtherLoader) + at(SemanticClass::kPerson) + at(SemanticClass::kWall);
  const float obstacle = hard + at(SemanticClass::kOther);
  const float sum = ground + pile + obstacle;
  // A pixel that is mostly the own machine says nothing about the cell: renormalising its
  // small remainder would turn a network's 1 % doubt into a confident class.
  if (!(sum > 0.5f)) return {kNaN, kNaN, kNaN, kNaN};
  return {ground / sum, pile / sum, obstacle / sum, hard / sum};
}

// Whether a pixel block within one block of the pixel rectangle [u0, u1] × [v0, v1] holds a
// surface nearer than `depth_limit`.
bool BesideOccludingContour(const std::vector<float>& nearest, int bw, int bh, int u0, int u1,
                            int v0, int v1, float depth_limit) {
  const int bu0 = std::max(0, u0 / kBlock - 1), bu1 = std::min(bw - 1, u1 / kBlock + 1);
  const int bv0 = std::max(0, v0 / kBlock - 1), bv1 = std::min(bh - 1, v1 / kBlock + 1);
  for (int bv = bv0; bv <= bv1; ++bv) {
    for (int bu = bu0; bu <= bu1; ++bu) {
      if (nearest[bv * bw + bu] < depth_limit) return true;
    }
  }
  return false;
}

// The elevation at `xy`, bilinear between the centres of the four cells around it (the
// grid's matrix is indexed from its lower corner, as planning's Interpolate reads it); a
// missing neighbour takes the height of the cell holding `xy`. NaN outside the map or over a
// hole. On the hot path of the ray casts below: index arithmetic, no IndexOf per corner.
float InterpolatedHeight(const GridMap& g, const Eigen::MatrixXf& elevation,
                         const Eigen::Vector2d& xy) {
  const int nx = g.size().x(), ny = g.size().y();
  const Eigen::Vector2d origin = g.position() - g.length() / 2;
  // Continuous index: cell i's centre at i.
  const double fx = (xy.x() - origin.x()) / g.resolution() - 0.5;
  const double fy = (xy.y() - origin.y()) / g.resolution() - 0.5;
  if (!(fx >= -0.5 && fy >= -0.5 && fx < nx - 0.5 && fy < ny - 0.5)) return kNaN;
  // The cell holding `xy`, as GridMap::IndexOf finds it.
  const float own =
      elevation(static_cast<int>(std::floor(fx + 0.5)), static_cast<int>(std::floor(fy + 0.5)));
  if (std::isnan(own)) return kNaN;
  const int ix = std::clamp(static_cast<int>(std::floor(fx)), 0, nx - 1);
  const int iy = std::clamp(static_cast<int>(std::floor(fy)), 0, ny - 1);
  const int jx = std::min(ix + 1, nx - 1), jy = std::min(iy + 1, ny - 1);
  const float tx = static_cast<float>(std::clamp(fx - ix, 0.0, 1.0));
  const float ty = static_cast<float>(std::clamp(fy - iy, 0.0, 1.0));
  auto z = [&](int x, int y) {
    const float v = elevation(x, y);
    return std::isnan(v) ? own : v;
  };
  return (1 - ty) * ((1 - tx) * z(ix, iy) + tx * z(jx, iy)) +
         ty * ((1 - tx) * z(ix, jy) + tx * z(jx, jy));
}

// Standard normal CDF.
double Phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// A mapped cell as the camera sees it: the pixel its centre falls in, its forward depth and the
// image rows its surface covers.
struct Hit {
  int cell, pixel;
  float depth;
  std::int16_t v_min, v_max;  // image rows the cell's surface covers
};

// Pass 1 of SemanticMap::Project: where each mapped cell lands in the w × h image (the camera's
// scaled by sx, sy) and how far it is; `nearest` (bw blocks of kBlock pixels a row) receives
// the nearest depth per pixel block.
std::vector<Hit> ProjectCells(const GridMap& g, const model::Camera& camera,
                              const Eigen::Isometry3d& T_world_camera, int w, int h, double sx,
                              double sy, int bw, std::vector<float>& nearest) {
  const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
  const Eigen::Matrix<float, 3, 3> R = T_camera_world.linear().cast<float>();
  const Eigen::Vector3f t = T_camera_world.translation().cast<float>();
  const Eigen::MatrixXf& elevation = g["elevation"];
  const int nx = g.size().x(), ny = g.size().y();
  const Eigen::Vector3d camera_world = T_world_camera.translation();
  auto project_v = [&](const Eigen::Vector3f& p_world, float& v) {
    const Eigen::Vector3f p_body = R * p_world + t;
    if (!(p_body.x() > 0.3f)) return false;
    v = static_cast<float>((camera.fy * (-p_body.z()) / p_body.x() + camera.cy + 0.5) * sy);
    return true;
  };
  std::vector<Hit> hits;
  hits.reserve(static_cast<std::size_t>(nx) * ny / 4);
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const float z = elevation(ix, iy);
      if (std::isnan(z)) continue;
      const Eigen::Vector2d xy = g.PositionOf(Index(ix, iy));
      const Eigen::Vector3f p_body =
          R * Eigen::Vector3f(static_cast<float>(xy.x()), static_cast<float>(xy.y()), z) + t;
      if (!(p_body.x() > 0.3f)) continue;  // behind or at the lens
      // Pixel centres lie at whole coordinates (the simulator's rays and OpenCV's convention),
      // and a reduced image's pixel j spans [j, j + 1) / s − 1/2 of the camera's: the pixel a
      // point falls in is floor((u + 1/2) s). (Truncating u itself, as before, looked up the
      // pixel up to one to the left and above: over a pile's crest, the wall behind it.)
      const double u = (camera.fx * (-p_body.y()) / p_body.x() + camera.cx + 0.5) * sx;
      const double v = (camera.fy * (-p_body.z()) / p_body.x() + camera.cy + 0.5) * sy;
      if (!(u >= 0 && v >= 0 && u < w && v < h)) continue;
      const int pixel = static_cast<int>(v) * w + static_cast<int>(u);
      const float depth = p_body.x();
      const int block = (static_cast<int>(v) / kBlock) * bw + static_cast<int>(u) / kBlock;
      nearest[block] = std::min(nearest[block], depth);
      // The rows the cell covers: its near and far edges along the viewing direction, at the
      // heights halfway to the neighbouring cells, projected. A pile face towards the camera
      // covers many rows, more than a square of the cell's width would.
      Eigen::Vector2d e = xy - camera_world.head<2>();
      e /= std::max(e.norm(), 1e-6);
      float v_edge[2] = {static_cast<float>(v), static_cast<float>(v)};
      for (int side = 0; side < 2; ++side) {
        const double sign = side == 0 ? -1.0 : 1.0;
        const Eigen::Vector2d edge = xy + sign * 0.5 * g.resolution() * e;
        Index neighbour;
        float z_edge = z;
        if (g.IndexOf(xy + sign * g.resolution() * e, neighbour) &&
            !std::isnan(elevation(neighbour.x(), neighbour.y()))) {
          z_edge = 0.5f * (z + elevation(neighbour.x(), neighbour.y()));
        }
        project_v(
            Eigen::Vector3f(static_cast<float>(edge.x()), static_cast<float>(edge.y()), z_edge),
            v_edge[side]);
      }
      const auto row = [&](float vv) {
        return static_cast<std::int16_t>(std::clamp(static_cast<int>(vv), 0, h - 1));
      };
      hits.push_back({iy * nx + ix, pixel, depth, row(std::min(v_edge[0], v_edge[1])),
                      row(std::max(v_edge[0], v_edge[1]))});
    }
  }
  return hits;
}

}  // namespace

ClassProbabilities FromLabels(const std::vector<std::uint8_t>& labels, int width, int height) {
  ClassProbabilities p;
  p.width = width;
  p.height = height;
  const std::size_t plane = static_cast<std::size_t>(width) * height;
  p.planes.assign(core::kNumSemanticClasses * plane, 0.0f);
  for (std::size_t i = 0; i < plane && i < labels.size(); ++i) {
    p.planes[std::min<int>(labels[i], core::kNumSemanticClasses - 1) * plane + i] = 1.0f;
  }
  return p;
}

SemanticMap::SemanticMap(ElevationMap& map, const SemanticMapConfig& config)
    : map_(map), config_(config) {
  GridMap& g = map_.map();
  for (const char* layer : {"ground_confidence", "pile_confidence", "obstacle_confidence",
                            "steep_obstacle_confidence", "height_ground_confidence", "class"}) {
    if (!g.Exists(layer)) g.Add(layer, kNaN);
  }
  if (!g.Exists("semantic_frames")) g.Add("semantic_frames", 0.0f);
  // A hole takes its nearest observed cell's class evidence with its height (Eq. 9's
  // continuity assumption): a hole behind a person is not pile by its height alone.
  for (const char* layer : {"ground_confidence", "pile_confidence", "obstacle_confidence",
                            "steep_obstacle_confidence"}) {
    map_.FillAlso(layer);
  }
}

long SemanticMap::Project(const ClassProbabilities& probabilities, const model::Camera& camera,
                          const Eigen::Isometry3d& T_world_camera) {
  GridMap& g = map_.map();
  const int w = probabilities.width, h = probabilities.height;
  if (w <= 0 || h <= 0 ||
      probabilities.planes.size() != static_cast<std::size_t>(core::kNumSemanticClasses) * w * h) {
    return 0;
  }
  // The image may be smaller than the camera's (a network run at reduced resolution).
  const double sx = static_cast<double>(w) / camera.width_px;
  const double sy = static_cast<double>(h) / camera.height_px;
  // World → optical: optical x = −body y, optical y = −body z, optical z = body x.
  const Eigen::Matrix<float, 3, 3> R = T_world_camera.inverse().linear().cast<float>();
  const Eigen::MatrixXf& elevation = g["elevation"];

  // Pass 1: where each cell lands and how far it is; the nearest depth per pixel block.
  const int bw = (w + kBlock - 1) / kBlock, bh = (h + kBlock - 1) / kBlock;
  std::vector<float> nearest(static_cast<std::size_t>(bw) * bh,
                             std::numeric_limits<float>::infinity());
  const std::vector<Hit> hits = ProjectCells(g, camera, T_world_camera, w, h, sx, sy, bw, nearest);
  const Eigen::Vector3d camera_world = T_world_camera.translation();
  const int nx = g.size().x();

  // Where a pixel's ray first meets the mapped surface, as a forward depth (the Hit::depth
  // measure), cast lazily for the machine, person and wall pixels the footprints below look at.
  // Such a pixel counts in full for a cell only when it shows the cell or something in front of
  // it: past a pile's crest, or past the edge of a cut, the pixels beside the cell's centre (and
  // at a crest seen edge-on the centre itself) show the wall 2 m behind, and the in-full rule
  // put that wall on the crest, where the crowd look-ahead stopped for it (docs/main_job.md).
  // The map's own cells are the only depth there is: the camera measures none.
  float farthest = 0;
  for (const Hit& hit : hits) farthest = std::max(farthest, hit.depth);
  const float cast_limit = farthest + static_cast<float>(config_.behind_tolerance) + 1.0f;
  const float cast_step = static_cast<float>(0.5 * g.resolution());
  // The surface between cell centres is taken bilinear (a pile's flank sloping across the view
  // is 0.1 m lower at a cell's edge than at its centre), and a ray skimming it within `skim`
  // is not taken as meeting it: a ray grazing a crest passes a few centimetres over the true
  // surface as often as under it, and what the pixel then shows is the wall behind. A ray onto
  // an obstacle's face is that deep below its top at once.
  const float skim = static_cast<float>(config_.skim_height);
  const Eigen::Matrix<float, 3, 3> R_world_camera = R.transpose();
  const Eigen::Vector3f origin = camera_world.cast<float>();
  std::vector<float> surface_depth(static_cast<std::size_t>(w) * h, kNaN);
  auto surface_depth_at = [&](int u, int v) {
    float& depth = surface_depth[static_cast<std::size_t>(v) * w + u];
    if (!std::isnan(depth)) return depth;
    // Body-frame direction through the pixel's centre, scaled to unit forward depth.
    const double u_camera = (u + 0.5) / sx - 0.5, v_camera = (v + 0.5) / sy - 0.5;
    const Eigen::Vector3f d_body(1.0f, -static_cast<float>((u_camera - camera.cx) / camera.fx),
                                 -static_cast<float>((v_camera - camera.cy) / camera.fy));
    const Eigen::Vector3f d_world = R_world_camera * d_body;
    depth = std::numeric_limits<float>::infinity();
    for (float s = 0.3f; s <= cast_limit; s += cast_step) {
      const Eigen::Vector3f p = origin + s * d_world;
      const float z = InterpolatedHeight(g, elevation, Eigen::Vector2d(p.x(), p.y()));
      if (!std::isnan(z) && p.z() <= z - skim) {
        depth = s;
        break;
      }
    }
    return depth;
  };

  // Pass 2: cells not hidden behind nearer ones take the pixel's confidences.
  Eigen::MatrixXf& ground = g["ground_confidence"];
  Eigen::MatrixXf& pile = g["pile_confidence"];
  Eigen::MatrixXf& obstacle = g["obstacle_confidence"];
  Eigen::MatrixXf& steep_obstacle_layer = g["steep_obstacle_confidence"];
  Eigen::MatrixXf& frames = g["semantic_frames"];
  long updated = 0;
  for (const Hit& hit : hits) {
    const int pu = hit.pixel % w, pv = hit.pixel / w;
    const float near = nearest[(pv / kBlock) * bw + pu / kBlock];
    if (hit.depth > near + config_.occlusion_tolerance + 0.03f * near) continue;
    // The cell covers a few pixels: the confidences are their mean, except that a machine,
    // person or wall in the footprint's rows at or below the cell's own centre row counts in
    // full, so that a cell on such an obstacle's silhouette is an obstacle (the seed's safety
    // rule of Eq. 11 applied to the footprint). The rows above the centre show what stands
    // behind the cell: a wall seen over a pile's surface is averaged, not handed to the pile in
    // front of it (docs/main_job.md: that put the look-ahead's sure cells 1.15 m before a bin's
    // back wall, 2.5 m up its 3 m face); so is a hard pixel in the other rows whose ray meets
    // the map behind the cell (surface_depth_at above). "Other" (debris, the sky over a crest)
    // is averaged.
    const int radius = std::clamp(
        static_cast<int>(camera.fx * sx * 0.5 * map_.map().resolution() / hit.depth), 1, 4);
    // Rows: the square of the cell's width, widened to the rows its surface covers (at most
    // four either way). (A footprint of the covered rows alone, thinner for grazing ground
    // cells, averaged too few pixels: the thin low pile lost 0.04 of IoU with the network.)
    const int v_lo = std::max<int>(std::min<int>(hit.v_min, pv - radius), pv - 4);
    const int v_hi = std::min<int>(std::max<int>(hit.v_max, pv + radius), pv + 4);
    // Beside an occluding contour (a much nearer surface within a block of the footprint) the
    // pixels mix the occluder and what lies behind it, and a network's labels blur across the
    // edge: the cell takes no evidence from this frame rather than the occluder's class.
    if (BesideOccludingContour(nearest, bw, bh, pu - radius, pu + radius, v_lo, v_hi,
                               static_cast<float>(config_.contour_depth_ratio) * hit.depth -
                                   static_cast<float>(config_.occlusion_tolerance))) {
      continue;
    }
    // Seen at a grazing angle (its surface a row or two high) a cell's own pixels are not
    // surely its own: a centimetre of height error moves the ray's hit decimetres along, onto
    // whatever stands behind (the in-full rule put a bin's back wall on pile tops seen from
    // 19 m). The class keeps the in-full rule (an obstacle is never pile), but the evidence
    // that an obstacle is *there* ("steep_obstacle_confidence", what the crowd look-ahead
    // stops for) takes the hard pixels in full only from steeper views.
    const bool steep = hit.v_max - hit.v_min >= config_.min_rows_for_hard;
    const float behind = static_cast<float>(config_.behind_tolerance);
    Confidences c{0, 0, 0, 0};
    float hard_max = 0;
    int samples = 0;
    for (int v = v_lo; v <= v_hi; ++v) {
      for (int du = -radius; du <= radius; ++du) {
        const int u = pu + du;
        if (u < 0 || v < 0 || u >= w || v >= h) continue;
        const Confidences p = Collapse(probabilities, v * w + u);
        if (std::isnan(p.ground)) continue;
        c.ground += p.ground, c.pile += p.pile, c.obstacle += p.obstacle;
        if (v > pv && p.hard > hard_max && surface_depth_at(u, v) <= hit.depth + behind) {
          hard_max = p.hard;
        }
        ++samples;
      }
    }
    if (samples == 0) continue;
    c.ground /= samples, c.pile /= samples, c.obstacle /= samples;
    const float steep_obstacle = steep ? std::max(c.obstacle, hard_max) : c.obstacle;
    c.obstacle = std::max(c.obstacle, hard_max);
    const int ix = hit.cell % nx, iy = hit.cell / nx;
    float& n = frames(ix, iy);
    n += 1;
    const float weight = std::max(1.0f / n, static_cast<float>(config_.min_frame_weight));
    auto blend = [&](float& layer, float value) {
      layer = std::isnan(layer) || n == 1 ? value : (1 - weight) * layer + weight * value;
    };
    blend(ground(ix, iy), c.ground);
    blend(pile(ix, iy), c.pile);
    blend(obstacle(ix, iy), c.obstacle);
    blend(steep_obstacle_layer(ix, iy), steep_obstacle);
    ++updated;
  }
  return updated;
}

bool SemanticMap::Fuse() {
  GridMap& g = map_.map();
  const Eigen::MatrixXf& elevation = g["elevation"];
  const Eigen::MatrixXf& variance = g["variance"];
  const int nx = g.size().x(), ny = g.size().y();
  std::vector<Eigen::Vector3d> low;
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const float z = elevation(ix, iy);
      if (std::isnan(z) || z > config_.ground_z0) continue;
      const Eigen::Vector2d xy = g.PositionOf(Index(ix, iy));
      low.emplace_back(xy.x(), xy.y(), z);
    }
  }
  const GroundPlane plane =
      FitGroundPlane(low, config_.ransac_threshold, config_.ransac_iterations);
  if (!plane.ok) return false;
  plane_ = plane.coefficients;
  ground_variance_ = plane.variance;
  const double sigma_z = std::sqrt(plane.variance);

  Eigen::MatrixXf& p1_layer = g["height_ground_confidence"];
  Eigen::MatrixXf& cls = g["class"];
  const Eigen::MatrixXf& ground = g["ground_confidence"];
  const Eigen::MatrixXf& pile = g["pile_confidence"];
  const Eigen::MatrixXf& obstacle = g["obstacle_confidence"];
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const float h = elevation(ix, iy);
      if (std::isnan(h)) {
        p1_layer(ix, iy) = cls(ix, iy) = kNaN;
        continue;
      }
      const Eigen::Vector2d xy = g.PositionOf(Index(ix, iy));
      const double z_ground = plane_.x() * xy.x() + plane_.y() * xy.y() + plane_.z();
      const double sigma_m = std::sqrt(std::max<double>(variance(ix, iy), 1e-8));
      const float p1 = static_cast<float>(Phi((z_ground + sigma_z - h) / sigma_m));  // Eq. (10)
      const float p2 = 1.0f - p1;
      p1_layer(ix, iy) = p1;
      // Eq. (11); a cell no image has seen is classified by its height alone.
      const float g1 = std::isnan(ground(ix, iy)) ? 0.0f : ground(ix, iy);
      const float g2 = std::isnan(pile(ix, iy)) ? 0.0f : pile(ix, iy);
      const float g3 = std::isnan(obstacle(ix, iy)) ? 0.0f : obstacle(ix, iy);
      CellClass c = CellClass::kGround;
      if (g3 > std::max(g1, g2)) {
        c = CellClass::kObstacle;
      } else if (p1 + g1 < p2 + g2) {
        c = CellClass::kPile;
      }
      cls(ix, iy) = static_cast<float>(c);
    }
  }
  return true;
}

CellClass SemanticOnlyClass(float ground, float pile, float obstacle) {
  if (obstacle > std::max(ground, pile)) return CellClass::kObstacle;
  return pile > ground ? CellClass::kPile : CellClass::kGround;
}

CellClass HeightOnlyClass(float p1) { return p1 < 0.5f ? CellClass::kPile : CellClass::kGround; }

}  // namespace autoshovel::perception
