// Benchmark of the normal-estimation stage (back-projection + normals, as the nodelet runs it, with
// the output storage reused from frame to frame) on a real 640x480 TUM depth frame: median and p95
// over N runs per method; PCL's integral-image methods in the same run are the baseline.
//
//   bench_normals [--runs N] [--depth PNG] [--method NAME|all] [--smoothing PIXELS]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/frame_source.h"

namespace qs = quadric_slam;

namespace {

double percentile(std::vector<double> values, double q) {
  std::sort(values.begin(), values.end());
  const std::size_t index =
      std::min(values.size() - 1, static_cast<std::size_t>(q * values.size()));
  return values[index];
}

// CPU time of the whole process (every thread), ms.
double processCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

int usage() {
  std::fprintf(stderr,
               "usage: bench_normals [--runs N] [--depth PNG] [--method NAME|all] "
               "[--smoothing PIXELS]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 200;
  std::string depth_file = std::string(QUADRIC_SLAM_SHARED_DATA_DIR) +
                           "/tum_frames/fr3_long_office_household/1341847980.723020.png";
  std::string method = "all";
  double smoothing = qs::NormalEstimator::Params().normal_smoothing_size;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 >= argc)
      return usage();
    if (arg == "--runs") {
      runs = std::atoi(argv[++i]);
    } else if (arg == "--depth") {
      depth_file = argv[++i];
    } else if (arg == "--method") {
      method = argv[++i];
    } else if (arg == "--smoothing") {
      smoothing = std::atof(argv[++i]);
    } else {
      return usage();
    }
  }
  cv::Mat depth_m;
  try {
    depth_m = qs::readTumDepthPng(depth_file);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_normals: %s\n", e.what());
    return 1;
  }
  if (runs < 1)
    return usage();
  qs::CameraIntrinsics intrinsics;  // Freiburg3, as in shared/data/README.md
  intrinsics.fx = 535.4;
  intrinsics.fy = 539.2;
  intrinsics.cx = 320.1;
  intrinsics.cy = 247.6;
  intrinsics.width = depth_m.cols;
  intrinsics.height = depth_m.rows;
  const qs::DepthImageView<float> view = qs::depthViewOf(depth_m);

  std::vector<std::string> methods = {method};
  if (method == "all") {
    methods = {"box_gradient", "average_3d_gradient", "covariance_matrix", "average_depth_change",
               "simple_3d_gradient"};
  }
  std::printf("frame %dx%d from %s, %d runs per method\n", depth_m.cols, depth_m.rows,
              depth_file.c_str(), runs);
  // Wall time is what a frame costs on an idle machine; CPU time (all threads) is what it costs
  // when other processes compete for the cores, as on a shared machine.
  std::printf("%-22s %10s %10s %10s %12s %10s\n", "method", "median_ms", "p95_ms", "backproj_ms",
              "cpu_median_ms", "valid");
  for (const std::string& name : methods) {
    qs::NormalEstimator::Params params;
    params.method = name;
    params.normal_smoothing_size = smoothing;
    const qs::NormalEstimator estimator(params);
    std::vector<double> total_ms, back_projection_ms, cpu_ms;
    pcl::PointCloud<pcl::PointNormal> normals;  // reused, as a stream of frames does
    std::size_t valid = 0;
    for (int run = 0; run < runs; ++run) {
      const double c0 = processCpuMs();
      const auto t0 = std::chrono::steady_clock::now();
      const auto cloud = qs::backProject(view, intrinsics, {});
      const auto t1 = std::chrono::steady_clock::now();
      estimator.compute(cloud, normals);
      const auto t2 = std::chrono::steady_clock::now();
      cpu_ms.push_back(processCpuMs() - c0);
      back_projection_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      total_ms.push_back(std::chrono::duration<double, std::milli>(t2 - t0).count());
      if (run == 0) {
        for (const auto& p : normals)
          valid += std::isfinite(p.normal_x) ? 1 : 0;
      }
    }
    std::printf("%-22s %10.2f %10.2f %10.2f %12.2f %10zu\n", name.c_str(),
                percentile(total_ms, 0.5), percentile(total_ms, 0.95),
                percentile(back_projection_ms, 0.5), percentile(cpu_ms, 0.5), valid);
  }
  return 0;
}
