// The top view writes a PNG that OpenCV reads back at the size the options ask for.
#include "runtime/plant/top_view.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "runtime/plant/scenario.h"

namespace autoshovel::plant {
namespace {

namespace fs = std::filesystem;

const std::string kScenarios = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models/scenarios/";

TEST(TopView, WritesAReadablePngOfTheExpectedSize) {
  const Scenario s = LoadScenario(kScenarios + "cone_pile.yaml");  // 40 m x 40 m
  const std::string png =
      (fs::path(::testing::TempDir()) / ("cone_pile_top_" + std::to_string(::getpid()) + ".png"))
          .string();
  TopViewOptions options;
  options.metres_per_pixel = 0.1;
  options.start = s.start;
  WriteTopView(s.world, png, options);
  ASSERT_TRUE(fs::exists(png));
  EXPECT_GT(fs::file_size(png), 1000u);
  const cv::Mat image = cv::imread(png, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 400);
  EXPECT_EQ(image.rows, 400);
  EXPECT_EQ(image.channels(), 3);
  // The pile (centre at 25, 20) is coloured; the bare floor (35, 35) is grey.
  const cv::Vec3b pile = image.at<cv::Vec3b>(400 - 200, 250);
  const cv::Vec3b floor = image.at<cv::Vec3b>(400 - 350, 350);
  EXPECT_EQ(floor[0], floor[1]);
  EXPECT_EQ(floor[1], floor[2]);
  EXPECT_NE(pile, floor);
}

TEST(TopView, SizeFollowsMetresPerPixel) {
  const Scenario s = LoadScenario(kScenarios + "mixing_station.yaml");  // 60 m x 60 m
  const std::string png = (fs::path(::testing::TempDir()) /
                           ("mixing_station_top_" + std::to_string(::getpid()) + ".png"))
                              .string();
  TopViewOptions options;
  options.metres_per_pixel = 0.25;
  WriteTopView(s.world, png, options);
  const cv::Mat image = cv::imread(png);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 240);
  EXPECT_EQ(image.rows, 240);
}

TEST(TopView, UnwritablePathThrows) {
  const Scenario s = LoadScenario(kScenarios + "low_pile.yaml");
  EXPECT_THROW(WriteTopView(s.world, "/nonexistent/folder/top.png"), std::runtime_error);
}

}  // namespace
}  // namespace autoshovel::plant
