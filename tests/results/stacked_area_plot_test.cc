// Stacked area plots, read back pixel by pixel: the bands lie in the stack's order with heights
// in the values' proportion, a zero (or negative, or NaN) series covers no pixel of the plotting
// area, the painted areas keep the series' integrals even with several samples per pixel, the
// legend lists the top of the stack first right of the plotting area, a phase boundary stands at
// its x, and bad input or an unwritable path throws.
#include "runtime/plot/stacked_area_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "runtime/core/file_output.h"
#include "tests/results/test_records.h"

namespace autoshovel::plot {
namespace {

namespace fs = std::filesystem;
using results::testing::ScratchDir;

// Colours no antialiased black, grey or red pixel can take.
constexpr Color kA{200, 60, 20};   // {b, g, r}: blue
constexpr Color kB{40, 190, 60};   // green
constexpr Color kZ{230, 20, 230};  // magenta
constexpr Color kMark{0, 0, 255};  // pure red

bool Is(const cv::Vec3b& p, Color c) { return p[0] == c.b && p[1] == c.g && p[2] == c.r; }

cv::Mat Read(const fs::path& path) {
  cv::Mat image = cv::imread(path.string(), cv::IMREAD_COLOR);
  EXPECT_FALSE(image.empty()) << path;
  return image;
}

// Pixels of colour `c`: how many, and their bounding box (columns and rows, inclusive).
struct Extent {
  int count = 0;
  int col_lo = std::numeric_limits<int>::max(), col_hi = -1;
  int row_lo = std::numeric_limits<int>::max(), row_hi = -1;
};
Extent Find(const cv::Mat& image, Color c, int col_from = 0,
            int col_to = std::numeric_limits<int>::max(), int row_from = 0) {
  Extent e;
  for (int r = row_from; r < image.rows; ++r) {
    for (int col = col_from; col < std::min(col_to, image.cols); ++col) {
      if (!Is(image.at<cv::Vec3b>(r, col), c)) continue;
      ++e.count;
      e.col_lo = std::min(e.col_lo, col), e.col_hi = std::max(e.col_hi, col);
      e.row_lo = std::min(e.row_lo, r), e.row_hi = std::max(e.row_hi, r);
    }
  }
  return e;
}

// Walking up column `col` from the bottom of the image: the first pixel of colour `c` and the
// length of the run of `c` that starts there (-1, 0 when there is none).
struct ColorRun {
  int start = -1;  // the lowest row
  int length = 0;
  int Above() const { return start - length; }  // the row just above the run
};
ColorRun RunUp(const cv::Mat& image, int col, Color c, int from_row) {
  ColorRun run;
  for (int r = from_row; r >= 0; --r) {
    if (Is(image.at<cv::Vec3b>(r, col), c)) {
      run.start = r;
      break;
    }
  }
  if (run.start < 0) return run;
  while (run.start - run.length >= 0 && Is(image.at<cv::Vec3b>(run.start - run.length, col), c))
    ++run.length;
  return run;
}

StackedAreaPlot TwoBands(double a, double b) {
  StackedAreaPlot plot;
  plot.title = "energy by category";
  plot.x_label = "t [s]";
  plot.y_label = "P [kW]";
  plot.width_px = 800;
  plot.height_px = 500;
  plot.x = {0.0, 2.5, 5.0, 7.5, 10.0};
  // Unnamed: no legend, so every pixel of A's or B's colour is in the plotting area.
  plot.series.push_back({"", std::vector<double>(5, a), kA});
  plot.series.push_back({"", std::vector<double>(5, b), kB});
  return plot;
}

TEST(StackedAreaPlot, HasTheRequestedSize) {
  const fs::path dir = ScratchDir("");
  StackedAreaPlot plot = TwoBands(2.0, 1.0);
  WriteStackedAreaPlotPng(plot, dir / "one.png");
  const cv::Mat image = Read(dir / "one.png");
  EXPECT_EQ(image.cols, 800);
  EXPECT_EQ(image.rows, 500);
  EXPECT_FALSE(fs::exists(dir / "one.png.tmp.png"));
}

// A = 2 under B = 1: from the x-axis up, A's colour over 2/3 of the stack, then B's over 1/3,
// then the dark total line, then nothing of either up to the top.
TEST(StackedAreaPlot, BandsStackBottomFirstInProportion) {
  const fs::path dir = ScratchDir("");
  WriteStackedAreaPlotPng(TwoBands(2.0, 1.0), dir / "ab.png");
  const cv::Mat image = Read(dir / "ab.png");
  const Extent a = Find(image, kA);
  ASSERT_GT(a.count, 1000);
  for (int col : {a.col_lo + 3, (a.col_lo + a.col_hi) / 2, a.col_hi - 3}) {
    SCOPED_TRACE("column " + std::to_string(col));
    const ColorRun run_a = RunUp(image, col, kA, image.rows - 1);
    const ColorRun run_b = RunUp(image, col, kB, image.rows - 1);
    ASSERT_GT(run_a.length, 150);
    EXPECT_EQ(run_b.start, run_a.Above()) << "B sits directly on A";
    // Rows are whole pixels and the frame covers A's lowest row: a few pixels of slack.
    const double stack = run_a.length + run_b.length;
    EXPECT_NEAR(run_a.length, 2.0 / 3.0 * stack, 2.0);
    EXPECT_NEAR(run_a.start - 2.0 / 3.0 * stack, run_b.start, 2.0);
    const cv::Vec3b line = image.at<cv::Vec3b>(run_b.Above(), col);
    EXPECT_LT(line[0] + line[1] + line[2], 3 * 100) << "the total: a dark line on top";
    for (int r = run_b.Above(); r >= 0; --r) {
      const cv::Vec3b p = image.at<cv::Vec3b>(r, col);
      ASSERT_FALSE(Is(p, kA) || Is(p, kB)) << "row " << r;
    }
  }
  // Swapped values: B = 2 over A = 1 takes 2/3 of the stack.
  WriteStackedAreaPlotPng(TwoBands(1.0, 2.0), dir / "ba.png");
  const cv::Mat swapped = Read(dir / "ba.png");
  const int col = (a.col_lo + a.col_hi) / 2;
  const ColorRun run_a = RunUp(swapped, col, kA, swapped.rows - 1);
  const ColorRun run_b = RunUp(swapped, col, kB, swapped.rows - 1);
  EXPECT_NEAR(run_b.length, 2.0 / 3.0 * (run_a.length + run_b.length), 2.0);
}

// A series linear between samples: A rising 0 -> 4 under a constant B = 1. The painted areas
// are the integrals (A's mean 2, B's 1), and A's height grows from left to right.
TEST(StackedAreaPlot, AreasAreTheIntegrals) {
  const fs::path dir = ScratchDir("");
  StackedAreaPlot plot = TwoBands(0.0, 1.0);
  plot.series[0].values = {0.0, 1.0, 2.0, 3.0, 4.0};
  WriteStackedAreaPlotPng(plot, dir / "ramp.png");
  cv::Mat image = Read(dir / "ramp.png");
  const Extent a = Find(image, kA), b = Find(image, kB, 0, a.col_hi + 1);
  ASSERT_GT(b.count, 1000);
  EXPECT_NEAR(static_cast<double>(a.count) / b.count, 2.0, 0.03);
  const int quarter = (b.col_hi - b.col_lo) / 4;
  const int h1 = RunUp(image, b.col_lo + quarter, kA, image.rows - 1).length;
  const int h3 = RunUp(image, b.col_hi - quarter, kA, image.rows - 1).length;
  EXPECT_NEAR(h3, 3.0 * h1, 3.0) << "A at 1/4 and 3/4 of the way: 1 and 3";

  // Pulses much narrower than a pixel (6 at every third of 60001 samples, 0 between: mean 2,
  // some 80 samples per column): each column shows its mean, so at every column A stands twice
  // as high as B, and the axis fits the means (3), not the peaks (7). Drawing the value at the
  // column's centre instead would give A anything from 0 to 6.
  StackedAreaPlot pulses = TwoBands(0.0, 1.0);
  pulses.x.clear();
  for (int i = 0; i <= 60000; ++i) pulses.x.push_back(i * 10.0 / 60000);
  pulses.series[0].values.assign(pulses.x.size(), 0.0);
  for (std::size_t i = 0; i < pulses.x.size(); i += 3) pulses.series[0].values[i] = 6.0;
  pulses.series[1].values.assign(pulses.x.size(), 1.0);
  WriteStackedAreaPlotPng(pulses, dir / "pulses.png");
  image = Read(dir / "pulses.png");
  const Extent pa = Find(image, kA), pb = Find(image, kB);
  ASSERT_GT(pb.count, 1000);
  EXPECT_NEAR(static_cast<double>(pa.count) / pb.count, 2.0, 0.02);
  EXPECT_EQ(pa.col_lo, pb.col_lo);
  EXPECT_EQ(pa.col_hi, pb.col_hi);
  for (int col = pa.col_lo; col <= pa.col_hi; ++col) {
    const ColorRun run_a = RunUp(image, col, kA, image.rows - 1);
    const ColorRun run_b = RunUp(image, col, kB, image.rows - 1);
    ASSERT_EQ(run_b.start, run_a.Above()) << "column " << col;
    ASSERT_NEAR(run_a.length, 2.0 * run_b.length, 4.0) << "column " << col;
  }
  EXPECT_GT(pb.row_hi - pb.row_lo, 80) << "B = 1 of an axis to 3.5, not to 7.5";
}

// A zero series between A and B covers no pixel of the plotting area; the legend, right of it,
// lists B (top) first, then Z, then A, each with a swatch.
TEST(StackedAreaPlot, ZeroSeriesCoversNothingAndLegendListsTopFirst) {
  const fs::path dir = ScratchDir("");
  StackedAreaPlot plot = TwoBands(2.0, 1.0);
  plot.series[0].name = "A";
  plot.series[1].name = "B";
  plot.series.insert(plot.series.begin() + 1, {"Z", std::vector<double>(5, 0.0), kZ});
  WriteStackedAreaPlotPng(plot, dir / "azb.png");
  const cv::Mat image = Read(dir / "azb.png");
  // A's band in the lower half of the image: the plotting area's columns (the legend is above).
  const Extent a = Find(image, kA, 0, image.cols, image.rows / 2);
  const int col = (a.col_lo + a.col_hi) / 2;
  const ColorRun run_a = RunUp(image, col, kA, image.rows - 1);
  EXPECT_EQ(RunUp(image, col, kB, image.rows - 1).start, run_a.Above());

  const Extent z = Find(image, kZ);
  ASSERT_GT(z.count, 0) << "Z is in the legend";
  EXPECT_LE(z.count, 18 * 12) << "a swatch, nothing more";
  EXPECT_GT(z.col_lo, a.col_hi + 5) << "right of the plotting area";
  const Extent legend_a = Find(image, kA, a.col_hi + 5), legend_b = Find(image, kB, a.col_hi + 5);
  ASSERT_GT(legend_a.count, 0);
  ASSERT_GT(legend_b.count, 0);
  EXPECT_LT(legend_b.row_hi, z.row_lo);
  EXPECT_LT(z.row_hi, legend_a.row_lo);
  EXPECT_EQ(Find(image, kB, a.col_lo, a.col_hi + 1).col_hi, a.col_hi) << "bands end together";
}

// Negative, NaN and infinite values draw exactly as zeros would: the same picture.
TEST(StackedAreaPlot, NegativeAndNonFiniteValuesDrawAsZero) {
  const fs::path dir = ScratchDir("");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  StackedAreaPlot bad = TwoBands(2.0, 1.0), zero = TwoBands(2.0, 1.0);
  bad.series[0].values = {2.0, -3.0, nan, inf, 2.0};
  zero.series[0].values = {2.0, 0.0, 0.0, 0.0, 2.0};
  bad.series[1].values = {-inf, 1.0, 1.0, 1.0, -1e300};
  zero.series[1].values = {0.0, 1.0, 1.0, 1.0, 0.0};
  ASSERT_NO_THROW(WriteStackedAreaPlotPng(bad, dir / "bad.png"));
  WriteStackedAreaPlotPng(zero, dir / "zero.png");
  const cv::Mat drawn = Read(dir / "bad.png"), expected = Read(dir / "zero.png");
  ASSERT_EQ(drawn.size(), expected.size());
  EXPECT_EQ(cv::norm(drawn, expected, cv::NORM_INF), 0.0);

  // All of A negative or NaN: no A pixel in the plotting area, B starts on the x-axis.
  StackedAreaPlot none = TwoBands(-1.0, 1.0);
  none.series[0].values[2] = nan;
  WriteStackedAreaPlotPng(none, dir / "none.png");
  const cv::Mat image = Read(dir / "none.png");
  EXPECT_EQ(Find(image, kA).count, 0);
  StackedAreaPlot b_only = TwoBands(0.0, 1.0);
  WriteStackedAreaPlotPng(b_only, dir / "b_only.png");
  EXPECT_EQ(cv::norm(image, Read(dir / "b_only.png"), cv::NORM_INF), 0.0);
}

// A phase boundary at t = 5 s of 0..10 s stands in the middle of the bands.
TEST(StackedAreaPlot, PhaseBoundaryAtItsX) {
  const fs::path dir = ScratchDir("");
  StackedAreaPlot plot = TwoBands(2.0, 1.0);
  plot.vertical.push_back({5.0, "lift", kMark, false});
  WriteStackedAreaPlotPng(plot, dir / "phase.png");
  const cv::Mat image = Read(dir / "phase.png");
  const Extent a = Find(image, kA);
  // The line below the label: in the rows of the bands.
  const Extent mark = Find(image, kMark, 0, image.cols, a.row_lo);
  ASSERT_GT(mark.count, 100);
  EXPECT_NEAR(0.5 * (mark.col_lo + mark.col_hi), 0.5 * (a.col_lo + a.col_hi), 2.0);
  EXPECT_LE(mark.col_hi - mark.col_lo, 3) << "one line, 2 px wide";
  EXPECT_LE(mark.row_hi, a.row_hi + 3) << "over the bands, not below the axis";
}

TEST(StackedAreaPlot, PlotsOneAboveTheOther) {
  const fs::path dir = ScratchDir("");
  StackedAreaPlot wide = TwoBands(2.0, 1.0), narrow = TwoBands(1.0, 1.0);
  wide.height_px = 400;
  narrow.width_px = 600;
  narrow.height_px = 300;
  WriteStackedAreaPlotsPng({wide, narrow}, dir / "both.png");
  const cv::Mat image = Read(dir / "both.png");
  EXPECT_EQ(image.cols, 800);
  EXPECT_EQ(image.rows, 700);
  // The lower plot's bands lie in the lower 300 rows.
  EXPECT_GE(Find(image, kA, 0, 500).row_hi, 400);
  EXPECT_THROW(WriteStackedAreaPlotsPng({}, dir / "none.png"), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "none.png"));
}

TEST(StackedAreaPlot, BadInputThrowsNamingIt) {
  const fs::path dir = ScratchDir("");
  StackedAreaPlot plot = TwoBands(2.0, 1.0);
  plot.series[1].name = "boom lift";
  plot.series[1].values.pop_back();
  try {
    WriteStackedAreaPlotPng(plot, dir / "short.png");
    ADD_FAILURE() << "a series shorter than x was drawn";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'boom lift' has 4 values for 5 x"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(WriteStackedAreaPlotsPng({TwoBands(1, 1), plot}, dir / "grid.png"),
               std::invalid_argument);

  StackedAreaPlot backwards = TwoBands(2.0, 1.0);
  backwards.x = {0.0, 2.5, 2.5, 7.5, 10.0};
  EXPECT_THROW(WriteStackedAreaPlotPng(backwards, dir / "backwards.png"), std::invalid_argument);
  backwards.x = {0.0, 2.5, std::nan(""), 7.5, 10.0};
  EXPECT_THROW(WriteStackedAreaPlotPng(backwards, dir / "nan_x.png"), std::invalid_argument);
  for (const char* name : {"short.png", "grid.png", "backwards.png", "nan_x.png"})
    EXPECT_FALSE(fs::exists(dir / name)) << name;

  // Degenerate but valid: no samples, or one, draws empty axes.
  StackedAreaPlot empty;
  EXPECT_NO_THROW(WriteStackedAreaPlotPng(empty, dir / "empty.png"));
  StackedAreaPlot one = TwoBands(2.0, 1.0);
  one.x = {3.0};
  one.series[0].values = {2.0};
  one.series[1].values = {1.0};
  EXPECT_NO_THROW(WriteStackedAreaPlotPng(one, dir / "one.png"));
  EXPECT_EQ(Read(dir / "one.png").cols, 800);
}

TEST(StackedAreaPlot, UnwritablePathThrowsOutputErrorNamingIt) {
  const fs::path dir = ScratchDir("");
  const fs::path path = dir / "no_such_folder" / "energy.png";
  try {
    WriteStackedAreaPlotPng(TwoBands(2.0, 1.0), path);
    ADD_FAILURE() << "wrote into a missing folder";
  } catch (const core::OutputError& e) {
    EXPECT_EQ(e.path(), path);
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(WriteStackedAreaPlotsPng({TwoBands(2.0, 1.0)}, path), core::OutputError);
}

// Distinct (L1 distance over b, g, r), most of all for neighbours in a stack; readable on white;
// cycling after seven.
TEST(StackedAreaPlot, PaletteIsDistinctAndCycles) {
  auto distance = [](Color a, Color b) {
    return std::abs(a.b - b.b) + std::abs(a.g - b.g) + std::abs(a.r - b.r);
  };
  for (int i = 0; i < 7; ++i) {
    for (int j = i + 1; j < 7; ++j) {
      EXPECT_GT(distance(PaletteColor(i), PaletteColor(j)), 75) << i << " and " << j;
    }
    EXPECT_GT(distance(PaletteColor(i), PaletteColor(i + 1)), 200) << i << " and its neighbour";
    const Color c = PaletteColor(i);
    EXPECT_LT(c.b + c.g + c.r, 3 * 230) << i << " stands out from white";
    EXPECT_TRUE(Is(cv::Vec3b(c.b, c.g, c.r), PaletteColor(i + 7)));
    EXPECT_TRUE(Is(cv::Vec3b(c.b, c.g, c.r), PaletteColor(i - 7)));
  }
}

}  // namespace
}  // namespace autoshovel::plot
