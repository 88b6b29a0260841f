// Step 3 of §4.1: the interpretation tree, depth-first with pruning, over synthetic regions.
#include "runtime/perception/truck/interpretation_tree.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "synthetic_regions.h"

namespace autoshovel::perception {
namespace {

using truck_sim::FlatGround;
using truck_sim::FlatRegion;
using truck_sim::IdealBed;
using truck_sim::VerticalRegion;

// The ideal bed's faces after the ground and a set of distractors: a flush cab side, the cab's
// back above the headboard (geometrically a possible headboard: only verification, which sees
// the gap between them, can tell; here it has less support), a retaining wall behind the
// truck, a container's side and top, a wheel, a second wall at a bed's width behind the
// container. Returns the index of each bed face in BedFace order.
std::vector<PlanarRegion> Scene(std::array<int, kNumBedFaces>* face_index) {
  const double hw = 0.5 * IdealBed::kWidth + IdealBed::kThickness;
  std::vector<PlanarRegion> regions{
      FlatRegion({0, 2, 0}, {1, 0, 0}, 20, 10, 20000),                         // ground
      VerticalRegion({0, -1, 0}, {4.6, -hw + 0.05, 2.0}, 1.1, 0.9, 3.1, 3.1),  // cab side
      VerticalRegion({-1, 0, 0}, {3.35, 0, 2.95}, 1.1, 2.75, 3.1, 3.1, 150),   // cab back
      VerticalRegion({0, -1, 0}, {0, 12, 1.5}, 10, 0, 3, 3, 2000),             // wall
      VerticalRegion({0, -1, 0}, {-12, 5, 1.25}, 3, 0, 2.5, 2.5),              // box side
      FlatRegion({-12, 6.2, 2.5}, {1, 0, 0}, 3, 1.2),                          // box top
      VerticalRegion({0, -1, 0}, {-1.5, -hw + 0.02, 0.5}, 0.5, 0, 1.0, 1.0),   // wheel
      VerticalRegion({0, -1, 0}, {-12, 7.6, 1.5}, 3, 0.5, 2.5, 2.5),           // 2nd wall
  };
  const std::vector<PlanarRegion> faces = IdealBed::Faces();
  for (int i = 0; i < kNumBedFaces; ++i) {
    (*face_index)[static_cast<std::size_t>(i)] = static_cast<int>(regions.size());
    regions.push_back(faces[static_cast<std::size_t>(i)]);
  }
  return regions;
}

// Accepts every interpretation; scores by support.
InterpretationVerifier AcceptAll(const std::vector<PlanarRegion>& regions) {
  return [&regions](const Interpretation& interpretation) -> std::optional<double> {
    double support = 0;
    for (int r : interpretation.region) {
      if (r >= 0) support += regions[static_cast<std::size_t>(r)].num_points;
    }
    return support;
  };
}

TEST(InterpretationTree, MatchesEveryFaceOfTheBedAmongDistractors) {
  std::array<int, kNumBedFaces> truth{};
  const std::vector<PlanarRegion> regions = Scene(&truth);
  const InterpretationSearchResult result =
      SearchInterpretationTree(regions, TruckBedModel{}, FlatGround(0), AcceptAll(regions));
  ASSERT_TRUE(result.found);
  EXPECT_EQ(result.best.NumMatched(), kNumBedFaces);
  // With an always-accepting verifier the mirror image (headboard and tailgate swapped) is just
  // as consistent; both must be among the verified, and sides and floor must be right.
  EXPECT_EQ(result.best[BedFace::kNearSide], truth[0]);
  EXPECT_EQ(result.best[BedFace::kFarSide], truth[1]);
  EXPECT_EQ(result.best[BedFace::kFloor], truth[2]);
  const bool straight =
      result.best[BedFace::kHeadboard] == truth[3] && result.best[BedFace::kTailgate] == truth[4];
  const bool mirrored =
      result.best[BedFace::kHeadboard] == truth[4] && result.best[BedFace::kTailgate] == truth[3];
  EXPECT_TRUE(straight || mirrored);
  EXPECT_FALSE(result.truncated);
}

TEST(InterpretationTree, PruningVisitsAFractionOfTheTree) {
  std::array<int, kNumBedFaces> truth{};
  const std::vector<PlanarRegion> regions = Scene(&truth);
  const InterpretationSearchResult result =
      SearchInterpretationTree(regions, TruckBedModel{}, FlatGround(0), AcceptAll(regions));
  // Without pairwise pruning a depth-first search would expand every combination of unary
  // candidates (each level: its candidates or "none").
  double full = 1;
  double nodes_full = 1;
  for (int count : result.candidates) {
    full *= count + 1;
    nodes_full += full;
  }
  EXPECT_GT(result.candidates[FaceIndex(BedFace::kNearSide)],
            2);  // distractors do pass unary tests
  EXPECT_LT(static_cast<double>(result.nodes), 0.1 * nodes_full);
  EXPECT_LT(result.complete, 10);
}

TEST(InterpretationTree, HiddenFacesAreMatchedToNone) {
  std::array<int, kNumBedFaces> truth{};
  std::vector<PlanarRegion> regions = Scene(&truth);
  // Hide the floor and the tailgate: move them far away, where they fit nothing.
  regions[static_cast<std::size_t>(truth[2])].centroid += Eigen::Vector3d(40, 0, 0);
  regions[static_cast<std::size_t>(truth[4])].centroid += Eigen::Vector3d(0, 40, 0);
  const InterpretationSearchResult result =
      SearchInterpretationTree(regions, TruckBedModel{}, FlatGround(0), AcceptAll(regions));
  ASSERT_TRUE(result.found);
  EXPECT_EQ(result.best.NumMatched(), 3);
  EXPECT_EQ(result.best[BedFace::kFloor], -1);
  EXPECT_EQ(result.best[BedFace::kNearSide], truth[0]);
  EXPECT_EQ(result.best[BedFace::kFarSide], truth[1]);
}

TEST(InterpretationTree, VerificationSelectsAndRejects) {
  std::array<int, kNumBedFaces> truth{};
  const std::vector<PlanarRegion> regions = Scene(&truth);
  // Rejecting the mirror image leaves the straight interpretation.
  const InterpretationVerifier accept_all = AcceptAll(regions);
  const InterpretationVerifier straight_only =
      [&](const Interpretation& i) -> std::optional<double> {
    if (i[BedFace::kHeadboard] == truth[4] || i[BedFace::kTailgate] == truth[3]) {
      return std::nullopt;
    }
    return accept_all(i);
  };
  InterpretationSearchResult result =
      SearchInterpretationTree(regions, TruckBedModel{}, FlatGround(0), straight_only);
  ASSERT_TRUE(result.found);
  EXPECT_EQ(result.best.region,
            (std::array<int, kNumBedFaces>{truth[0], truth[1], truth[2], truth[3], truth[4]}));
  // Rejecting everything: complete interpretations were tried, none verified.
  result = SearchInterpretationTree(regions, TruckBedModel{}, FlatGround(0),
                                    [](const Interpretation&) { return std::nullopt; });
  EXPECT_FALSE(result.found);
  EXPECT_GT(result.complete, 0);
  EXPECT_EQ(result.verified, 0);
}

TEST(InterpretationTree, BothSideWallsAreRequired) {
  // The bed without its far side, on the ground: floor, headboard and tailgate still fit the near
  // side, but no interpretation is complete without both side walls.
  std::vector<PlanarRegion> regions{FlatRegion({0, 2, 0}, {1, 0, 0}, 20, 10, 20000)};
  const std::vector<PlanarRegion> faces = IdealBed::Faces();
  for (BedFace face : kAllBedFaces) {
    if (face != BedFace::kFarSide)
      regions.push_back(faces[static_cast<std::size_t>(FaceIndex(face))]);
  }
  const InterpretationSearchResult result =
      SearchInterpretationTree(regions, TruckBedModel{}, FlatGround(0), AcceptAll(regions));
  EXPECT_FALSE(result.found);
  EXPECT_EQ(result.complete, 0);
}

TEST(InterpretationTree, NodeCapTruncatesAndBadInputThrows) {
  std::array<int, kNumBedFaces> truth{};
  const std::vector<PlanarRegion> regions = Scene(&truth);
  InterpretationTreeParams params;
  params.max_nodes = 3;
  const InterpretationSearchResult result =
      SearchInterpretationTree(regions, TruckBedModel{}, FlatGround(0), AcceptAll(regions), params);
  EXPECT_TRUE(result.truncated);
  EXPECT_EQ(result.nodes, 3);
  EXPECT_THROW(SearchInterpretationTree(regions, TruckBedModel{}, FlatGround(0), {}),
               std::invalid_argument);
  params.max_nodes = 0;
  EXPECT_THROW(
      SearchInterpretationTree(regions, TruckBedModel{}, FlatGround(0), AcceptAll(regions), params),
      std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::perception
