// The §4.3 (excavator seed) terrain templates: what each one's score means, and the 5 × 5 /
// 7 × 7 choice from the bucket.
#include "runtime/planning/dump/dump_template.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "runtime/planning/dump/grid_filters.h"

namespace autoshovel::planning {
namespace {

TEST(DumpTemplate, FlatTemplateScoresMinusTheMeanHeightUnderIt) {
  for (const int n : {5, 7}) {
    SCOPED_TRACE(n);
    const Eigen::MatrixXd flat = MakeDumpTemplate(DumpTemplateShape::kFlat, n);
    ASSERT_EQ(flat.rows(), n);
    ASSERT_EQ(flat.cols(), n);
    EXPECT_NEAR(flat.sum(), -1.0, 1e-12);
    Eigen::MatrixXd field(20, 12);
    for (int i = 0; i < field.rows(); ++i) {
      for (int j = 0; j < field.cols(); ++j) field(i, j) = 0.01 * i * i + 0.05 * j;
    }
    const Eigen::MatrixXd score = Correlate(field, flat);
    const int r = n / 2;
    EXPECT_NEAR(score(9, 6), -field.block(9 - r, 6 - r, n, n).mean(), 1e-12);
    // Lower terrain scores higher.
    EXPECT_GT(score(4, 6), score(14, 6));
  }
}

TEST(DumpTemplate, HoleTemplateMeasuresADepressionWhateverTheLevelOrSlope) {
  for (const int n : {5, 7}) {
    SCOPED_TRACE(n);
    const Eigen::MatrixXd hole = MakeDumpTemplate(DumpTemplateShape::kHole, n);
    EXPECT_NEAR(hole.sum(), 0.0, 1e-12);
    EXPECT_NEAR(hole.cwiseMax(0.0).sum(), 1.0, 1e-12);   // ring mean ...
    EXPECT_NEAR(hole.cwiseMin(0.0).sum(), -1.0, 1e-12);  // ... minus inner mean
    // A tilted plane at any level has no depression: score 0 in the interior.
    Eigen::MatrixXd plane(20, 12);
    for (int i = 0; i < 20; ++i) {
      for (int j = 0; j < 12; ++j) plane(i, j) = 0.8 + 0.03 * i - 0.02 * j;
    }
    EXPECT_NEAR(Correlate(plane, hole)(10, 6), 0.0, 1e-12);
    // A pit as wide as the inner block and 0.2 m deep scores its depth at its centre.
    Eigen::MatrixXd pit = plane;
    pit.block(10 - (n / 2 - 1), 6 - (n / 2 - 1), n - 2, n - 2).array() -= 0.2;
    EXPECT_NEAR(Correlate(pit, hole)(10, 6), 0.2, 1e-12);
  }
}

TEST(DumpTemplate, TemplateSizeFollowsTheBucketFootprint) {
  EXPECT_EQ(ChooseTemplateSize(0.60, 0.15), 5);
  EXPECT_EQ(ChooseTemplateSize(0.75, 0.15), 5);  // exactly a 5-cell bucket
  EXPECT_EQ(ChooseTemplateSize(0.89, 0.15), 5);
  EXPECT_EQ(ChooseTemplateSize(0.91, 0.15), 7);
  EXPECT_EQ(ChooseTemplateSize(1.20, 0.15), 7);
  EXPECT_EQ(ChooseTemplateSize(2.00, 0.15), 7);  // the seed's largest
  EXPECT_EQ(ChooseTemplateSize(0.75, 0.10), 7);  // the same bucket on a finer grid
  EXPECT_THROW(ChooseTemplateSize(0.0, 0.15), std::invalid_argument);
  EXPECT_THROW(ChooseTemplateSize(1.0, -0.15), std::invalid_argument);
}

TEST(DumpTemplate, SizesOutsideOddThreeToFifteenAreRejected) {
  for (const int n : {-5, 0, 1, 4, 6, 17}) {
    EXPECT_THROW(MakeDumpTemplate(DumpTemplateShape::kFlat, n), std::invalid_argument) << n;
    EXPECT_THROW(MakeDumpTemplate(DumpTemplateShape::kHole, n), std::invalid_argument) << n;
  }
}

}  // namespace
}  // namespace autoshovel::planning
