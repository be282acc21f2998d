// bench_mapping: per-frame cost of the mapping back-end (QuadricMapper) over a long synthetic run
// (test/unit/mapping/synthetic_world.h: the room world, circling laps, or the corridor, whose map
// grows with the distance travelled). Prints median and p95 of
// association time (every frame) and window optimisation time (keyframes), for the whole run and
// for its first and last fifths, with the window problem sizes: the cost must not grow with the
// sequence. Usage:
//   bench_mapping [--frames N (1000)] [--window K (10)] [--world room|corridor] [--no-covariance]
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "../unit/mapping/synthetic_world.h"
#include "quadric_slam/mapping/quadric_mapper.h"

namespace {

double percentile(std::vector<double> v, double q) {
  if (v.empty())
    return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * (v.size() - 1) + 0.5)];
}

void row(const std::string& name, const std::vector<double>& seconds) {
  std::cout << "  " << std::left << std::setw(34) << name << std::right << " n " << std::setw(5)
            << seconds.size() << "  median " << std::fixed << std::setprecision(3) << std::setw(8)
            << 1e3 * percentile(seconds, 0.5) << " ms  p95 " << std::setw(8)
            << 1e3 * percentile(seconds, 0.95) << " ms\n";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace quadric_slam;
  int frames = 1000;
  std::string world_name = "room";
  QuadricMapper::Params params;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--frames" && i + 1 < argc) {
      frames = std::atoi(argv[++i]);
    } else if (arg == "--window" && i + 1 < argc) {
      params.window.size = std::atoi(argv[++i]);
    } else if (arg == "--world" && i + 1 < argc) {
      world_name = argv[++i];
    } else if (arg == "--no-covariance") {
      params.window.compute_covariance = false;
    } else {
      std::cerr << "usage: bench_mapping [--frames N] [--window K] [--world room|corridor] "
                   "[--no-covariance]\n";
      return 2;
    }
  }
  if (frames < 10 || (world_name != "room" && world_name != "corridor")) {
    std::cerr << "bench_mapping: --frames must be >= 10, --world room or corridor\n";
    return 2;
  }
  QuadricMapper mapper(params);
  const bool room = world_name == "room";
  const std::vector<test::TrueLandmark> world =
      room ? test::roomWorld() : test::corridorWorld(static_cast<int>(0.03 * frames) + 3);
  const std::vector<Eigen::Isometry3d> poses =
      room ? test::circleTrajectory(300, frames / 300.0) : test::corridorTrajectory(frames);
  std::mt19937 rng(1);
  const std::vector<Eigen::Isometry3d> odometry = test::driftingOdometry(poses, rng);

  const int n = static_cast<int>(poses.size());
  const int fifth = n / 5;
  std::vector<double> association_all, association_early, association_late;
  std::vector<double> optimisation_all, optimisation_early, optimisation_late;
  int keyframes = 0, max_blocks_early = 0, max_blocks_late = 0, max_residuals_early = 0,
      max_residuals_late = 0;
  for (int i = 0; i < n; ++i) {
    FrameMeasurements frame;
    frame.stamp = i / 30.0;
    for (const test::TrueLandmark& l : world)
      if (test::visible(l, poses[i]))
        frame.observations.push_back(test::measure(l, poses[i], rng));
    OdometryInput odom;
    odom.T_odom_camera = odometry[i];
    const MapperFrameResult r = mapper.process(frame, odom);
    if (r.status != FrameStatus::kOk) {
      std::cerr << "frame " << i << " refused: " << r.message << "\n";
      return 1;
    }
    association_all.push_back(r.association_seconds);
    if (i < fifth)
      association_early.push_back(r.association_seconds);
    if (i >= n - fifth)
      association_late.push_back(r.association_seconds);
    if (!r.keyframe)
      continue;
    ++keyframes;
    optimisation_all.push_back(r.optimisation_seconds);
    if (i < fifth) {
      optimisation_early.push_back(r.optimisation_seconds);
      max_blocks_early = std::max(max_blocks_early, r.window.parameter_blocks);
      max_residuals_early = std::max(max_residuals_early, r.window.residuals);
    }
    if (i >= n - fifth) {
      optimisation_late.push_back(r.optimisation_seconds);
      max_blocks_late = std::max(max_blocks_late, r.window.parameter_blocks);
      max_residuals_late = std::max(max_residuals_late, r.window.residuals);
    }
  }
  std::cout << "bench_mapping: " << world_name << ", " << n << " frames, " << keyframes
            << " keyframes, window " << params.window.size << ", covariance "
            << (params.window.compute_covariance ? "on" : "off") << ", landmarks "
            << mapper.map().landmarks().size() << "\n";
  row("association (all frames)", association_all);
  row("association (first fifth)", association_early);
  row("association (last fifth)", association_late);
  row("window optimisation (keyframes)", optimisation_all);
  row("window optimisation (first fifth)", optimisation_early);
  row("window optimisation (last fifth)", optimisation_late);
  std::cout << "  window size: max parameter blocks first fifth " << max_blocks_early
            << ", last fifth " << max_blocks_late << "; max residuals first fifth "
            << max_residuals_early << ", last fifth " << max_residuals_late << "\n";
  return 0;
}
