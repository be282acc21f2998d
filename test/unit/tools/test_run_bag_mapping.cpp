// End to end through the offline runner (the `synth`, `run_bag` and `evaluate` tools built beside
// this test binary): a short synthetic desk sequence goes through normals, segmentation, odometry
// and the mapper; the mapped trajectory is as accurate as the odometry, the map holds the scene's
// primitives without duplicates or spurious landmarks, and the reconstruction is written.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <algorithm>

#include "quadric_slam/io/map_yaml.h"

namespace fs = std::filesystem;

namespace {

fs::path toolDir() {
  return fs::read_symlink("/proc/self/exe").parent_path();
}

// Runs a tool of toolDir() and returns its standard output (exit code in *code).
std::string run(const std::string& tool, const std::string& arguments, int* code) {
  std::string out;
  FILE* pipe = popen(((toolDir() / tool).string() + " " + arguments + " 2>/dev/null").c_str(), "r");
  if (!pipe)
    return out;
  std::array<char, 4096> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe))
    out += buffer.data();
  const int status = pclose(pipe);
  *code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

// The number after the first " key " (or a line starting with "key ") in text; NaN when absent.
double valueAfter(const std::string& text, const std::string& key) {
  std::size_t at = text.find("\n" + key + " ");
  if (at == std::string::npos)
    at = text.find(" " + key + " ");
  return at == std::string::npos ? NAN : std::stod(text.substr(at + key.size() + 2));
}

}  // namespace

TEST(RunBagMapping, DeskSequenceBuildsAMapOfTheScene) {
  for (const char* tool : {"synth", "run_bag", "evaluate"}) {
    if (!fs::exists(toolDir() / tool))
      GTEST_SKIP() << tool << " is not built in " << toolDir();
  }
  const fs::path dir =
      fs::path(testing::TempDir()) / ("run_bag_mapping_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  int code = -1;
  run("synth",
      "--out " + (dir / "sequence").string() +
          " --seconds 4 --rate 10 --no-bag --seed 2 --threads 1",
      &code);
  ASSERT_EQ(code, 0);
  // run_bag on the generated sequence, its outputs in dir / out.
  const auto runBag = [&](const std::string& out, const std::string& options) {
    return run("run_bag",
               (dir / "sequence").string() + " --out " + (dir / out).string() + " " + options,
               &code);
  };
  const std::string gt_option = " --gt " + (dir / "sequence/groundtruth.txt").string();
  const std::string runner = runBag("out", gt_option + " --quiet");
  ASSERT_EQ(code, 0) << runner;
  std::printf("%s", runner.c_str());
  const double odometry_ate = valueAfter(runner, "ate_rmse_m");
  const double map_ate = valueAfter(runner, "map_ate_rmse_m");
  ASSERT_TRUE(std::isfinite(odometry_ate) && std::isfinite(map_ate)) << runner;
  // Odometry on this easy scene is millimetre-accurate: the mapper must not spoil it.
  EXPECT_LT(map_ate, 0.01);
  EXPECT_LT(map_ate, odometry_ate + 0.002);
  EXPECT_EQ(valueAfter(runner, "map_pairs"), 40);
  EXPECT_TRUE(fs::exists(dir / "out/reconstruction.pcd"));

  const quadric_slam::MapFile map = quadric_slam::readMapYaml((dir / "out/map.yaml").string());
  EXPECT_GE(map.quadrics.size(), 6u);
  for (const auto& quadric : map.quadrics)
    EXPECT_GE(quadric.observations, 5) << "landmark " << quadric.id << " entered early";

  const std::string scored =
      run("evaluate",
          "--gt " + (dir / "sequence/groundtruth.txt").string() + " --est " +
              (dir / "out/trajectory.txt").string() + " --map " + (dir / "out/map.yaml").string() +
              " --quadrics-gt " + (dir / "sequence/quadrics_gt.yaml").string(),
          &code);
  ASSERT_EQ(code, 0) << scored;
  const std::size_t summary = scored.find("map_summary ");
  ASSERT_NE(summary, std::string::npos) << scored;
  std::printf("%s", scored.substr(summary).c_str());
  const std::string line = scored.substr(summary, scored.find('\n', summary) - summary);
  EXPECT_GE(valueAfter(line, "matched"), 6);
  EXPECT_EQ(valueAfter(line, "duplicates"), 0);
  EXPECT_EQ(valueAfter(line, "unmatched_estimates"), 0);

  // The sequence has RGB (registered, rgb.txt): the reconstruction's points carry the colours of
  // their pixels (alpha 255), which are the rendered surfaces' shades, not the landmark colours.
  // Without RGB (--no-rgb) the same frames give the same map, every point in its landmark's colour
  // (up to the corners' guess, which the image feeds at 10 Hz: the fused poses move by a fraction
  // of a millimetre).
  const auto colouredShare = [](const fs::path& pcd, std::size_t* points) {
    pcl::PointCloud<pcl::PointXYZRGBL> cloud;
    if (pcl::io::loadPCDFile(pcd.string(), cloud) != 0)
      return -1.0;
    std::size_t coloured = 0;
    for (const auto& p : cloud)
      coloured += (p.rgba >> 24) == 0xFFu;
    *points = cloud.size();
    return static_cast<double>(coloured) / std::max<std::size_t>(cloud.size(), 1);
  };
  std::size_t points_rgb = 0, points_depth = 0;
  EXPECT_GT(colouredShare(dir / "out/reconstruction.pcd", &points_rgb), 0.95);
  const std::string depth_only = runBag("out_depth", gt_option + " --quiet --no-rgb");
  ASSERT_EQ(code, 0) << depth_only;
  EXPECT_EQ(colouredShare(dir / "out_depth/reconstruction.pcd", &points_depth), 0.0);
  EXPECT_NEAR(static_cast<double>(points_depth), static_cast<double>(points_rgb),
              0.005 * static_cast<double>(points_rgb));
  EXPECT_NEAR(valueAfter(depth_only, "map_ate_rmse_m"), map_ate, 0.0005);
  EXPECT_EQ(quadric_slam::readMapYaml((dir / "out_depth/map.yaml").string()).quadrics.size(),
            map.quadrics.size());

  // Pipelined (two frames ahead in the front end, each on its own thread) and --sequential give
  // the same trajectory, to the last digit.
  const std::string sequential = runBag("out_sequential", "--quiet --no-rgb --sequential");
  ASSERT_EQ(code, 0) << sequential;
  const auto contents = [](const fs::path& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  const std::string pipelined_trajectory = contents(dir / "out_depth/trajectory.txt");
  EXPECT_FALSE(pipelined_trajectory.empty());
  EXPECT_EQ(contents(dir / "out_sequential/trajectory.txt"), pipelined_trajectory);
  // The worker threads inside the stages (default 1 when pipelined, the configured 2 with
  // --sequential above) change the time, not the result; out of range is a usage error.
  const std::string threaded = runBag("out_threads", "--quiet --no-rgb --stage-threads 2");
  ASSERT_EQ(code, 0) << threaded;
  EXPECT_EQ(contents(dir / "out_threads/trajectory.txt"), pipelined_trajectory);
  runBag("out_bad", "--stage-threads 0");
  EXPECT_EQ(code, 2);
  fs::remove_all(dir);
}
