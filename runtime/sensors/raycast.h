// Ray casting against the simulated yard: the terrain height grid and oriented boxes. Every
// simulated exteroceptive sensor (LiDARs, camera) is built on it.
//
// Terrain surface. The surface is the bilinear interpolation of the cell-centre heights, the
// same surface as plant::Terrain::HeightAt: between four neighbouring cell centres it is the
// patch z(a, b) = h00 (1−a)(1−b) + h10 a (1−b) + h01 (1−a) b + h11 a b, a, b ∈ [0, 1]. It is
// continuous (no 5 cm staircase that flat-topped cells would show a LiDAR as false edges), it
// reproduces any plane exactly, and along a straight ray a, b and z are linear in the ray
// parameter t, so the ray–patch intersection is the root of a quadratic: the hit is exact, not
// marched (cf. Tevs, Ihrke, Seidel, "Maximum mipmaps for fast, accurate, and scalable dynamic
// height field rendering", I3D 2008, §4). For a smooth surface f sampled at spacing h the
// interpolation error is at most h²/8·(|f_xx| + |f_yy|); for a surface of slope ≤ s with kinks
// (a cone's apex and rim) at most s·h/√2 — the LiDAR tests hold the simulator to these bounds.
// The surface covers the grid's rectangle; beyond the outermost cell centres it is extended
// flat (as HeightAt clamps). Outside the rectangle there is nothing: rays that leave the yard
// return no terrain hit.
//
// Empty-space skipping. A max-height pyramid over the patches: level 0 holds each patch's
// maximum (the largest of its four corners: a bilinear patch attains its extrema at corners),
// level L+1 the maximum of 2×2 cells of level L, up to a single cell. The traversal (Tevs et
// al. 2008, Alg. 1) walks the ray through the pyramid, going down a level where the ray may be
// below the cell's maximum and up again after crossing a parent's boundary, so a ray over open
// ground costs O(log n) cells instead of one per patch. When the plant digs or dumps it marks a
// dirty rectangle and UpdateTerrain() rebuilds only the pyramid cells above it.
//
// Boxes. Oriented boxes (obstacles of the world and the extra boxes of the machine carrying the
// sensors) are intersected with the slab test (Kay and Kajiya, SIGGRAPH 1986) in the box frame.
// A ray that starts inside a box does not see that box: a sensor sits in its housing and looks
// out of it, and the own machine's body boxes may enclose a sensor mount.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

#include "runtime/core/semantic_class.h"
#include "runtime/plant/world.h"

namespace autoshovel::sensors {

/// What a ray hit.
struct RayHit {
  bool hit = false;
  double range = std::numeric_limits<double>::infinity();  ///< along the unit direction [m]
  Eigen::Vector3d point = Eigen::Vector3d::Zero();         ///< world [m]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();       ///< unit outward surface normal
  core::SemanticClass semantic_class = core::SemanticClass::kOther;
  double reflectivity = 0;  ///< Lambertian LiDAR reflectivity [0, 1]
  /// Index into RaycastScene::boxes() of the box hit; -1 for the terrain.
  int box = -1;
  /// Terrain hits: the cell containing the hit point (material lookup, texture); -1 for boxes.
  int cell_x = -1, cell_y = -1;
};

/// Material above the floor by more than this makes a cell a pile cell [m]: a few grains
/// spilled on the floor are still ground to the perception stack.
inline constexpr double kPileDepthThreshold = 0.01;

/// Ray–oriented-box slab test. `direction` must be unit length. Returns the entry distance in
/// [0, max_range] and the outward normal of the entry face, or false when the ray misses, the
/// entry lies beyond `max_range`, or the origin is inside the box.
bool IntersectBox(const plant::OrientedBox& box, const Eigen::Vector3d& origin,
                  const Eigen::Vector3d& direction, double max_range, double& range,
                  Eigen::Vector3d& normal);

/// A world prepared for ray casting. Keeps a reference to the World: the world must outlive
/// the scene, and after the terrain or the obstacles change the owner calls UpdateTerrain(),
/// UpdateBoxes() or Update() before the next cast. Cast() is const and keeps no scratch state,
/// so several threads may cast at once.
class RaycastScene {
 public:
  /// `extra_boxes`: bodies that are not part of the world, typically the machine carrying the
  /// sensors (class kOwnLoader), in world coordinates.
  explicit RaycastScene(const plant::World& world,
                        std::vector<plant::OrientedBox> extra_boxes = {});
  /// The scene refers to the world: a temporary would dangle.
  explicit RaycastScene(plant::World&& world,
                        std::vector<plant::OrientedBox> extra_boxes = {}) = delete;

  /// Rebuilds everything from the world: the whole pyramid (≈ 10 ms for 1200 × 1200 cells)
  /// and the boxes. Needed after the grid's geometry changed.
  void Update();
  /// The terrain heights of cells [ix0, ix1] × [iy0, iy1] (inclusive, clamped to the grid)
  /// changed: refreshes the pyramid cells above them, O(area + log n).
  void UpdateTerrain(int ix0, int iy0, int ix1, int iy1);
  /// The world's obstacles moved (or were added or removed).
  void UpdateBoxes();
  /// Replaces the extra boxes (the own machine moved).
  void SetExtraBoxes(std::vector<plant::OrientedBox> extra_boxes);

  /// First surface along the ray origin + t·direction, t ∈ [0, max_range]. `direction` must be
  /// unit length; a non-finite origin or direction hits nothing.
  RayHit Cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
              double max_range) const;
  /// The terrain only (semantic class and reflectivity filled in).
  RayHit CastTerrain(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                     double max_range) const;
  /// The boxes only.
  RayHit CastBoxes(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                   double max_range) const;

  /// Ray against box `index` of boxes() alone (the slab test CastBoxes applies to each box,
  /// with the box's yaw prepared): its entry range in [0, max_range] and outward normal, or
  /// false when it misses, enters beyond max_range, or starts inside the box.
  bool IntersectBoxAt(int index, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                      double max_range, double& range, Eigen::Vector3d& normal) const;
  /// The RayHit of box `index` of boxes() met at `range` along the ray with outward `normal`, as
  /// Cast would report it.
  RayHit BoxHit(int index, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                double range, const Eigen::Vector3d& normal) const;

  const plant::World& world() const { return *world_; }
  /// The world's obstacles followed by the extra boxes, as of the last update.
  const std::vector<plant::OrientedBox>& boxes() const { return boxes_; }
  /// Highest terrain surface point [m] (top of the pyramid).
  double max_terrain_height() const;
  int pyramid_levels() const { return static_cast<int>(levels_.size()); }

 private:
  struct Level {
    int nx = 0, ny = 0;
    std::vector<float> max;  // row-major, rounded up to float
  };
  struct PreparedBox {
    Eigen::Vector3d center;
    Eigen::Vector3d half;
    double c = 1, s = 0;  // cos, sin of yaw
    // World-space bounding sphere for a cheap early reject.
    double radius = 0;
  };

  // The boxes' footprints binned on a uniform xy grid (compressed rows: the boxes of cell k are
  // box_index_[cell_start_[k] .. cell_start_[k + 1])). A ray walks the cells it crosses, nearest
  // first, and stops at the first cell that begins beyond its nearest hit: a yard has dozens of
  // walls and machines, and a LiDAR frame tens of thousands of rays, most of which meet the
  // ground long before most of the boxes. A kd-tree or BVH would do as well at this size; the
  // grid's walk is the terrain pyramid's in two dimensions, and rebuilding it is O(boxes).
  struct BoxGrid {
    double x0 = 0, y0 = 0, cell = 1;  // corner of cell (0, 0), cell size [m]
    int nx = 0, ny = 0;
    double z_lo = 0, z_hi = 0;  // lowest bottom, highest top of all boxes [m]
    std::vector<int> cell_start;
    std::vector<int> box_index;
  };
  void BuildBoxGrid();

  void BuildPyramid();
  float PatchMax(int px, int py) const;
  void RefreshLevels(int px0, int py0, int px1, int py1);
  bool TraverseTerrain(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                       double max_range, RayHit& hit) const;
  bool IntersectPatch(int px, int py, double u0, double v0, double z0, double du, double dv,
                      double dz, double t_in, double t_out, double& t_hit, double& a_hit,
                      double& b_hit) const;
  void FillTerrainHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double t,
                      int px, int py, double a, double b, RayHit& hit) const;

  const plant::World* world_;
  std::vector<plant::OrientedBox> extra_boxes_;
  std::vector<plant::OrientedBox> boxes_;
  std::vector<PreparedBox> prepared_;
  BoxGrid box_grid_;
  std::vector<Level> levels_;  // levels_[0]: (nx + 1) × (ny + 1) patches
  int grid_nx_ = 0, grid_ny_ = 0;
};

/// The boxes of a scene binned across one direction, for many parallel rays: a camera's shadow
/// rays towards the sun. Each box's shadow, its outline projected along the direction onto the
/// plane across it, is entered in the cells of a uniform grid on that plane that it touches, so a
/// ray tests only the boxes whose shadow covers its origin. Built per frame (the machine's own
/// boxes move), O(boxes + cells they cover).
class ParallelRayBoxes {
 public:
  /// `direction` need not be unit length; a zero or non-finite one is refused
  /// (std::invalid_argument).
  ParallelRayBoxes(const RaycastScene& scene, const Eigen::Vector3d& direction);
  /// Whether a box lies along origin + t·direction, t ∈ [0, max_range]: exactly
  /// scene.CastBoxes(origin, direction, max_range).hit.
  bool Occluded(const Eigen::Vector3d& origin, double max_range) const;
  const Eigen::Vector3d& direction() const { return direction_; }

 private:
  const RaycastScene* scene_;
  Eigen::Vector3d direction_, e1_, e2_;
  double x0_ = 0, y0_ = 0, cell_ = 1;
  int nx_ = 0, ny_ = 0;
  bool everywhere_ = false;  // a box without a finite outline: every ray tests every box
  std::vector<int> cell_start_, box_index_;
};

}  // namespace autoshovel::sensors
