// bench_odometry: times OdometryTracker::track (point-to-plane ICP against the keyframe) on
// synthetic 640 x 480 frames of a room corner with Kinect-like depth noise, along a smooth
// hand-held-like path; prints median / p95 / max per-frame time and the end drift against the
// known path. Rendering and normal estimation are not timed.
//
// Usage: bench_odometry [--frames N] [--decimation D] [--stride S] [--noise K] [--levels L]
//                      [--ref-stride R] [--verbose 1]
//   N frames (default 150), D cloud decimation (1), S ICP finest_stride (4), R reference_stride
//   (2), K depth noise sigma = K z^2 (0.0015 m^-1), L pyramid levels (3); --verbose 1 prints every
//   frame's status and position error.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "../../test/unit/odometry/synthetic_scene.h"
#include "quadric_slam/odometry/odometry_tracker.h"

using quadric_slam::CameraIntrinsics;
using quadric_slam::OdometryTracker;
using quadric_slam::TrackingStatus;
namespace synthetic = quadric_slam::synthetic;

namespace {

// 5 mm and about 0.15 degrees per frame, like the unit test's path, repeated for longer runs.
Eigen::Isometry3d pathPose(int i) {
  const double s = i / 59.0;
  const Eigen::Vector3d eye(-0.3 + 0.25 * std::sin(0.5 * M_PI * s),
                            -0.3 + 0.1 * std::sin(2 * M_PI * s), 1.5 + 0.05 * std::sin(M_PI * s));
  const Eigen::Vector3d target(2.0 + 0.3 * std::sin(2 * M_PI * s),
                               2.0 - 0.2 * std::sin(0.5 * M_PI * s),
                               0.7 + 0.1 * std::cos(2 * M_PI * s));
  return synthetic::lookAt(eye, target);
}

double threadCpuMs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const std::size_t i = static_cast<std::size_t>(std::round(q * (v.size() - 1)));
  return v[i];
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 150, decimation = 1, stride = 4, ref_stride = 2, levels = 3, verbose = 0;
  double noise = 0.0015;
  if (argc % 2 == 0) {  // an option without its value, or --help
    std::fprintf(stderr,
                 "usage: bench_odometry [--frames N] [--decimation D] [--stride S] [--noise M] "
                 "[--levels L] [--ref-stride R] [--verbose V]\n");
    return 2;
  }
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const char* value = argv[i + 1];
    if (key == "--frames")
      frames = std::atoi(value);
    else if (key == "--decimation")
      decimation = std::atoi(value);
    else if (key == "--stride")
      stride = std::atoi(value);
    else if (key == "--noise")
      noise = std::atof(value);
    else if (key == "--levels")
      levels = std::atoi(value);
    else if (key == "--ref-stride")
      ref_stride = std::atoi(value);
    else if (key == "--verbose")
      verbose = std::atoi(value);
    else {
      std::fprintf(stderr, "unknown option %s\n", key.c_str());
      return 2;
    }
  }
  if (frames < 2 || decimation < 1) {
    std::fprintf(stderr, "need --frames >= 2 and --decimation >= 1\n");
    return 2;
  }
  OdometryTracker::Params params;
  params.icp.finest_stride = stride;
  params.icp.pyramid_levels = levels;
  params.icp.reference_stride = ref_stride;
  OdometryTracker tracker(params);
  const synthetic::Scene scene = synthetic::roomScene();
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  const Eigen::Isometry3d T_world_first = pathPose(0);

  std::vector<double> ms, cpu_ms;
  int counts[3] = {0, 0, 0}, keyframes = 0;
  double iterations = 0, worst_drift = 0;
  Eigen::Isometry3d last_estimate, last_truth;
  for (int i = 0; i < frames; ++i) {
    const Eigen::Isometry3d T_world_camera = pathPose(i);
    auto cloud = synthetic::renderCloud(scene, T_world_camera, k, decimation, noise, 7000 + i);
    const double cpu_start = threadCpuMs();
    const auto start = std::chrono::steady_clock::now();
    const OdometryTracker::Result r = tracker.track(*cloud, k, i / 30.0);
    const auto stop = std::chrono::steady_clock::now();
    const double cpu_stop = threadCpuMs();
    if (i > 0) {  // the first frame only becomes the keyframe
      ms.push_back(std::chrono::duration<double, std::milli>(stop - start).count());
      cpu_ms.push_back(cpu_stop - cpu_start);
      iterations += r.icp.iterations;
    }
    ++counts[static_cast<int>(r.status)];
    keyframes += r.new_keyframe ? 1 : 0;
    last_truth = T_world_first.inverse() * T_world_camera;
    last_estimate = r.T_odom_camera;
    const double error = (last_estimate.translation() - last_truth.translation()).norm();
    worst_drift = std::max(worst_drift, error);
    if (verbose) {
      std::printf(
          "frame %3d: %-10s keyframe %d inliers %.3f eigenvalue ratio %.1e iterations %2d "
          "error %.2f mm\n",
          i, quadric_slam::toString(r.status), r.new_keyframe ? 1 : 0, r.icp.inlier_fraction,
          r.icp.eigenvalue_ratio, r.icp.iterations, error * 1e3);
    }
  }
  const double end_drift = (last_estimate.translation() - last_truth.translation()).norm();
  const double end_rot =
      quadric_slam::pose_math::rotationAngle(last_estimate.inverse() * last_truth) * 180 / M_PI;
  std::printf(
      "bench_odometry: %d frames %dx%d (decimation %d), finest_stride %d, reference_stride %d, "
      "%d levels, noise %.4f z^2\n",
      frames, k.width / decimation, k.height / decimation, decimation, stride, ref_stride, levels,
      noise);
  std::printf(
      "track() wall time per frame: median %.2f ms, p95 %.2f ms, max %.2f ms (%zu timed frames)\n",
      percentile(ms, 0.5), percentile(ms, 0.95), percentile(ms, 1.0), ms.size());
  std::printf("track() thread CPU time: median %.2f ms, p95 %.2f ms, max %.2f ms\n",
              percentile(cpu_ms, 0.5), percentile(cpu_ms, 0.95), percentile(cpu_ms, 1.0));
  std::printf("mean Gauss-Newton iterations per frame (all levels): %.1f\n",
              iterations / static_cast<double>(ms.size()));
  std::printf("status: %d ok, %d degenerate, %d lost; %d keyframes\n", counts[0], counts[1],
              counts[2], keyframes);
  std::printf("path length %.3f m; end drift %.2f mm, %.3f deg; worst position error %.2f mm\n",
              last_truth.translation().norm(), end_drift * 1e3, end_rot, worst_drift * 1e3);
  return 0;
}
