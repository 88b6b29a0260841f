// The shipped scenarios load, and the terrain they build obeys the rules of scenario.h: pile
// shapes and volumes, the angle of repose between neighbouring cells, walls that hold and clip
// material, seeded irregular piles, byte-identical rebuilds.
#include "runtime/plant/scenario.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>

#include "runtime/core/diagnostics.h"

namespace autoshovel::plant {
namespace {

namespace fs = std::filesystem;

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
const std::string kMaterials = kModels + "/materials";

std::string ScenarioFile(const std::string& name) {
  return kModels + "/scenarios/" + name + ".yaml";
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Writes `text` to a file of the test's temporary folder, with the materials of models/.
std::string WriteScenario(const std::string& file_name, std::string text) {
  text += "\nmaterials: " + kMaterials + "\n";
  const fs::path path =
      fs::path(::testing::TempDir()) / (std::to_string(::getpid()) + "_" + file_name);
  std::ofstream(path) << text;
  return path.string();
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' not in the text";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Cells whose centre lies under a wall (bin walls, retaining walls, fences).
std::vector<std::uint8_t> WallMask(const World& world) {
  const Terrain& t = world.terrain;
  std::vector<std::uint8_t> wall(t.heights().size(), 0);
  for (int iy = 0; iy < t.ny(); ++iy) {
    for (int ix = 0; ix < t.nx(); ++ix) {
      for (const auto& box : world.obstacles) {
        if (box.semantic_class == core::SemanticClass::kWall &&
            FootprintContains(box, t.CellCenter(ix, iy))) {
          wall[t.Index(ix, iy)] = 1;
        }
      }
    }
  }
  return wall;
}

std::vector<std::string> ShippedScenarios() { return FindScenarios(kModels); }

TEST(Scenarios, AllSixAreShipped) {
  std::set<std::string> names;
  for (const auto& file : ShippedScenarios()) names.insert(fs::path(file).stem().string());
  for (const char* name : {"mixing_station", "cone_pile", "irregular_pile", "low_pile",
                           "pile_against_wall", "pile_behind_loader"}) {
    EXPECT_EQ(names.count(name), 1u) << name;
  }
}

TEST(Scenarios, EveryShippedScenarioLoads) {
  for (const auto& file : ShippedScenarios()) {
    SCOPED_TRACE(file);
    Scenario s;
    try {
      s = LoadScenario(file);
    } catch (const core::InputError& e) {
      FAIL() << e.what();
    }
    EXPECT_EQ(s.name, fs::path(file).stem().string());
    EXPECT_FALSE(s.description.empty());
    EXPECT_EQ(s.sha256.size(), 64u);
    // The loader yards are worked by the XCMG-class loader; the truck-loading face by the 25 t
    // excavator.
    EXPECT_EQ(s.machine, s.name == "truck_loading" ? "excavator_25t" : "xcmg_968ev");
    EXPECT_EQ(s.world.materials.size(), 3u);
    ASSERT_FALSE(s.piles.empty());
    for (const auto& pile : s.piles) {
      EXPECT_GT(pile.cells, 0) << pile.name;
      EXPECT_GT(pile.volume, 0) << pile.name;
      EXPECT_GE(pile.material_index, 0) << pile.name;
      EXPECT_EQ(s.world.materials[pile.material_index].name, pile.material);
      EXPECT_EQ(s.FindPile(pile.name), &pile);
    }
    EXPECT_GT(s.world.terrain.MaterialVolume(), 0);
    int ix = 0, iy = 0;
    ASSERT_TRUE(s.world.terrain.CellOf(s.start.x, s.start.y, ix, iy));
    EXPECT_EQ(s.world.terrain.material(ix, iy), Terrain::kNoMaterial);
  }
}

TEST(Scenarios, ResolveByNameOrPathAndSuggest) {
  EXPECT_EQ(ResolveScenario("cone_pile", kModels), ScenarioFile("cone_pile"));
  EXPECT_EQ(ResolveScenario(ScenarioFile("low_pile"), kModels), ScenarioFile("low_pile"));
  try {
    ResolveScenario("mixing_staton", kModels);
    ADD_FAILURE() << "unknown scenario accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'mixing_station'?"), std::string::npos)
        << e.what();
  }
}

// A folder named like a shipped scenario in the working directory (build/tests/truck_loading in
// a build tree, a run folder named after the scenario) does not hide the scenario; a folder that
// names none is still said to be a folder.
TEST(Scenarios, AFolderOfTheSameNameDoesNotHideTheScenario) {
  const std::filesystem::path before = std::filesystem::current_path();
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "scenario_resolve_cwd";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "cone_pile");
  std::filesystem::create_directories(dir / "no_such_scenario");
  std::filesystem::current_path(dir);
  const std::string resolved = ResolveScenario("cone_pile", kModels);
  std::string folder_error;
  try {
    ResolveScenario("no_such_scenario", kModels);
  } catch (const std::runtime_error& e) {
    folder_error = e.what();
  }
  std::filesystem::current_path(before);
  EXPECT_EQ(resolved, ScenarioFile("cone_pile"));
  EXPECT_NE(folder_error.find("no_such_scenario: "), std::string::npos) << folder_error;
  EXPECT_NE(folder_error.find("folder"), std::string::npos) << folder_error;
}

TEST(Scenarios, ConeVolumeIsOneThirdPiRSquaredH) {
  const Scenario s = LoadScenario(ScenarioFile("cone_pile"));
  const Pile* cone = s.FindPile("gravel_cone");
  ASSERT_NE(cone, nullptr);
  EXPECT_EQ(cone->shape, PileShape::kCone);
  const double repose = s.world.materials[cone->material_index].angle_of_repose;
  EXPECT_NEAR(cone->height / cone->base_radius, std::tan(repose), 1e-12);  // radius from repose
  const double expected =
      std::numbers::pi * cone->base_radius * cone->base_radius * cone->height / 3;
  EXPECT_NEAR(s.world.terrain.MaterialVolume(), expected, 0.01 * expected);
  EXPECT_NEAR(cone->volume, expected, 0.01 * expected);
  EXPECT_NEAR(cone->peak_height, cone->height, 0.05);
}

TEST(Scenarios, FloorCellsHaveNoMaterialAndPileCellsHaveDepth) {
  for (const auto& file : ShippedScenarios()) {
    SCOPED_TRACE(file);
    const Terrain& t = LoadScenario(file).world.terrain;
    for (std::size_t i = 0; i < t.heights().size(); ++i) {
      const double depth = t.heights()[i] - t.floors()[i];
      ASSERT_GE(depth, 0);
      ASSERT_EQ(t.materials()[i] == Terrain::kNoMaterial, depth == 0) << "cell " << i;
    }
  }
}

// Between 8-neighbours, the higher cell stands at most tan(repose of its material) times their
// distance above the lower one; pairs across a wall are exempt (the wall holds the material).
TEST(Scenarios, NoSlopeExceedsTheAngleOfRepose) {
  constexpr double kTolerance = 1e-6;  // [m]
  for (const auto& file : ShippedScenarios()) {
    SCOPED_TRACE(file);
    const Scenario s = LoadScenario(file);
    const Terrain& t = s.world.terrain;
    const std::vector<std::uint8_t> wall = WallMask(s.world);
    int violations = 0;
    double worst_excess_deg = 0;
    for (int iy = 0; iy < t.ny(); ++iy) {
      for (int ix = 0; ix < t.nx(); ++ix) {
        if (wall[t.Index(ix, iy)]) continue;
        for (const auto& [dx, dy] : {std::pair{1, 0}, {0, 1}, {1, 1}, {1, -1}}) {
          const int jx = ix + dx, jy = iy + dy;
          if (!t.InBounds(jx, jy) || wall[t.Index(jx, jy)]) continue;
          const bool i_higher = t.height(ix, iy) >= t.height(jx, jy);
          const int hx = i_higher ? ix : jx, hy = i_higher ? iy : jy;
          const std::int16_t m = t.material(hx, hy);
          if (m == Terrain::kNoMaterial) continue;  // flat floor
          const double distance = t.resolution() * std::hypot(dx, dy);
          const double rise = std::abs(t.height(ix, iy) - t.height(jx, jy));
          const double repose = s.world.materials[m].angle_of_repose;
          if (rise > std::tan(repose) * distance + kTolerance) {
            ++violations;
            worst_excess_deg = std::max(
                worst_excess_deg, (std::atan(rise / distance) - repose) * 180 / std::numbers::pi);
          }
        }
      }
    }
    EXPECT_EQ(violations, 0) << "worst excess " << worst_excess_deg << " deg";
  }
}

TEST(Scenarios, NoMaterialUnderAnyWall) {
  for (const auto& file : ShippedScenarios()) {
    SCOPED_TRACE(file);
    const Scenario s = LoadScenario(file);
    const Terrain& t = s.world.terrain;
    const std::vector<std::uint8_t> wall = WallMask(s.world);
    for (std::size_t i = 0; i < wall.size(); ++i) {
      if (!wall[i]) continue;
      ASSERT_EQ(t.materials()[i], Terrain::kNoMaterial) << "cell " << i;
      ASSERT_EQ(t.heights()[i], t.floors()[i]) << "cell " << i;
    }
  }
}

TEST(Scenarios, AgainstWallPileLiesOnOneSideOfItsWall) {
  const Scenario s = LoadScenario(ScenarioFile("pile_against_wall"));
  const Pile* pile = s.FindPile("sand_against_wall");
  ASSERT_NE(pile, nullptr);
  const OrientedBox* wall = nullptr;
  for (const auto& box : s.world.obstacles) {
    if (box.name == "sand_against_wall/wall") wall = &box;
  }
  ASSERT_NE(wall, nullptr);
  EXPECT_EQ(wall->semantic_class, core::SemanticClass::kWall);
  EXPECT_NEAR(2 * wall->half_extents.z(), 3.0, 1e-12);
  const Eigen::Vector2d outwards(std::cos(pile->yaw), std::sin(pile->yaw));  // from the wall
  EXPECT_NEAR(outwards.y(), -1.0, 1e-12);                                    // faces south
  const Terrain& t = s.world.terrain;
  int cells = 0;
  for (int iy = 0; iy < t.ny(); ++iy) {
    for (int ix = 0; ix < t.nx(); ++ix) {
      if (t.material(ix, iy) == Terrain::kNoMaterial) continue;
      ++cells;
      ASSERT_GT((t.CellCenter(ix, iy) - pile->center).dot(outwards), 0)
          << "material behind the wall at cell " << ix << ", " << iy;
    }
  }
  EXPECT_GT(cells, 1000);
  // Held by the wall, the pile keeps its full height right at the wall's face.
  EXPECT_NEAR(pile->peak_height, pile->height, 0.05);
}

// Two bins; a cone in the first is wider than the bin. Nothing of it may reach under the walls or
// into the second bin; in front of the bins it spreads freely.
TEST(Scenarios, BinWallsClipPiles) {
  const std::string path = WriteScenario("two_bins.yaml", R"(
name: two_bins
description: a cone wider than its bin
yard: {size: [30, 30]}
machine: {name: xcmg_968ev, start: {x: 15, y: 3, heading_deg: 90}}
bins:
  - origin: [5, 15]
    width: 6
    depth: 8
    wall_height: 3
    wall_thickness: 0.4
    contents:
      - name: full
        piles:
          - {name: wide_cone, shape: cone, material: small_gravel, center: [0, 4], height: 3.5}
      - name: empty
)");
  const Scenario s = LoadScenario(path);
  ASSERT_EQ(s.bins.size(), 2u);
  EXPECT_EQ(s.world.obstacles.size(), 4u);  // three side walls and the back wall
  const Pile& cone = s.piles.at(0);
  EXPECT_EQ(cone.bin, 0);
  const Bin& full = s.bins[0];
  const Bin& empty = s.bins[1];
  EXPECT_NEAR((cone.center - (full.front_center + Eigen::Vector2d(0, 4))).norm(), 0, 1e-12);
  const auto in_bin = [](const Bin& bin, const Eigen::Vector2d& p) {
    const Eigen::Vector2d d = p - bin.front_center;
    const double u = std::cos(bin.yaw) * d.x() + std::sin(bin.yaw) * d.y();
    const double v = -std::sin(bin.yaw) * d.x() + std::cos(bin.yaw) * d.y();
    return std::abs(u) <= bin.width / 2 && v >= 0 && v <= bin.depth;
  };
  const Terrain& t = s.world.terrain;
  const std::vector<std::uint8_t> wall = WallMask(s.world);
  int in_full = 0, in_front = 0;
  for (int iy = 0; iy < t.ny(); ++iy) {
    for (int ix = 0; ix < t.nx(); ++ix) {
      if (t.material(ix, iy) == Terrain::kNoMaterial) continue;
      const Eigen::Vector2d p = t.CellCenter(ix, iy);
      ASSERT_FALSE(wall[t.Index(ix, iy)]) << "material under a wall at " << p.transpose();
      ASSERT_FALSE(in_bin(empty, p)) << "material in the empty bin at " << p.transpose();
      in_full += in_bin(full, p);
      in_front += p.y() < full.front_center.y();
    }
  }
  EXPECT_GT(in_full, 0);
  EXPECT_GT(in_front, 0);
  const double unclipped = std::numbers::pi * cone.base_radius * cone.base_radius * cone.height / 3;
  EXPECT_LT(cone.volume, 0.9 * unclipped);
  // The walls hold the pile: it is still full height inside the bin.
  EXPECT_NEAR(cone.peak_height, cone.height, 0.05);
}

TEST(Scenarios, IrregularPileIsDeterminedBySeed) {
  const std::string text = ReadText(ScenarioFile("irregular_pile"));
  const Scenario original = LoadScenario(ScenarioFile("irregular_pile"));
  const Scenario same = LoadScenario(WriteScenario("irregular_same.yaml", text));
  const Scenario other = LoadScenario(
      WriteScenario("irregular_other.yaml", Replace(text, "\nseed: 7\n", "\nseed: 8\n")));
  const Scenario explicit_seed = LoadScenario(
      WriteScenario("irregular_explicit.yaml",
                    Replace(text, "    roughness: 0.45", "    roughness: 0.45\n    seed: 99")));
  EXPECT_EQ(original.piles[0].seed, same.piles[0].seed);
  EXPECT_NE(original.piles[0].seed, other.piles[0].seed);
  EXPECT_EQ(explicit_seed.piles[0].seed, 99u);
  EXPECT_TRUE(original.world.terrain.heights() == same.world.terrain.heights());
  EXPECT_FALSE(original.world.terrain.heights() == other.world.terrain.heights());
  EXPECT_FALSE(original.world.terrain.heights() == explicit_seed.world.terrain.heights());
  // Another seed, the same kind of heap: volumes within a fifth of each other.
  EXPECT_NEAR(other.piles[0].volume, original.piles[0].volume, 0.2 * original.piles[0].volume);
  // And it is irregular: not the cone it is built on.
  const Pile& p = original.piles[0];
  const double cone = std::numbers::pi * p.base_radius * p.base_radius * p.height / 3;
  EXPECT_GT(std::abs(p.volume - cone), 0.02 * cone);
}

TEST(Scenarios, LoadingTwiceGivesByteIdenticalTerrain) {
  const Scenario a = LoadScenario(ScenarioFile("mixing_station"));
  const Scenario b = LoadScenario(ScenarioFile("mixing_station"));
  const Terrain& ta = a.world.terrain;
  const Terrain& tb = b.world.terrain;
  ASSERT_EQ(ta.heights().size(), tb.heights().size());
  EXPECT_EQ(
      std::memcmp(ta.heights().data(), tb.heights().data(), ta.heights().size() * sizeof(double)),
      0);
  EXPECT_EQ(
      std::memcmp(ta.floors().data(), tb.floors().data(), ta.floors().size() * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(ta.materials().data(), tb.materials().data(),
                        ta.materials().size() * sizeof(std::int16_t)),
            0);
  EXPECT_EQ(a.sha256, b.sha256);
}

TEST(Scenarios, MixingStationLayout) {
  const auto start = std::chrono::steady_clock::now();
  const Scenario s = LoadScenario(ScenarioFile("mixing_station"));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RecordProperty("load_seconds", std::to_string(seconds));
  EXPECT_LT(seconds, 3.0);  // about 0.1 s in a release build; generous for loaded machines
  EXPECT_EQ(s.world.terrain.nx(), 1200);
  EXPECT_EQ(s.world.terrain.ny(), 1200);
  ASSERT_EQ(s.bins.size(), 8u);
  for (const auto& bin : s.bins) {
    EXPECT_GE(bin.width, 8.0);
    EXPECT_LE(bin.width, 10.0);
  }
  std::set<std::string> materials;
  std::set<PileShape> shapes;
  bool thin_low_pile = false;
  for (const auto& pile : s.piles) {
    materials.insert(pile.material);
    shapes.insert(pile.shape);
    ASSERT_GE(pile.bin, 0) << pile.name;
    thin_low_pile |= pile.shape == PileShape::kLow && pile.peak_height <= 0.6;
    EXPECT_LE(pile.peak_height, 3.6) << pile.name;
  }
  EXPECT_EQ(materials.size(), 3u);
  EXPECT_GE(shapes.size(), 4u);
  EXPECT_TRUE(thin_low_pile);
  // Obstacles by class and the bins they stand in.
  const auto bin_of = [&](const Eigen::Vector3d& c) {
    for (std::size_t b = 0; b < s.bins.size(); ++b) {
      const Bin& bin = s.bins[b];
      const Eigen::Vector2d d = c.head<2>() - bin.front_center;
      const double u = std::cos(bin.yaw) * d.x() + std::sin(bin.yaw) * d.y();
      const double v = -std::sin(bin.yaw) * d.x() + std::cos(bin.yaw) * d.y();
      if (std::abs(u) <= bin.width / 2 && v >= -1 && v <= bin.depth) return static_cast<int>(b);
    }
    return -1;
  };
  std::set<int> loader_bins, fence_bins, debris_bins;
  int walls = 0, people = 0;
  for (const auto& box : s.world.obstacles) {
    switch (box.semantic_class) {
      case core::SemanticClass::kOtherLoader:
        if (box.name.ends_with("/body")) loader_bins.insert(bin_of(box.center));
        EXPECT_NEAR(2 * box.half_extents.z(), box.name.ends_with("/body") ? 3.4 : 1.19, 1e-9);
        break;
      case core::SemanticClass::kWall:
        if (box.name.starts_with("fence")) {
          fence_bins.insert(bin_of(box.center));
        } else {
          ++walls;
          EXPECT_NEAR(2 * box.half_extents.z(), 3.0, 1e-12) << box.name;
        }
        break;
      case core::SemanticClass::kOther:
        debris_bins.insert(bin_of(box.center));
        break;
      case core::SemanticClass::kPerson:
        ++people;
        EXPECT_NEAR(2 * box.half_extents.z(), 1.8, 1e-12);
        break;
      default:
        ADD_FAILURE() << box.name;
    }
  }
  EXPECT_EQ(loader_bins.size(), 2u);
  EXPECT_EQ(loader_bins.count(-1), 0u);
  EXPECT_EQ(fence_bins.size(), 2u);
  EXPECT_EQ(debris_bins, fence_bins);
  EXPECT_EQ(walls, 6 + 4 + 2);  // side walls of both rows and their back walls
  EXPECT_EQ(people, 1);
  EXPECT_EQ(bin_of({s.start.x, s.start.y, 0}), -1);  // the loader starts in the open area
}

}  // namespace
}  // namespace autoshovel::plant
