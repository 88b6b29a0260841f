#include "runtime/app/truck_scan/truck_placement.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace autoshovel::app {
namespace {

// Box layout of truck recognition's test trucks (tests/truck_recognition/
// truck_scan_simulation.cc), so that the recogniser meets the bodies it was measured on.
constexpr double kFloorSlab = 0.12;  // floor plate and cross members [m]
constexpr double kSkirt = 0.25;      // side walls reach this far below the floor's top [m]

void Require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("PlaceTruck: " + message);
}

std::string Num(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

void ValidateBody(const TruckBody& b) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  const auto non_negative = [](double v) { return std::isfinite(v) && v >= 0; };
  Require(positive(b.inner_length) && positive(b.inner_width) && positive(b.wall_height) &&
              positive(b.floor_height) && positive(b.wall_thickness) && positive(b.cab_length) &&
              positive(b.cab_width) && positive(b.cab_height) && positive(b.wheel_radius),
          "body '" + b.name + "': every size must be finite and positive");
  Require(non_negative(b.headboard_rise) && non_negative(b.cab_gap),
          "body '" + b.name + "': headboard_rise and cab_gap must be finite and >= 0");
  Require(std::isfinite(b.reflectivity) && b.reflectivity >= 0 && b.reflectivity <= 1,
          "body '" + b.name + "': reflectivity must lie in [0, 1], got " + Num(b.reflectivity));
  // The chassis rails run from just above the wheels' tops up to the floor slab.
  Require(2 * b.wheel_radius - 0.3 < b.floor_height - kFloorSlab,
          "body '" + b.name + "': wheels of radius " + Num(b.wheel_radius) +
              " m leave no room for the chassis under a floor " + Num(b.floor_height) + " m up");
  Require(b.cab_height > 0.9 + 0.1, "body '" + b.name + "': cab_height must exceed 1.0 m");
}

}  // namespace

std::string_view ToString(TruckClass truck_class) {
  switch (truck_class) {
    case TruckClass::kTipper15t:
      return "15 t tipper";
    case TruckClass::kTipper20t:
      return "20 t tipper";
    case TruckClass::kHauler38t:
      return "38 t articulated hauler";
  }
  return "?";
}

TruckBody TruckBodyOf(TruckClass truck_class) {
  TruckBody s;
  s.name = std::string(ToString(truck_class));
  switch (truck_class) {
    case TruckClass::kTipper15t:
      s.inner_length = 4.8;
      s.inner_width = 2.30;
      s.wall_height = 0.90;
      s.floor_height = 1.45;
      s.wall_thickness = 0.06;
      s.headboard_rise = 0.3;
      s.has_tailgate = true;
      s.cab_gap = 0.3;
      s.cab_length = 2.1;
      s.cab_width = 2.3;
      s.cab_height = 3.0;
      s.wheel_radius = 0.5;
      break;
    case TruckClass::kTipper20t:
      s.inner_length = 5.8;
      s.inner_width = 2.35;
      s.wall_height = 1.15;
      s.floor_height = 1.55;
      s.wall_thickness = 0.07;
      s.headboard_rise = 0.3;
      s.has_tailgate = true;
      s.cab_gap = 0.35;
      s.cab_length = 2.2;
      s.cab_width = 2.3;
      s.cab_height = 3.1;
      s.wheel_radius = 0.52;
      break;
    case TruckClass::kHauler38t:
      s.inner_length = 6.2;
      s.inner_width = 3.3;
      s.wall_height = 1.55;
      s.floor_height = 1.95;
      s.wall_thickness = 0.10;
      s.headboard_rise = 0.6;
      s.has_tailgate = false;
      s.cab_gap = 1.0;  // the articulation between the tractor unit and the body
      s.cab_length = 2.6;
      s.cab_width = 2.8;
      s.cab_height = 3.6;
      s.wheel_radius = 0.8;
      break;
  }
  return s;
}

std::vector<TruckBodyBox> TruckBodyBoxes(const TruckBody& body) {
  const double L = body.inner_length;
  const double W = body.inner_width;
  const double H = body.wall_height;
  const double t = body.wall_thickness;
  std::vector<TruckBodyBox> boxes;
  const auto add = [&](std::string part, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    boxes.push_back({std::move(part), lo, hi});
  };
  const double rear_end = -L / 2 - (body.has_tailgate ? t : 0.0);
  const double floor_top = -H;
  const double ground = -body.rim_height();
  add("floor", {-L / 2, -W / 2, floor_top - kFloorSlab}, {L / 2, W / 2, floor_top});
  add("left_side", {rear_end, W / 2, floor_top - kSkirt}, {L / 2 + t, W / 2 + t, 0});
  add("right_side", {rear_end, -W / 2 - t, floor_top - kSkirt}, {L / 2 + t, -W / 2, 0});
  add("headboard", {L / 2, -W / 2 - t, floor_top - kFloorSlab},
      {L / 2 + t, W / 2 + t, body.headboard_rise});
  if (body.has_tailgate) {
    add("tailgate", {-L / 2 - t, -W / 2, floor_top - kFloorSlab}, {-L / 2, W / 2, 0});
  }
  const double cab_start = L / 2 + t + body.cab_gap;
  const double cab_end = cab_start + body.cab_length;
  add("cab", {cab_start, -body.cab_width / 2, ground + 0.9},
      {cab_end, body.cab_width / 2, ground + body.cab_height});
  const double wr = body.wheel_radius;
  add("chassis", {rear_end + 0.2, -0.5, ground + 2 * wr - 0.3},
      {cab_end - 0.2, 0.5, floor_top - kFloorSlab});
  const double wheel_outer = W / 2 + t - 0.02;
  int wheel = 0;
  for (const double axle_x :
       {-L / 2 + 0.9, -L / 2 + 0.9 + 2.4 * wr, cab_start + 0.5 * body.cab_length}) {
    for (const double side : {-1.0, 1.0}) {
      const double y_in = side * (wheel_outer - 0.45);
      const double y_out = side * wheel_outer;
      add("wheel_" + std::to_string(wheel++), {axle_x - wr, std::min(y_in, y_out), ground},
          {axle_x + wr, std::max(y_in, y_out), ground + 2 * wr});
    }
  }
  return boxes;
}

Eigen::Isometry3d TruckPlacement::T_world_bed_corner() const {
  Eigen::Isometry3d T_bed_corner = Eigen::Isometry3d::Identity();
  T_bed_corner.translation() = Eigen::Vector3d(-0.5 * inner_length, -0.5 * inner_width, 0.0);
  return T_world_bed * T_bed_corner;
}

bool TruckPlacement::InsideBed(double x, double y) const {
  const Eigen::Vector3d p_bed = T_world_bed.inverse() * Eigen::Vector3d(x, y, rim_z);
  return std::abs(p_bed.x()) < 0.5 * inner_length && std::abs(p_bed.y()) < 0.5 * inner_width;
}

double TruckPlacement::MaterialInBed(const plant::Terrain& terrain) const {
  double depth_sum = 0;
  for (const int i : floor_cells) depth_sum += terrain.heights()[i] - terrain.floors()[i];
  return depth_sum * terrain.cell_area();
}

TruckPlacement PlaceTruck(const TruckBody& body, const TruckPose& pose, plant::World* world,
                          const TruckPlacementOptions& options) {
  Require(world != nullptr, "world is null");
  ValidateBody(body);
  Require(pose.p_world_bed.allFinite() && std::isfinite(pose.yaw) && std::isfinite(pose.ground_z),
          "the pose must be finite");
  plant::Terrain& terrain = world->terrain;
  Require(terrain.nx() > 0 && terrain.ny() > 0, "the world has no terrain grid");

  const double L = body.inner_length;
  const double W = body.inner_width;
  const double H = body.wall_height;

  TruckPlacement placement;
  placement.body = body;
  placement.pose = pose;
  placement.inner_length = L;
  placement.inner_width = W;
  placement.wall_height = H;
  placement.floor_z = pose.ground_z + body.floor_height;
  placement.rim_z = pose.ground_z + body.rim_height();
  placement.T_world_bed.linear() =
      Eigen::AngleAxisd(pose.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  placement.T_world_bed.translation() =
      Eigen::Vector3d(pose.p_world_bed.x(), pose.p_world_bed.y(), placement.rim_z);
  const Eigen::Isometry3d& T_world_bed = placement.T_world_bed;
  placement.p_world_corners = {T_world_bed * Eigen::Vector3d(L / 2, W / 2, 0),
                               T_world_bed * Eigen::Vector3d(L / 2, -W / 2, 0),
                               T_world_bed * Eigen::Vector3d(-L / 2, -W / 2, 0),
                               T_world_bed * Eigen::Vector3d(-L / 2, W / 2, 0)};

  // --- Terrain under the bed: floor cells and the wall ring. ---
  const double r = terrain.resolution();
  const Eigen::Vector2d axis_x(std::cos(pose.yaw), std::sin(pose.yaw));
  const Eigen::Vector2d axis_y(-axis_x.y(), axis_x.x());
  const auto to_bed = [&](const Eigen::Vector2d& p_world) {
    const Eigen::Vector2d d = p_world - pose.p_world_bed;
    return Eigen::Vector2d(d.dot(axis_x), d.dot(axis_y));
  };
  const double reach = 0.5 * std::hypot(L, W) + 3 * r;  // bed plus its ring, with margin
  const Eigen::Vector2d lo = pose.p_world_bed - Eigen::Vector2d::Constant(reach);
  const Eigen::Vector2d hi = pose.p_world_bed + Eigen::Vector2d::Constant(reach);
  const plant::GridGeometry& grid = terrain.geometry();
  const Eigen::Vector2d grid_hi =
      grid.origin + r * Eigen::Vector2d(static_cast<double>(grid.nx), static_cast<double>(grid.ny));
  Require((lo.array() >= grid.origin.array()).all() && (hi.array() <= grid_hi.array()).all(),
          "the bed at (" + Num(pose.p_world_bed.x()) + ", " + Num(pose.p_world_bed.y()) +
              ") m reaches beyond the terrain grid");
  const int ix0 = static_cast<int>(std::floor((lo.x() - grid.origin.x()) / r));
  const int iy0 = static_cast<int>(std::floor((lo.y() - grid.origin.y()) / r));
  const int ix1 =
      std::min(grid.nx - 1, static_cast<int>(std::ceil((hi.x() - grid.origin.x()) / r)));
  const int iy1 =
      std::min(grid.ny - 1, static_cast<int>(std::ceil((hi.y() - grid.origin.y()) / r)));

  const auto is_floor = [&](int ix, int iy) {
    const Eigen::Vector2d b = to_bed(terrain.CellCenter(ix, iy));
    return std::abs(b.x()) < L / 2 && std::abs(b.y()) < W / 2;
  };
  for (int iy = iy0; iy <= iy1; ++iy) {
    for (int ix = ix0; ix <= ix1; ++ix) {
      if (is_floor(ix, iy)) placement.floor_cells.push_back(terrain.Index(ix, iy));
    }
  }
  Require(!placement.floor_cells.empty(), "the bed covers no terrain cell centre");
  if (options.wall_cells_at_rim) {
    for (int iy = iy0 + 1; iy < iy1; ++iy) {
      for (int ix = ix0 + 1; ix < ix1; ++ix) {
        if (is_floor(ix, iy)) continue;
        // A body without tailgate is open at the rear: soil leaves it there.
        if (!body.has_tailgate && to_bed(terrain.CellCenter(ix, iy)).x() < -L / 2) continue;
        bool next_to_floor = false;
        for (int dy = -1; dy <= 1 && !next_to_floor; ++dy) {
          for (int dx = -1; dx <= 1 && !next_to_floor; ++dx) {
            next_to_floor = is_floor(ix + dx, iy + dy);
          }
        }
        if (next_to_floor) placement.wall_cells.push_back(terrain.Index(ix, iy));
      }
    }
  }
  const auto check_cells = [&](const std::vector<int>& cells, double new_floor, const char* what) {
    for (const int i : cells) {
      const int ix = i % grid.nx;
      const int iy = i / grid.nx;
      Require(terrain.depth(ix, iy) <= 1e-9, std::string("a ") + what + " cell (" +
                                                 std::to_string(ix) + ", " + std::to_string(iy) +
                                                 ") holds " + Num(terrain.depth(ix, iy)) +
                                                 " m of material: a truck does not park on a heap");
      Require(terrain.floor(ix, iy) <= new_floor + 1e-9,
              std::string("the terrain floor of ") + what + " cell (" + std::to_string(ix) + ", " +
                  std::to_string(iy) + ") lies at " + Num(terrain.floor(ix, iy)) +
                  " m, above the truck's " + Num(new_floor) +
                  " m: the truck stands inside the "
                  "terrain");
    }
  };
  check_cells(placement.floor_cells, placement.floor_z, "bed floor");
  check_cells(placement.wall_cells, placement.rim_z, "wall");
  for (const int i : placement.floor_cells) {
    terrain.SetFloor(i % grid.nx, i / grid.nx, placement.floor_z);
  }
  for (const int i : placement.wall_cells) {
    terrain.SetFloor(i % grid.nx, i / grid.nx, placement.rim_z);
  }

  for (const TruckBodyBox& part : TruckBodyBoxes(body)) {
    plant::OrientedBox box;
    box.name = options.name + "_" + part.part;
    box.center = T_world_bed * (0.5 * (part.lo_bed + part.hi_bed));
    box.half_extents = 0.5 * (part.hi_bed - part.lo_bed);
    box.yaw = pose.yaw;
    box.semantic_class = core::SemanticClass::kOtherLoader;
    box.reflectivity = body.reflectivity;
    placement.boxes.push_back(box);
  }
  world->obstacles.insert(world->obstacles.end(), placement.boxes.begin(), placement.boxes.end());
  return placement;
}

}  // namespace autoshovel::app
