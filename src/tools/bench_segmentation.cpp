// bench_segmentation: time of QuadricSegmenter per 640x480 frame (normals excluded) over the real
// frames in ../shared/data (OSD mosd_cylinders PCDs, TUM depth PNGs), every K-th frame of the real
// 7-Scenes kitchen sequence, frames of the generated desk and room scenes with the harsh Kinect
// model, and simple rendered synthetic frames, against the baseline the paper uses:
// CGAL Efficient RANSAC with plane, sphere, cylinder and cone on all points of the full frame.
//
//   bench_segmentation [--data DIR] [--repeats N (3)] [--synthetic N (10)] [--baseline-frames N
//   (8)] [--kitchen-every K (50; 0: no kitchen frames)] [--harsh N (10 per scene; 0: none)]
//
// Prints median and p95 per set and per stage, plane and curved segments per frame per set, the
// baseline's time, their ratio, and the machine load (uptime).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "quadric_slam/frontend/cgal_shape_detector.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/io/segmentation_input.h"
#include "quadric_slam/pipeline/segmenter_params.h"
#include "quadric_slam/sim/primitive_scene_renderer.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/synthetic_frame_source.h"

namespace qs = quadric_slam;
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double ms(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

double percentile(std::vector<double> v, double q) {
  if (v.empty())
    return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5));
  return v[i];
}

struct Frame {
  std::string name;
  pcl::PointCloud<pcl::PointNormal> cloud;
};

qs::CameraIntrinsics intrinsics(double fx, double fy, double cx, double cy) {
  qs::CameraIntrinsics k;
  k.fx = fx;
  k.fy = fy;
  k.cx = cx;
  k.cy = cy;
  return k;
}

std::vector<Frame> realFrames(const std::string& data, const qs::NormalEstimator& normals) {
  std::vector<Frame> frames;
  auto add = [&](const std::string& path, const qs::CameraIntrinsics& k, double scale) {
    try {
      frames.push_back({path, normals.compute(qs::loadOrganizedCloud(path, k, scale))});
    } catch (const std::exception&) {
      // not a depth frame (e.g. an RGB PNG)
    }
  };
  const std::vector<std::pair<std::string, qs::CameraIntrinsics>> tum = {
      {"fr1_xyz", intrinsics(517.3, 516.5, 318.6, 255.3)},
      {"fr2_desk", intrinsics(520.9, 521.0, 325.1, 249.7)},
      {"fr3_long_office_household", intrinsics(535.4, 539.2, 320.1, 247.6)}};
  for (const auto& [sequence, k] : tum) {
    const fs::path dir = fs::path(data) / "tum_frames" / sequence;
    if (!fs::exists(dir))
      continue;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().extension() == ".png")
        files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files)
      add(f.string(), k, sequence == "fr2_desk" ? 5208.0 : 5000.0);
  }
  const fs::path osd = fs::path(data) / "mosd_cylinders";
  if (fs::exists(osd)) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(osd))
      if (e.path().extension() == ".pcd")
        files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files)
      add(f.string(), qs::CameraIntrinsics(), 1.0);
  }
  return frames;
}

// Every K-th depth frame of the 7-Scenes kitchen (TUM layout, depth intrinsics 585/585/320/240).
std::vector<Frame> kitchenFrames(const std::string& data, int every,
                                 const qs::NormalEstimator& normals) {
  std::vector<Frame> frames;
  const fs::path dir = fs::path(data) / "7scenes_redkitchen";
  if (every <= 0 || !fs::exists(dir / "depth.txt"))
    return frames;
  const qs::CameraIntrinsics k = intrinsics(585, 585, 320, 240);
  std::ifstream list(dir / "depth.txt");
  std::string line;
  int i = 0;
  while (std::getline(list, line)) {
    if (line.empty() || line[0] == '#')
      continue;
    if (i++ % every != 0)
      continue;
    const std::string file = line.substr(line.find(' ') + 1);
    frames.push_back({"kitchen_" + std::to_string(i - 1),
                      normals.compute(qs::loadOrganizedCloud((dir / file).string(), k, 5000.0))});
  }
  return frames;
}

// Frames of the generated scenes with the harsh Kinect depth model (sim/kinect_depth_model.h, the
// generator's default): `count` frames at 1 Hz of each scene's seeded hand-held motion.
std::vector<Frame> harshFrames(const std::vector<std::string>& scenes, int count,
                               const qs::NormalEstimator& normals) {
  std::vector<Frame> frames;
  for (const std::string& path : scenes) {
    if (count <= 0)
      break;
    qs::SyntheticFrameSource::Params params;
    params.seconds = count;
    params.rate = 1.0;
    params.rgb = false;
    qs::SyntheticFrameSource source(qs::readSceneYaml(path), params);
    qs::RgbdFrame frame;
    while (source.next(frame)) {
      const qs::DepthImageView<float> view = qs::depthViewOf(frame.depth_m);
      frames.push_back(
          {fs::path(path).stem().string() + "_" + std::to_string(frames.size()),
           normals.compute(qs::backProject(view, frame.intrinsics, qs::BackProjectionParams()))});
    }
  }
  return frames;
}

// Desk-like rendered scenes: floor, wall, and a sphere, cylinder and cone at random places.
std::vector<Frame> syntheticFrames(int count, const qs::NormalEstimator& normals) {
  std::vector<Frame> frames;
  qs::CameraIntrinsics k = intrinsics(525, 525, 319.5, 239.5);
  k.width = 640;
  k.height = 480;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uni(-1, 1);
  for (int i = 0; i < count; ++i) {
    std::vector<qs::ScenePrimitive> scene(5);
    scene[0].shape = qs::PrimitiveShape::plane(Eigen::Vector3d(0, -1, 0), -0.8);
    scene[1].shape = qs::PrimitiveShape::plane(Eigen::Vector3d(0, 0, -1), -2.6);
    scene[2].shape = qs::PrimitiveShape::sphere(
        Eigen::Vector3d(-0.45 + 0.1 * uni(rng), 0.2 + 0.1 * uni(rng), 1.6 + 0.3 * uni(rng)),
        0.12 + 0.04 * uni(rng));
    scene[3].shape = qs::PrimitiveShape::cylinder(
        Eigen::Vector3d(0.05 + 0.1 * uni(rng), 0.8, 1.8 + 0.3 * uni(rng)),
        Eigen::Vector3d(0, -1, 0), 0.08 + 0.03 * uni(rng));
    scene[3].axis_max = 0.5;
    scene[4].shape =
        qs::PrimitiveShape::cone(Eigen::Vector3d(0.55 + 0.1 * uni(rng), 0.3, 1.5 + 0.3 * uni(rng)),
                                 Eigen::Vector3d(0, 1, 0), 0.4 + 0.1 * uni(rng));
    scene[4].axis_min = 0.1;
    scene[4].axis_max = 0.5;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = (Eigen::AngleAxisd(0.15 * uni(rng), Eigen::Vector3d::UnitX()) *
                  Eigen::AngleAxisd(0.15 * uni(rng), Eigen::Vector3d::UnitY()))
                     .toRotationMatrix();
    for (auto& p : scene)
      p.shape = p.shape.transformed(T);
    qs::RenderParams render;
    render.seed = 100 + i;
    const qs::PrimitiveRendering rendered = qs::renderPrimitives(scene, k, render);
    const qs::DepthImageView<float> view = qs::depthViewOf(rendered.depth);
    frames.push_back({"synthetic_" + std::to_string(i),
                      normals.compute(qs::backProject(view, k, qs::BackProjectionParams()))});
  }
  return frames;
}

// The baseline: CGAL Efficient RANSAC, all four shapes, every point with a normal.
double baselineMs(const pcl::PointCloud<pcl::PointNormal>& cloud, std::size_t& shapes) {
  const auto t0 = Clock::now();
  std::vector<Eigen::Vector3d> points, normals;
  for (const auto& p : cloud.points) {
    if (!std::isfinite(p.z) || !std::isfinite(p.normal_x))
      continue;
    points.emplace_back(p.x, p.y, p.z);
    normals.emplace_back(p.normal_x, p.normal_y, p.normal_z);
  }
  qs::CgalShapeDetector::Params params;
  params.planes = params.spheres = params.cylinders = params.cones = true;
  params.probability = 0.05;
  params.min_points = 500;
  params.epsilon = 0.008;
  params.cluster_epsilon = 0.03;
  params.normal_threshold = 0.85;
  shapes = qs::CgalShapeDetector(params).detect(points, normals).size();
  return ms(t0, Clock::now());
}

void report(const char* name, const std::vector<double>& times) {
  std::printf("%-28s n=%3zu  median %7.1f ms  p95 %7.1f ms\n", name, times.size(),
              percentile(times, 0.5), percentile(times, 0.95));
}

int usage() {
  std::fprintf(stderr,
               "usage: bench_segmentation [--data DIR] [--repeats N] [--synthetic N] "
               "[--baseline-frames N] [--kitchen-every K] [--harsh N] [--config "
               "segmentation.yaml] [--set KEY=VALUE]...\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data = QUADRIC_SLAM_SHARED_DATA_DIR;
  int repeats = 3, synthetic = 10, baseline_frames = 8, kitchen_every = 50, harsh = 10;
  qs::QuadricSegmenter::Params params;
  if (argc % 2 == 0)  // an option without its value, or --help
    return usage();
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i], value = argv[i + 1];
    if (arg == "--data")
      data = value;
    else if (arg == "--repeats")
      repeats = std::atoi(value.c_str());
    else if (arg == "--synthetic")
      synthetic = std::atoi(value.c_str());
    else if (arg == "--baseline-frames")
      baseline_frames = std::atoi(value.c_str());
    else if (arg == "--harsh")
      harsh = std::atoi(value.c_str());
    else if (arg == "--kitchen-every")
      kitchen_every = std::atoi(value.c_str());
    else if (arg == "--config")
      params = qs::loadSegmenterParams(value);
    else if (arg == "--set" && value.find('=') != std::string::npos)
      qs::setSegmenterParam(params, value.substr(0, value.find('=')),
                            std::atof(value.c_str() + value.find('=') + 1));
    else
      return usage();
  }
  const qs::NormalEstimator normals{qs::NormalEstimator::Params()};
  const qs::QuadricSegmenter segmenter(params);
  const std::vector<Frame> real = realFrames(data, normals);
  const std::vector<Frame> kitchen = kitchenFrames(data, kitchen_every, normals);
  const std::vector<Frame> synth = syntheticFrames(synthetic, normals);
  const std::string scenes = std::string(QUADRIC_SLAM_CONFIG_DIR) + "/scenes/";
  const std::vector<Frame> harsh_frames =
      harshFrames({scenes + "desk.yaml", scenes + "room.yaml"}, harsh, normals);
  std::printf(
      "frames: %zu real (%s), %zu kitchen (every %d-th), %zu harsh-model (desk, room), %zu "
      "synthetic; %d repeats each\n",
      real.size(), data.c_str(), kitchen.size(), kitchen_every, harsh_frames.size(), synth.size(),
      repeats);

  // Segments per frame, per set: planes and curved (sphere, cylinder, cone, general).
  struct Counts {
    double frames = 0, planes = 0, curved = 0, ransac_points = 0, candidates = 0;
    // Per-frame stage times of this set; "other" is the frame's time outside the five stages.
    std::vector<double> planes_ms, ransac_ms, verify_ms, upsample_ms, boundary_ms, other_ms;
  };
  Counts real_counts, kitchen_counts, harsh_counts, synth_counts;
  std::vector<double> real_ms, kitchen_ms, harsh_ms, synth_ms, all_ms, planes_ms, ransac_ms,
      verify_ms, upsample_ms, boundary_ms;
  for (int r = 0; r < repeats; ++r) {
    for (const auto* set : {&real, &kitchen, &harsh_frames, &synth}) {
      for (const Frame& f : *set) {
        const auto t0 = Clock::now();
        const qs::Segmentation s = segmenter.segment(f.cloud);
        const double t = ms(t0, Clock::now());
        (set == &real      ? real_ms
         : set == &kitchen ? kitchen_ms
         : set == &synth   ? synth_ms
                           : harsh_ms)
            .push_back(t);
        Counts& counts = set == &real      ? real_counts
                         : set == &kitchen ? kitchen_counts
                         : set == &synth   ? synth_counts
                                           : harsh_counts;
        counts.frames += 1;
        counts.ransac_points += s.timings.ransac_points;
        counts.candidates += s.timings.ransac_candidates;
        for (const qs::QuadricDetection& d : s.detections)
          (d.shape.quadric_class == qs::QuadricClass::kPlane ? counts.planes : counts.curved) += 1;
        const qs::SegmentationTimings& st = s.timings;
        counts.planes_ms.push_back(st.planes_ms);
        counts.ransac_ms.push_back(st.ransac_ms);
        counts.verify_ms.push_back(st.verify_ms);
        counts.upsample_ms.push_back(st.upsample_ms);
        counts.boundary_ms.push_back(st.boundary_ms);
        counts.other_ms.push_back(t - st.planes_ms - st.ransac_ms - st.verify_ms - st.upsample_ms -
                                  st.boundary_ms);
        all_ms.push_back(t);
        planes_ms.push_back(s.timings.planes_ms);
        ransac_ms.push_back(s.timings.ransac_ms);
        verify_ms.push_back(s.timings.verify_ms);
        upsample_ms.push_back(s.timings.upsample_ms);
        boundary_ms.push_back(s.timings.boundary_ms);
      }
    }
  }
  std::vector<double> base_ms;
  std::size_t base_shapes = 0;
  const std::size_t step =
      std::max<std::size_t>(1, (real.size() + kitchen.size() + harsh_frames.size() + synth.size()) /
                                   std::max(1, baseline_frames));
  std::vector<const Frame*> everything;
  for (const auto& f : real)
    everything.push_back(&f);
  for (const auto& f : kitchen)
    everything.push_back(&f);
  for (const auto& f : harsh_frames)
    everything.push_back(&f);
  for (const auto& f : synth)
    everything.push_back(&f);
  for (std::size_t i = 0;
       i < everything.size() && static_cast<int>(base_ms.size()) < baseline_frames; i += step) {
    std::size_t shapes = 0;
    base_ms.push_back(baselineMs(everything[i]->cloud, shapes));
    base_shapes += shapes;
  }

  std::printf("QuadricSegmenter (normals excluded):\n");
  report("  real frames", real_ms);
  report("  kitchen frames", kitchen_ms);
  report("  harsh-model frames", harsh_ms);
  report("  synthetic frames", synth_ms);
  report("  all frames", all_ms);
  report("    stage: planes", planes_ms);
  report("    stage: ransac", ransac_ms);
  report("    stage: verification", verify_ms);
  report("    stage: upsampling", upsample_ms);
  report("    stage: boundary", boundary_ms);
  for (const auto& [name, c] : {std::pair<const char*, Counts>{"real", real_counts},
                                {"kitchen", kitchen_counts},
                                {"harsh", harsh_counts},
                                {"synthetic", synth_counts}})
    if (c.frames > 0)
      std::printf(
          "  per frame, %-9s  segments: planes %5.1f  curved %5.1f;  RANSAC input %6.0f "
          "points, %5.1f candidates\n",
          name, c.planes / c.frames, c.curved / c.frames, c.ransac_points / c.frames,
          c.candidates / c.frames);
  for (const auto& [name, c] : {std::pair<const char*, Counts>{"real", real_counts},
                                {"kitchen", kitchen_counts},
                                {"harsh", harsh_counts},
                                {"synthetic", synth_counts}})
    if (c.frames > 0)
      std::printf(
          "  stage medians, %-9s planes %4.1f  ransac %4.1f  verification %4.1f  "
          "upsampling %4.1f  boundary %4.1f  other %4.1f ms\n",
          name, percentile(c.planes_ms, 0.5), percentile(c.ransac_ms, 0.5),
          percentile(c.verify_ms, 0.5), percentile(c.upsample_ms, 0.5),
          percentile(c.boundary_ms, 0.5), percentile(c.other_ms, 0.5));
  if (!base_ms.empty()) {
    std::printf("Baseline, CGAL Efficient RANSAC, 4 shapes, full frame (%zu shapes total):\n",
                base_shapes);
    report("  baseline frames", base_ms);
    std::printf("speed-up (baseline median / all-frames median): %.1fx\n",
                percentile(base_ms, 0.5) / std::max(1e-9, percentile(all_ms, 0.5)));
  }
  std::ifstream loadavg("/proc/loadavg");
  std::string l1, l5, l15;
  loadavg >> l1 >> l5 >> l15;
  std::printf("machine load (1/5/15 min): %s %s %s on %u hardware threads\n", l1.c_str(),
              l5.c_str(), l15.c_str(), std::thread::hardware_concurrency());
  return 0;
}
