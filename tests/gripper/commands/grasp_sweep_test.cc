// Grasp sweeps (gripper/commands/grasp_sweep.h): each row is HandReport's (or FingerReportJson's)
// for the objects moved by its offset, statuses instead of exceptions, and the number of threads
// changes nothing.
#include "gripper/commands/grasp_sweep.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "commands/command_error.h"

namespace hybrid::cli {
namespace {

std::string Circle(double x, double y, double r) {
  std::ostringstream s;
  s.precision(17);
  s << "circle:" << x << "," << y << "," << r;
  return s.str();
}

// Row r of `sweep` against the hand report of the same objects.
void ExpectRow(const GraspSweep& sweep, size_t r, const nlohmann::ordered_json& report) {
  EXPECT_EQ(sweep.status[r], report.at("status").get<std::string>());
  for (int f = 0; f < 3; ++f) {
    const auto& finger = report.at("fingers").at(f);
    EXPECT_EQ(sweep.motor[3 * r + f], finger.at("motor").get<double>());
    EXPECT_EQ(sweep.theta[9 * r + 3 * f + 2], finger.at("theta3").get<double>());
    EXPECT_EQ(sweep.phase[3 * r + f], finger.at("phase").get<std::string>());
    for (const auto& c : finger.at("contacts")) {
      const int link = c.at("link").get<int>();
      EXPECT_EQ(sweep.contact_g[9 * r + 3 * f + link - 1], c.at("g").get<double>());
      EXPECT_EQ(sweep.contact_by[9 * r + 3 * f + link - 1], c.at("by").get<std::string>());
    }
  }
}

TEST(GraspSweepTest, RowsAreTheHandsReports) {
  HandArgs args;
  args.objects = {Circle(0.0, 0.06, 0.02)};
  const std::vector<std::array<double, 2>> offsets = {
      {0.0, 0.0}, {0.01, 0.02}, {-0.02, 0.03}, {0.5, 0.5}, {0.0, -0.07}};
  const GraspSweep sweep = HandSweep(args, offsets, 2);
  ASSERT_EQ(sweep.status.size(), offsets.size());
  for (size_t r = 0; r < 4; ++r) {
    HandArgs moved = args;
    moved.objects = {Circle(0.0 + offsets[r][0], 0.06 + offsets[r][1], 0.02)};
    ExpectRow(sweep, r, HandReport(moved));
  }
  EXPECT_EQ(sweep.status[3], "out_of_reach");
  EXPECT_EQ(sweep.status[4], "invalid");
  EXPECT_NE(sweep.message[4].find("overlaps the palm"), std::string::npos) << sweep.message[4];
  const GraspSweep one = HandSweep(args, offsets, 1);
  EXPECT_EQ(one.theta.size(), sweep.theta.size());
  for (size_t k = 0; k < one.theta.size(); ++k) {
    EXPECT_TRUE(one.theta[k] == sweep.theta[k] ||
                (std::isnan(one.theta[k]) && std::isnan(sweep.theta[k])));
  }
}

TEST(GraspSweepTest, FingerRowsAreTheFingersReports) {
  const std::vector<std::array<double, 2>> offsets = {{0.0, 0.0}, {-0.3, 0.0}};
  const GraspSweep sweep = FingerSweep({Circle(0.06, 0.08, 0.01)}, 30.0, offsets, 1);
  FingerArgs args;
  args.g = 30.0;
  args.objects = {Circle(0.06, 0.08, 0.01)};
  const auto report = FingerReportJson(args);
  EXPECT_EQ(sweep.status[0], report.at("status").get<std::string>());
  EXPECT_EQ(sweep.first_contact[0], report.at("first_contact").get<double>());
  EXPECT_EQ(sweep.theta[0], report.at("theta1").get<double>());
  EXPECT_EQ(sweep.status[1], "out_of_reach");
}

TEST(GraspSweepTest, BadSweepsAreRejected) {
  HandArgs args;
  args.objects = {Circle(0.0, 0.06, 0.02)};
  const std::vector<std::array<double, 2>> bad = {{0.0, std::nan("")}};
  EXPECT_THROW(HandSweep(args, bad, 1), OptionError);
  const std::vector<std::array<double, 2>> fine = {{0.0, 0.0}};
  EXPECT_THROW(HandSweep(args, fine, 0), OptionError);
  EXPECT_THROW(FingerSweep({}, 255.0, fine, 1), OptionError);
  EXPECT_THROW(FingerSweep({"circle:0,0.1"}, 255.0, fine, 1), OptionError);
  EXPECT_THROW(FingerSweep({Circle(0.06, 0.08, 0.01)}, 300.0, fine, 1), OptionError);
}

}  // namespace
}  // namespace hybrid::cli
