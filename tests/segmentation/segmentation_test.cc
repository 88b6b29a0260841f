// Segmentation: the shipped network on held-out simulated frames (a seed no training or
// evaluation set uses), its softmax output, and the errors for bad models and bad frames.
#include "runtime/perception/segmentation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "identification/segmentation/yard_views.h"

namespace autoshovel::perception {
namespace {

using core::SemanticClass;
using identification::ConfusionMatrix;
using identification::YardView;
using identification::YardViewSampler;

std::string SourcePath(const std::string& relative) {
  return std::string(AUTOSHOVEL_SOURCE_DIR) + "/" + relative;
}

const std::string kModel = SourcePath("models/segmentation/yard_segmenter.onnx");
// Training used seed 1, the README's held-out evaluation seed 1000.
constexpr std::uint64_t kTestSeed = 424242;
constexpr int kViewsPerLighting = 12;

const Segmenter& Shipped() {
  static const Segmenter segmenter(kModel);
  return segmenter;
}

// The scenarios named, so that a scenario added later does not change these frames.
const YardViewSampler& Sampler() {
  static const YardViewSampler sampler(SourcePath("models"),
                                       {"cone_pile", "irregular_pile", "low_pile", "mixing_station",
                                        "pile_against_wall", "pile_behind_loader"});
  return sampler;
}

// Per lighting (normal, bright, dim) and over all views.
struct Scores {
  std::vector<ConfusionMatrix> by_lighting = std::vector<ConfusionMatrix>(3);
  ConfusionMatrix all;
};

TEST(Segmentation, HeldOutFramesScoreAsMeasured) {
  Scores scores;
  for (int i = 0; i < 3 * kViewsPerLighting; ++i) {
    const YardView view = Sampler().Render(kTestSeed, static_cast<std::uint64_t>(i));
    const SegmentationResult r = Shipped().Run(view.frame);
    scores.by_lighting[static_cast<int>(view.lighting)].Add(view.frame.labels, r.labels);
    scores.all.Add(view.frame.labels, r.labels);
  }
  for (int l = 0; l < 3; ++l) {
    for (int c = 0; c < core::kNumSemanticClasses; ++c) {
      const auto iou = scores.by_lighting[l].Iou(c);
      std::printf("%-7s %-13s %s\n", plant::ToString(static_cast<plant::Lighting>(l)),
                  std::string(core::kSemanticClassNames[c]).c_str(),
                  iou ? std::to_string(*iou).c_str() : "n/a");
    }
    std::printf("%-7s mIoU %.4f\n", plant::ToString(static_cast<plant::Lighting>(l)),
                scores.by_lighting[l].MeanIou());
  }
  std::printf("all     mIoU %.4f\n", scores.all.MeanIou());
  // Thresholds: these 36 frames measured mIoU 0.939 overall, 0.963 normal, 0.936 bright, 0.926
  // dim, pile 0.924 in normal light, own loader 0.999 (a 300-view set: README.md); the margins
  // absorb small numeric differences of other OpenCV builds and CPUs.
  EXPECT_GE(scores.all.MeanIou(), 0.92);
  EXPECT_GE(scores.by_lighting[0].MeanIou(), 0.93);
  EXPECT_GE(scores.by_lighting[1].MeanIou(), 0.90);
  EXPECT_GE(scores.by_lighting[2].MeanIou(), 0.90);
  EXPECT_GE(*scores.by_lighting[0].Iou(static_cast<int>(SemanticClass::kPile)), 0.90);
  EXPECT_GE(*scores.all.Iou(static_cast<int>(SemanticClass::kOwnLoader)), 0.98);
}

TEST(Segmentation, ProbabilitiesAreASoftmaxAndLabelsItsArgmax) {
  const YardView view = Sampler().Render(kTestSeed, 100, plant::Lighting::kDim);
  const SegmentationResult r = Shipped().Run(view.frame);
  ASSERT_EQ(r.width, view.frame.width);
  ASSERT_EQ(r.height, view.frame.height);
  const std::size_t n = static_cast<std::size_t>(r.width) * r.height;
  ASSERT_EQ(r.probabilities.size(), core::kNumSemanticClasses * n);
  ASSERT_EQ(r.labels.size(), n);
  double worst = 0;
  std::size_t not_argmax = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0;
    int best = 0;
    for (int c = 0; c < core::kNumSemanticClasses; ++c) {
      const float p = r.probabilities[c * n + i];
      ASSERT_TRUE(p >= 0.0f && p <= 1.0f) << "pixel " << i << " class " << c << ": " << p;
      sum += p;
      if (p > r.probabilities[best * n + i]) best = c;
    }
    worst = std::max(worst, std::abs(sum - 1.0));
    // Ties in float probabilities may round either way; the label is the argmax of the scores.
    if (r.probabilities[best * n + i] > r.probabilities[r.labels[i] * n + i]) ++not_argmax;
  }
  EXPECT_LT(worst, 1e-5);
  EXPECT_EQ(not_argmax, 0u);
  // The accessors read the same planes.
  const int u = r.width / 2, v = r.height - 1;
  EXPECT_EQ(r.probability(r.label(u, v), u, v),
            r.probabilities[static_cast<std::size_t>(r.labels[v * r.width + u]) * n +
                            static_cast<std::size_t>(v) * r.width + u]);
}

// At half the resolution (issue 45): the result has the frame's size, each pixel's
// probabilities still sum to 1 (bilinear weights sum to 1), labels are their argmax, and the
// labels mostly agree with full resolution (they differ along class borders). Measured on this
// frame: 94.1 % agree; the bound leaves room for other OpenCV builds.
TEST(Segmentation, AtHalfResolutionTheResultKeepsTheFramesSize) {
  const YardView view = Sampler().Render(kTestSeed, 7, plant::Lighting::kNormal);
  const SegmentationResult full = Shipped().Run(view.frame);
  const SegmentationResult half = Shipped().Run(view.frame, 0.5);
  ASSERT_EQ(half.width, view.frame.width);
  ASSERT_EQ(half.height, view.frame.height);
  const std::size_t n = static_cast<std::size_t>(half.width) * half.height;
  ASSERT_EQ(half.probabilities.size(), core::kNumSemanticClasses * n);
  double worst = 0;
  std::size_t agree = 0, not_argmax = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0;
    int best = 0;
    for (int c = 0; c < core::kNumSemanticClasses; ++c) {
      sum += half.probabilities[c * n + i];
      if (half.probabilities[c * n + i] > half.probabilities[best * n + i]) best = c;
    }
    worst = std::max(worst, std::abs(sum - 1.0));
    not_argmax += half.labels[i] != best;
    agree += half.labels[i] == full.labels[i];
  }
  EXPECT_LT(worst, 1e-5);
  EXPECT_EQ(not_argmax, 0u);
  const double agreement = static_cast<double>(agree) / static_cast<double>(n);
  std::printf("labels agreeing with full resolution: %.1f %%\n", 100 * agreement);
  EXPECT_GT(agreement, 0.90);
  EXPECT_LT(agreement, 1.0);  // a different computation, not the full one returned
  EXPECT_THROW(Shipped().Run(view.frame, 0.0), std::invalid_argument);
  EXPECT_THROW(Shipped().Run(view.frame, 1.5), std::invalid_argument);
}

TEST(Segmentation, SameFrameGivesTheSameResultAndOtherSizesArePadded) {
  const YardView view = Sampler().Render(kTestSeed, 101, plant::Lighting::kBright);
  const SegmentationResult a = Shipped().Run(view.frame);
  const SegmentationResult b = Shipped().Run(view.frame);
  EXPECT_EQ(a.labels, b.labels);
  EXPECT_EQ(a.probabilities, b.probabilities);

  // A 101×37 corner of the frame: padded to 112×48 inside, cropped back.
  sensors::CameraFrame corner;
  corner.width = 101, corner.height = 37;
  for (int v = 0; v < corner.height; ++v) {
    const auto* row = view.frame.bgr.data() + 3 * static_cast<std::size_t>(v) * view.frame.width;
    corner.bgr.insert(corner.bgr.end(), row, row + 3 * corner.width);
  }
  const SegmentationResult c = Shipped().Run(corner);
  EXPECT_EQ(c.width, 101);
  EXPECT_EQ(c.height, 37);
  EXPECT_EQ(c.labels.size(), 101u * 37u);
  EXPECT_EQ(c.probabilities.size(), 7u * 101u * 37u);
}

// The message of the exception `f` throws, or "" when it throws none of type E.
template <typename E, typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "";
}

TEST(Segmentation, MissingCorruptAndWrongShapeModelsAreRefusedNamingTheFile) {
  const std::string missing = testing::TempDir() + "/no_such_model.onnx";
  std::remove(missing.c_str());
  std::string message = ErrorOf<std::runtime_error>([&] { Segmenter s(missing); });
  EXPECT_NE(message.find(missing), std::string::npos) << message;
  EXPECT_NE(message.find("no such file"), std::string::npos) << message;

  const std::string corrupt = testing::TempDir() + "/corrupt_model.onnx";
  {
    std::ofstream f(corrupt, std::ios::binary);
    for (int i = 0; i < 4096; ++i) f.put(static_cast<char>((i * 7919) & 0xff));
  }
  message = ErrorOf<std::runtime_error>([&] { Segmenter s(corrupt); });
  EXPECT_NE(message.find(corrupt), std::string::npos) << message;
  EXPECT_NE(message.find("not an ONNX network"), std::string::npos) << message;
  std::remove(corrupt.c_str());

  // Valid ONNX, but 3 output planes (identification/segmentation/make_test_models.py).
  const std::string three = SourcePath("tests/segmentation/data/three_classes.onnx");
  message = ErrorOf<std::runtime_error>([&] { Segmenter s(three); });
  EXPECT_NE(message.find(three), std::string::npos) << message;
  EXPECT_NE(message.find("gives 1x3x384x480"), std::string::npos) << message;
  EXPECT_NE(message.find("expected 1x7x384x480"), std::string::npos) << message;
}

TEST(Segmentation, FramesWithoutPixelsOrWithAMismatchedBufferAreRefused) {
  sensors::CameraFrame empty;
  empty.width = 480, empty.height = 383;
  std::string message = ErrorOf<std::invalid_argument>([&] { Shipped().Run(empty); });
  EXPECT_NE(message.find("no pixels"), std::string::npos) << message;

  sensors::CameraFrame short_buffer = empty;
  short_buffer.bgr.assign(480 * 383 * 3 - 3, 0);
  message = ErrorOf<std::invalid_argument>([&] { Shipped().Run(short_buffer); });
  EXPECT_NE(message.find("needs 551520 bgr bytes, got 551517"), std::string::npos) << message;

  sensors::CameraFrame no_size;
  no_size.bgr.assign(300, 0);
  message = ErrorOf<std::invalid_argument>([&] { Shipped().Run(no_size); });
  EXPECT_NE(message.find("no pixels"), std::string::npos) << message;
}

}  // namespace
}  // namespace autoshovel::perception
