// The warp_odometry_bench tool (built beside this test binary) on one shipped real frame and two
// small known motions (2 cm and 2 degrees): the tool runs end to end, writes its tables, the
// motions it reports are the sizes asked for, and the front-end recovers them (a motion applied
// the wrong way round, or a warp that moved the surface, would leave 4 cm / 4 degrees of error).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../real_frames.h"

namespace fs = std::filesystem;

namespace {

fs::path toolDir() { return fs::read_symlink("/proc/self/exe").parent_path(); }

std::vector<std::vector<std::string>> readCsv(const fs::path& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream f(path);
  for (std::string line; std::getline(f, line);) {
    std::vector<std::string> cells;
    std::stringstream in(line);
    for (std::string cell; std::getline(in, cell, ',');)
      cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

int column(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name)
      return static_cast<int>(i);
  ADD_FAILURE() << "no column " << name;
  return 0;
}

}  // namespace

TEST(WarpOdometryBench, RecoversSmallKnownMotionsOfARealFrame) {
  const fs::path tool = toolDir() / "warp_odometry_bench";
  if (!fs::exists(tool))
    GTEST_SKIP() << "warp_odometry_bench is not built in " << toolDir();
  const fs::path out =
      fs::path(testing::TempDir()) / ("warp_odometry_bench_" + std::to_string(::getpid()));
  const std::string frame =
      quadric_slam::test::shippedData(quadric_slam::test::kFr3HouseholdDepth).string();
  const std::string command = tool.string() + " --frame " + frame + " --steps 2 " +
                              "--motions-per-step 2 --seed 3 --quiet --out " + out.string() +
                              " > " + (out.string() + ".log") + " 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "failed: " << command;

  const auto trials = readCsv(out / "trials.csv");
  ASSERT_EQ(trials.size(), 3u);  // header + 2 trials
  const auto& h = trials[0];
  for (std::size_t i = 1; i < trials.size(); ++i) {
    const auto& r = trials[i];
    const double tx = std::stod(r[column(h, "true_tx")]), ty = std::stod(r[column(h, "true_ty")]),
                 tz = std::stod(r[column(h, "true_tz")]);
    EXPECT_NEAR(std::sqrt(tx * tx + ty * ty + tz * tz), 0.02, 1e-7);
    EXPECT_NEAR(std::stod(r[column(h, "true_angle_deg")]), 2.0, 1e-6);
    // The frame's own holes (about 15%) and the few pixels a 2 cm step uncovers, not an empty view.
    EXPECT_LT(std::stod(r[column(h, "hole_fraction")]), 0.5);
    EXPECT_EQ(r[column(h, "status")], "ok");
    EXPECT_LT(std::stod(r[column(h, "translation_error_m")]), 0.01);
    EXPECT_LT(std::stod(r[column(h, "rotation_error_deg")]), 1.0);
    EXPECT_EQ(r[column(h, "recovered")], "1");
  }
  const auto summary = readCsv(out / "summary.csv");
  ASSERT_EQ(summary.size(), 2u);
  EXPECT_EQ(summary[1][column(summary[0], "step_cm_deg")], "2");
  EXPECT_EQ(summary[1][column(summary[0], "recovered")], "2");
  EXPECT_TRUE(fs::exists(out / "summary.md"));
  fs::remove_all(out);
}
