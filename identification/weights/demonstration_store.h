// Expert demonstrations on file: one SQLite database per dataset (docs/weight_tuning.md gives
// the schema and example queries). A demonstration is what a person records in the field too:
// the pile elevation map the machine saw, where it stood, and where the operator shovelled.
//
//   meta(key TEXT PRIMARY KEY, value TEXT)         format = autoshovel-demonstrations-1, ...
//   demonstrations(
//     id INTEGER PRIMARY KEY, kind TEXT,
//     resolution REAL, nx INTEGER, ny INTEGER,      the map: cells and size [m]
//     center_x REAL, center_y REAL,                 its centre, world [m]
//     ground_a REAL, ground_b REAL, ground_c REAL,  ground plane z = a x + b y + c
//     start_x REAL, start_y REAL, start_heading REAL,      hinge pose [m, rad]
//     expert_x REAL, expert_y REAL, expert_heading REAL,   the expert's entry point and δ
//     elevation BLOB,  nx·ny float32 little-endian, x fastest; NaN where unknown [m]
//     class BLOB)      nx·ny bytes: 0 ground, 1 pile, 2 obstacle, 255 unknown
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "runtime/perception/grid_map.h"
#include "runtime/planning/dubins_path.h"

namespace autoshovel::identification {

inline constexpr const char* kDemonstrationFormat = "autoshovel-demonstrations-1";

struct Demonstration {
  int id = 0;
  std::string kind;
  perception::GridMap map;  ///< layers "elevation" and "class" (perception::CellClass)
  Eigen::Vector3d ground_plane = Eigen::Vector3d::Zero();
  planning::Pose2 start;                                ///< hinge pose
  Eigen::Vector2d expert_xy = Eigen::Vector2d::Zero();  ///< where the bucket tip meets the pile
  double expert_heading = 0;                            ///< δ at entry [rad]
};

/// Writes a new dataset; refuses (std::runtime_error naming the file) to overwrite an existing
/// file, so that a recorded dataset is never lost. `meta` is stored beside the format version.
void WriteDemonstrations(const std::filesystem::path& file,
                         const std::vector<Demonstration>& demonstrations,
                         const std::map<std::string, std::string>& meta);

/// Reads a dataset. Every problem (not SQLite, wrong format, a blob of the wrong size, a
/// non-finite pose, a class byte out of range) throws std::runtime_error naming the file and the
/// demonstration's id.
std::vector<Demonstration> ReadDemonstrations(const std::filesystem::path& file,
                                              std::map<std::string, std::string>* meta = nullptr);

}  // namespace autoshovel::identification
