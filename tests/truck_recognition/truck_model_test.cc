// The parametric bed model's constraints (§4.1: sizes, relative centroid positions and angles
// between planes, as ranges).
#include "runtime/perception/truck/truck_model.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "synthetic_regions.h"

namespace autoshovel::perception {
namespace {

using truck_sim::FlatGround;
using truck_sim::FlatRegion;
using truck_sim::IdealBed;
using truck_sim::VerticalRegion;

constexpr BedFace kNear = BedFace::kNearSide;
constexpr BedFace kFar = BedFace::kFarSide;
constexpr BedFace kFloor = BedFace::kFloor;
constexpr BedFace kHead = BedFace::kHeadboard;
constexpr BedFace kTail = BedFace::kTailgate;

class TruckModelTest : public ::testing::Test {
 protected:
  const TruckBedModel model_;
  const GroundEstimate ground_ = FlatGround();
  const std::vector<PlanarRegion> faces_ = IdealBed::Faces();
  const PlanarRegion& Face(BedFace face) const { return faces_[FaceIndex(face)]; }
};

TEST_F(TruckModelTest, IdealFacesPassTheirOwnUnaryConstraints) {
  for (BedFace face : kAllBedFaces) {
    EXPECT_TRUE(UnaryConsistent(model_, face, Face(face), ground_)) << BedFaceName(face);
  }
}

TEST_F(TruckModelTest, UnaryConstraintsRejectWhatNoBedFaceCanBe) {
  // The ground (no floor is that low), a roof 3.5 m up (no floor is that high).
  EXPECT_FALSE(UnaryConsistent(model_, kFloor, FlatRegion({0, 0, 0}, {1, 0, 0}, 3, 1), ground_));
  EXPECT_FALSE(UnaryConsistent(model_, kFloor, FlatRegion({0, 0, 3.5}, {1, 0, 0}, 2, 1), ground_));
  // A pile's flank, tilted 35°: neither wall nor floor.
  PlanarRegion flank = Face(kNear);
  flank.normal = Eigen::Vector3d(0, -std::sin(0.6), std::cos(0.6));
  for (BedFace face : kAllBedFaces) {
    EXPECT_FALSE(UnaryConsistent(model_, face, flank, ground_)) << BedFaceName(face);
  }
  // A wall 12 m long is no near side; a wheel's side (top 1 m up) neither.
  EXPECT_FALSE(UnaryConsistent(model_, kNear, VerticalRegion({0, -1, 0}, {0, -2, 1.5}, 6, 0, 3, 3),
                               ground_));
  EXPECT_FALSE(UnaryConsistent(
      model_, kNear, VerticalRegion({0, -1, 0}, {-1.5, -1.2, 0.5}, 0.5, 0, 1, 1), ground_));
  // A 5 m wide face is no headboard.
  EXPECT_FALSE(UnaryConsistent(model_, kHead, VerticalRegion({-1, 0, 0}, {3, 0, 2}, 2.5, 1.5, 3, 3),
                               ground_));
  // Without a ground estimate, heights above it are not checked.
  EXPECT_TRUE(UnaryConsistent(model_, kFloor, FlatRegion({0, 0, 3.5}, {1, 0, 0}, 2, 1), {}));
}

TEST_F(TruckModelTest, IdealFacesArePairwiseConsistentAndTheCheckIsSymmetric) {
  for (BedFace a : kAllBedFaces) {
    for (BedFace b : kAllBedFaces) {
      if (a == b) continue;
      EXPECT_TRUE(PairConsistent(model_, a, Face(a), b, Face(b)))
          << BedFaceName(a) << " / " << BedFaceName(b);
    }
  }
  // Symmetry on inconsistent pairs too: swap the roles of the two end walls' regions.
  EXPECT_EQ(PairConsistent(model_, kNear, Face(kNear), kHead, Face(kTail)),
            PairConsistent(model_, kHead, Face(kTail), kNear, Face(kNear)));
  EXPECT_THROW(PairConsistent(model_, kNear, Face(kNear), kNear, Face(kNear)),
               std::invalid_argument);
}

TEST_F(TruckModelTest, PairConstraintsRejectWrongGeometry) {
  // Side walls 5 m apart, or not parallel.
  PlanarRegion far = Face(kFar);
  far.centroid.y() += 3.0;
  EXPECT_FALSE(PairConsistent(model_, kNear, Face(kNear), kFar, far));
  far = Face(kFar);
  far.normal = Eigen::Vector3d(0.5, -std::sqrt(0.75), 0);  // 30° off
  EXPECT_FALSE(PairConsistent(model_, kNear, Face(kNear), kFar, far));
  // A floor above the rim.
  PlanarRegion floor = Face(kFloor);
  floor.centroid.z() = IdealBed::kRim + 0.5;
  EXPECT_FALSE(PairConsistent(model_, kNear, Face(kNear), kFloor, floor));
  // A headboard seen from outside (normal pointing away from the bed).
  PlanarRegion outside = Face(kHead);
  outside.normal = -outside.normal;
  outside.axis_u = -outside.axis_u;
  EXPECT_FALSE(PairConsistent(model_, kNear, Face(kNear), kHead, outside));
  // End walls facing the same way, or 10 m apart.
  PlanarRegion tail = Face(kTail);
  tail.normal = Face(kHead).normal;
  EXPECT_FALSE(PairConsistent(model_, kHead, Face(kHead), kTail, tail));
  tail = Face(kTail);
  tail.centroid.x() -= 4.5;
  EXPECT_FALSE(PairConsistent(model_, kHead, Face(kHead), kTail, tail));
  // A far inside face that runs a metre past the headboard's inside.
  PlanarRegion long_far = Face(kFar);
  long_far.centroid.x() += 1.4;
  EXPECT_FALSE(PairConsistent(model_, kFar, long_far, kHead, Face(kHead)));
  // An "end wall" reaching down 2.5 m below the rim (the back of a cab) is no headboard.
  PlanarRegion cab_back = Face(kHead);
  cab_back.z_min = IdealBed::kRim - 2.7;
  EXPECT_FALSE(PairConsistent(model_, kNear, Face(kNear), kHead, cab_back));
}

TEST_F(TruckModelTest, ValidateNamesTheBadField) {
  const auto message = [](const TruckBedModel& m) -> std::string {
    try {
      Validate(m);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(message(model_), "");
  TruckBedModel m;
  m.inner_width = {3.0, 2.0};
  EXPECT_NE(message(m).find("inner_width"), std::string::npos);
  m = {};
  m.nominal_wall_thickness = 0.5;
  EXPECT_NE(message(m).find("nominal_wall_thickness"), std::string::npos);
  m = {};
  m.min_matched_faces = 1;
  EXPECT_NE(message(m).find("min_matched_faces"), std::string::npos);
  m = {};
  m.angle_tolerance_deg = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(m).find("angle_tolerance_deg"), std::string::npos);
}

}  // namespace
}  // namespace autoshovel::perception
