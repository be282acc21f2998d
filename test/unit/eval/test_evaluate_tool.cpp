// End-to-end check of the `evaluate` command-line tool (built beside this test binary): a rigidly
// moved trajectory and map must come out with zero trajectory error and the known map errors.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "quadric_slam/eval/map_metrics.h"
#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/io/trajectory_io.h"

namespace fs = std::filesystem;

namespace {

struct ToolRun {
  int exit_code = -1;
  std::string out;
};

std::string toolPath() {
  return (fs::read_symlink("/proc/self/exe").parent_path() / "evaluate").string();
}

ToolRun runTool(const std::string& arguments) {
  ToolRun result;
  FILE* pipe = popen((toolPath() + " " + arguments + " 2>&1").c_str(), "r");
  if (!pipe)
    return result;
  std::array<char, 4096> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe))
    result.out += buffer.data();
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

double valueAfter(const std::string& text, const std::string& key) {
  const std::size_t at = text.find("\n" + key + " ");
  if (at == std::string::npos && text.rfind(key + " ", 0) != 0)
    return NAN;
  const std::size_t start = (at == std::string::npos ? 0 : at + 1) + key.size() + 1;
  return std::stod(text.substr(start));
}

}  // namespace

TEST(EvaluateTool, RigidlyMovedTrajectoryAndMap) {
  if (!fs::exists(toolPath()))
    GTEST_SKIP() << "evaluate tool not built at " << toolPath();
  const fs::path dir = fs::path(::testing::TempDir()) / "evaluate_tool_test";
  fs::create_directories(dir);

  Eigen::Isometry3d T_gt_est = Eigen::Isometry3d::Identity();
  T_gt_est.linear() =
      Eigen::AngleAxisd(0.8, Eigen::Vector3d(0, 0.3, 1).normalized()).toRotationMatrix();
  T_gt_est.translation() = Eigen::Vector3d(1.0, -2.0, 0.3);
  quadric_slam::Trajectory gt, est;
  for (int k = 0; k < 300; ++k) {  // 10 s at 30 Hz on a curve
    const double t = k / 30.0;
    quadric_slam::StampedPose p;
    p.stamp = 1000.0 + t;
    p.T_world_sensor.translation() = Eigen::Vector3d(std::sin(t), std::cos(0.5 * t), 0.1 * t);
    p.T_world_sensor.linear() =
        Eigen::AngleAxisd(0.2 * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    gt.push_back(p);
    est.push_back({p.stamp + 0.001, T_gt_est.inverse() * p.T_world_sensor});
  }
  quadric_slam::writeTumTrajectory(gt, (dir / "gt.txt").string());
  quadric_slam::writeTumTrajectory(est, (dir / "est.txt").string());

  quadric_slam::MapFile truth, estimate;
  quadric_slam::MapFileQuadric sphere;
  sphere.id = 1;
  sphere.quadric_class = "sphere";
  sphere.shape = {{"center", {1, 2, 0.5}}, {"radius", {0.2}}};
  truth.quadrics.push_back(sphere);
  quadric_slam::MapFileQuadric plane;
  plane.id = 2;
  plane.quadric_class = "plane";
  plane.shape = {{"normal", {0, 0, 1}}, {"offset", {0.0}}};
  truth.quadrics.push_back(plane);
  quadric_slam::MapFileQuadric estimated_sphere = sphere;  // 4 cm off in x, in the truth frame
  estimated_sphere.id = 7;
  estimated_sphere.shape["center"] = {1.04, 2, 0.5};
  estimate.quadrics.push_back(quadric_slam::transformQuadric(estimated_sphere, T_gt_est.inverse()));
  quadric_slam::writeMapYaml(truth, (dir / "quadrics_gt.yaml").string());
  quadric_slam::writeMapYaml(estimate, (dir / "map.yaml").string());

  const ToolRun ok = runTool("--gt " + (dir / "gt.txt").string() + " --est " +
                             (dir / "est.txt").string() + " --map " + (dir / "map.yaml").string() +
                             " --quadrics-gt " + (dir / "quadrics_gt.yaml").string());
  ASSERT_EQ(ok.exit_code, 0) << ok.out;
  EXPECT_NEAR(valueAfter(ok.out, "ate_rmse_m"), 0.0, 2e-6) << ok.out;  // 1e-9 m file precision
  EXPECT_EQ(valueAfter(ok.out, "pairs"), 300) << ok.out;
  EXPECT_NEAR(valueAfter(ok.out, "rpe_m_per_s"), 0.0, 2e-6) << ok.out;
  EXPECT_NE(ok.out.find("truth 1 sphere matched estimate 7 center_m 0.0400"), std::string::npos)
      << ok.out;
  EXPECT_NE(ok.out.find("truth 2 plane missed"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("map_summary matched 1 misses 1 duplicates 0 unmatched_estimates 0"),
            std::string::npos)
      << ok.out;
  // One line per class and range band of the true surfaces (their distance from the true path).
  EXPECT_NE(ok.out.find("class_range sphere "), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("class_range plane "), std::string::npos) << ok.out;

  const ToolRun missing = runTool("--gt " + (dir / "gt.txt").string());
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.out.find("usage:"), std::string::npos) << missing.out;
  const ToolRun bad_option = runTool("--gt a --est b --max-difference -1");
  EXPECT_EQ(bad_option.exit_code, 1);
  EXPECT_NE(bad_option.out.find("--max-difference"), std::string::npos) << bad_option.out;
  const ToolRun unreadable =
      runTool("--gt " + (dir / "gt.txt").string() + " --est " + (dir / "nonexistent.txt").string());
  EXPECT_EQ(unreadable.exit_code, 1);
  EXPECT_NE(unreadable.out.find("nonexistent.txt: cannot open"), std::string::npos)
      << unreadable.out;
  fs::remove_all(dir);
}
