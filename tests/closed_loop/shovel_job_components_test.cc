// The main job's components alone (runtime/app/shovel_job/, docs/architecture.md): each is fed
// typed inputs and its outputs checked, without a plant or a whole cycle.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <regex>
#include <set>
#include <sstream>

#include "runtime/app/shovel_job/clearance_record.h"
#include "runtime/app/shovel_job/fault_schedule.h"
#include "runtime/app/shovel_job/navigation_goal.h"
#include "runtime/app/shovel_job/path_watch.h"
#include "runtime/app/shovel_job/shovel_cycle.h"
#include "runtime/app/shovel_job/shovel_point_task.h"
#include "runtime/app/stop_hold.h"

namespace autoshovel::app {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(FaultSchedule, ActiveOnlyInItsCycleAndWindowFromTheCycleStart) {
  plant::FaultSpec late;
  late.kind = plant::FaultKind::kLidarDropout;
  late.start_s = 2.0;
  late.duration_s = 1.0;
  late.cycles = {1};
  const std::vector<plant::FaultSpec> faults = {late};
  const double t0 = 100.0;  // the cycle's plant starts at machine time 100 s
  const FaultSchedule cycle1(faults, 1, t0), cycle0(faults, 0, t0);
  EXPECT_EQ(cycle1.Active(plant::FaultKind::kLidarDropout, t0 + 1.9), nullptr);
  EXPECT_NE(cycle1.Active(plant::FaultKind::kLidarDropout, t0 + 2.5), nullptr);
  EXPECT_EQ(cycle1.Active(plant::FaultKind::kLidarDropout, t0 + 3.1), nullptr);
  EXPECT_EQ(cycle1.Active(plant::FaultKind::kCameraBlackout, t0 + 2.5), nullptr);
  EXPECT_EQ(cycle0.Active(plant::FaultKind::kLidarDropout, t0 + 2.5), nullptr);
  EXPECT_TRUE(cycle1.InCycle(plant::FaultKind::kLidarDropout));
  EXPECT_FALSE(cycle0.InCycle(plant::FaultKind::kLidarDropout));
}

planning::ShovelCandidate Candidate(double x, double heading, double score, bool feasible = true,
                                    double approach_clearance = 2.0) {
  planning::ShovelCandidate c;
  c.pose.xy = {x, 0.0};
  c.pose.entry_heading = heading;
  c.score = score;
  c.feasible = feasible;
  c.infeasible = feasible ? "" : "path collides with an obstacle";
  c.scores.approach_obstacle_distance = approach_clearance;
  c.scores.min_obstacle_distance = approach_clearance;
  return c;
}

// Reconsider reads the task's last selection; an empty map gives an empty one, which the test
// fills through a task whose selection it controls.
class ReconsiderTest : public ::testing::Test {
 protected:
  ReconsiderTest() {
    config_.entry_angle_offsets = {-0.2, 0.0, 0.2};  // half step 0.1 rad
  }
  GoalChange Run(const std::vector<planning::ShovelCandidate>& ranked,
                 const planning::ShovelCandidate& goal, std::size_t best, bool chen = false) {
    task_ = std::make_unique<ShovelPointTask>(config_, 0.8, chen, loader_,
                                              [](const Eigen::Vector2d&) { return true; });
    selection_.ranked = ranked;
    task_->SetLastSelectionForTest(selection_);
    return task_->Reconsider(goal, task_->last_selection().ranked[best]);
  }
  planning::ShovelPointConfig config_;
  planning::LoaderGeometry loader_;
  planning::ShovelPointResult selection_;
  std::unique_ptr<ShovelPointTask> task_;
};

TEST_F(ReconsiderTest, KeepsTheGoalFoundAgainWithinHalfAMetreAndHalfAnAngleStep) {
  const planning::ShovelCandidate goal = Candidate(10.0, 0.0, 0.90);
  // The goal moved 0.3 m and 0.05 rad on the new map; another candidate scores a little more.
  const GoalChange change = Run({Candidate(20.0, 0.0, 0.93), Candidate(10.3, 0.05, 0.90)}, goal, 0);
  ASSERT_NE(change.candidate, nullptr);
  EXPECT_FALSE(change.new_goal);
  EXPECT_DOUBLE_EQ(change.candidate->pose.xy.x(), 10.3);
  EXPECT_TRUE(change.log.empty());
}

TEST_F(ReconsiderTest, TakesTheBestWhenItBeatsTheGoalByMoreThanTheHysteresis) {
  const planning::ShovelCandidate goal = Candidate(10.0, 0.0, 0.80);
  const GoalChange change = Run({Candidate(20.0, 0.0, 0.86), Candidate(10.0, 0.0, 0.80)}, goal, 0);
  EXPECT_TRUE(change.new_goal);
  EXPECT_DOUBLE_EQ(change.candidate->pose.xy.x(), 20.0);
  EXPECT_NE(change.log.find("re-selected: point (20.00, 0.00)"), std::string::npos) << change.log;
  // The baseline of Chen et al. keeps its goal whatever Eq. (18) says.
  const GoalChange chen =
      Run({Candidate(20.0, 0.0, 0.86), Candidate(10.0, 0.0, 0.80)}, goal, 0, /*chen=*/true);
  EXPECT_FALSE(chen.new_goal);
}

TEST_F(ReconsiderTest, GivesUpAGoalThatIsGoneInfeasibleOrTooCloseToAnObstacle) {
  const planning::ShovelCandidate goal = Candidate(10.0, 0.0, 0.90);
  const GoalChange gone = Run({Candidate(20.0, 0.0, 0.5), Candidate(10.0, 0.15, 0.9)}, goal, 0);
  EXPECT_TRUE(gone.new_goal);  // 0.15 rad off: more than half the 0.2 rad step
  EXPECT_NE(gone.log.find("not among the new candidates"), std::string::npos) << gone.log;
  const GoalChange blocked =
      Run({Candidate(20.0, 0.0, 0.5), Candidate(10.0, 0.0, kInf * -1, false)}, goal, 0);
  EXPECT_TRUE(blocked.new_goal);
  EXPECT_NE(blocked.log.find("path collides"), std::string::npos) << blocked.log;
  const GoalChange close =
      Run({Candidate(20.0, 0.0, 0.5), Candidate(10.0, 0.0, 0.9, true, /*approach=*/0.5)}, goal, 0);
  EXPECT_TRUE(close.new_goal);
  EXPECT_NE(close.log.find("approach 0.50 m from an obstacle"), std::string::npos) << close.log;
}

// A straight path along +x from the origin; obstacle cells at given x on it.
struct StraightPath {
  NavigationGoal nav;
  perception::GridMap map{0.1, Eigen::Vector2d(40.0, 10.0), Eigen::Vector2d(15.0, 0.0)};
  StraightPath() {
    planning::ShovelCandidate c;
    c.path = planning::ShortestDubinsPath({{0.0, 0.0}, 0.0}, {{20.0, 0.0}, 0.0}, 0.2);
    nav.goal = c;
    map.Add("class", 0.0f);
    nav.planned_obstacles = Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>::Constant(
        map.size().x(), map.size().y(), false);
  }
};

TEST(ObstacleAheadOnPath, DistanceFromTheFrontEdgeAlongThePath) {
  StraightPath p;
  Eigen::Vector2d blocking = Eigen::Vector2d::Zero();
  // Front axle at x = 2, the bucket's front edge 1.5 m beyond it; a cell on the path at x = 9.
  const double ahead = ObstacleAheadOnPath(p.nav, {{9.0, 0.2}}, p.map, {2.0, 0.0}, 1.5,
                                           /*tube=*/1.5, /*horizon=*/12.0, &blocking);
  // The tube first reaches the cell where the path comes within 1.5 m of it; measured from the
  // front edge, to within a path sample (0.2 m), never before.
  const double touch = 9.0 - std::sqrt(1.5 * 1.5 - 0.2 * 0.2);
  EXPECT_GE(ahead, touch - 2.0 - 1.5 - 1e-9);
  EXPECT_LE(ahead, touch - 2.0 - 1.5 + 0.2 + 1e-9);
  EXPECT_EQ(blocking, Eigen::Vector2d(9.0, 0.2));
  // Beside the tube, or beyond the horizon: nothing ahead.
  EXPECT_TRUE(std::isinf(
      ObstacleAheadOnPath(p.nav, {{9.0, 2.0}}, p.map, {2.0, 0.0}, 1.5, 1.5, 12.0, &blocking)));
  EXPECT_TRUE(std::isinf(
      ObstacleAheadOnPath(p.nav, {{18.0, 0.0}}, p.map, {2.0, 0.0}, 1.5, 1.5, 12.0, &blocking)));
}

TEST(ObstacleAheadOnPath, IgnoresMoreOfAnObstacleThePathWasPlannedRound) {
  StraightPath p;
  perception::Index i;
  ASSERT_TRUE(p.map.IndexOf({9.15, 0.05}, i));
  p.nav.planned_obstacles(i.x(), i.y()) = true;  // seen when the path was planned
  Eigen::Vector2d blocking;
  // Within two cells of it: the same obstacle, come into view; farther: a newcomer.
  EXPECT_TRUE(std::isinf(
      ObstacleAheadOnPath(p.nav, {{9.0, 0.2}}, p.map, {2.0, 0.0}, 1.5, 1.5, 12.0, &blocking)));
  EXPECT_FALSE(std::isinf(
      ObstacleAheadOnPath(p.nav, {{9.6, 0.2}}, p.map, {2.0, 0.0}, 1.5, 1.5, 12.0, &blocking)));
}

TEST(ClearanceRecord, CountsEachApproachCloserThanTheSafetyDistanceOnce) {
  ClearanceRecord record(0.5);
  plant::OrientedBox wall;
  wall.name = "wall";
  wall.center = {10.0, 0.0, 1.0};
  wall.half_extents = {0.1, 5.0, 1.0};
  perception::MachineFootprint body;
  body.front_length = 1.0;
  body.rear_length = 1.0;
  body.half_width = 1.0;
  plant::MachineState s;
  std::ostringstream log_text;
  const CycleLog log(&log_text, 0);
  for (double x : {5.0, 8.7, 8.8, 6.0, 8.9, 5.0}) {  // in, stays in, out, in again, out
    body.hinge_xy = {x, 0.0};
    record.Update(body, {wall}, s, 0.0, 0.0, log);
  }
  EXPECT_EQ(record.violations(), 2);
  EXPECT_NEAR(record.min_clearance(), 10.0 - 0.1 - 8.9 - 1.0, 1e-6);
  EXPECT_NE(log_text.str().find("[cycle 1] SAFETY"), std::string::npos);
}

// The diagram is drawn from the task table the cycle registers: every component of every task
// is a node, every flow joins two of them (or the machine and the recorder), and the rates are
// the run's.
TEST(Architecture, DiagramNamesEveryTaskAtItsRateAndJoinsOnlyKnownComponents) {
  ShovelRunOptions options;
  options.map_rate = 5;
  const std::string dot = ShovelJobArchitectureDot(options);
  EXPECT_NE(dot.find("map_and_selection (5 Hz)"), std::string::npos) << dot;
  EXPECT_NE(dot.find("state_machine_and_safety (20 Hz)"), std::string::npos);
  EXPECT_NE(dot.find("control (100 Hz)"), std::string::npos);
  std::set<std::string> nodes = {"SimulatedMachine", "CycleRecorder"};
  const std::regex node(R"(^    ([A-Za-z]+);$)"), edge(R"(^  ([A-Za-z]+) -> ([A-Za-z]+) )");
  std::istringstream lines(dot);
  std::vector<std::pair<std::string, std::string>> edges;
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_search(line, m, node)) nodes.insert(m[1]);
    if (std::regex_search(line, m, edge)) edges.emplace_back(m[1], m[2]);
  }
  EXPECT_GE(nodes.size(), 14u);
  EXPECT_GE(edges.size(), 15u);
  std::set<std::string> joined;
  for (const auto& [from, to] : edges) {
    EXPECT_TRUE(nodes.count(from)) << from;
    EXPECT_TRUE(nodes.count(to)) << to;
    joined.insert(from), joined.insert(to);
  }
  for (const std::string& n : nodes) EXPECT_TRUE(joined.count(n)) << n << " has no flow";
}

// The hold rule both jobs share: a reason stops at once, a new reason while stopped adds no
// stop, and the machine goes on only after the checks have found no reason for resume_after
// from the first clear check; a reason seen meanwhile starts the wait again.
TEST(StopHold, StopsAtOnceAndResumesAfterTheReasonHasBeenGone) {
  // Times in quarter seconds: exact in binary, so the 1 s boundary is exact.
  SafetySupervisor supervisor;
  StopHold hold(1.0);
  using Change = StopHold::Change;
  EXPECT_EQ(hold.Update(0.0, "", supervisor), Change::kNone);
  EXPECT_EQ(hold.Update(0.25, "person ahead", supervisor), Change::kStopped);
  EXPECT_TRUE(supervisor.stopped());
  EXPECT_EQ(supervisor.reason(), "person ahead");
  EXPECT_EQ(hold.Update(0.5, "person ahead", supervisor), Change::kNone);
  EXPECT_EQ(hold.Update(0.75, "", supervisor), Change::kNone);       // clear from 0.75
  EXPECT_EQ(hold.Update(1.5, "", supervisor), Change::kNone);        // 0.75 s clear
  EXPECT_EQ(hold.Update(1.75, "again", supervisor), Change::kNone);  // seen again: wait anew
  EXPECT_EQ(hold.Update(2.0, "", supervisor), Change::kNone);        // clear from 2.0
  EXPECT_EQ(hold.Update(2.75, "", supervisor), Change::kNone);       // 0.75 s clear
  EXPECT_EQ(hold.Update(3.0, "", supervisor), Change::kResumed);     // 1 s clear
  EXPECT_FALSE(supervisor.stopped());
  EXPECT_EQ(supervisor.safe_stops(), 1);
  EXPECT_EQ(supervisor.recoveries(), 1);
  EXPECT_EQ(hold.Update(3.25, "", supervisor), Change::kNone);
}

}  // namespace
}  // namespace autoshovel::app
