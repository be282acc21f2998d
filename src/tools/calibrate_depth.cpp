// calibrate_depth: a depth camera's fixed disparity distortion from its own frames
// (frontend/depth_correction_estimator.h). Every Nth frame of a TUM folder or bag is
// back-projected, its normals estimated and segmented with the configured parameters; the planar
// segments' pixels feed the estimator, and the correction is written for run_bag --depth-correction
// (io/depth_correction_yaml.h). Prints the frames and segments used and the segments' disparity
// RMS before and after the correction.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "quadric_slam/frontend/depth_correction_estimator.h"
#include "quadric_slam/io/depth_correction_yaml.h"
#include "quadric_slam/pipeline/quadric_slam.h"
#include "quadric_slam/ros/recording_source.h"

namespace qs = quadric_slam;

namespace {

struct Options {
  std::string input, out;
  std::string config_dir = QUADRIC_SLAM_CONFIG_DIR;
  qs::CameraIntrinsics intrinsics;  // fx = 0: from the input
  double baseline = 0.075;          // m: the Kinect v1's projector-camera baseline
  long every = 10;
  long max_frames = -1;
  qs::DepthCorrectionEstimator::Params estimator;
};

int usage(const std::string& problem) {
  std::cerr
      << "calibrate_depth: " << problem << "\n"
      << "usage: calibrate_depth INPUT --out FILE [--intrinsics fx,fy,cx,cy] [--baseline M]\n"
      << "                       [--every N] [--max-frames N] [--config DIR] "
         "[--grid COLSxROWS]\n"
      << "  INPUT: a TUM folder (depth.txt, depth/) or a TUM rosbag\n"
      << "  --baseline: the sensor's projector-camera baseline (m, default 0.075: Kinect v1)\n"
      << "  --every: every Nth frame is used (default 10)\n"
      << "  --grid: nodes of the correction's grid (default 17x13)\n";
  return 2;
}

bool parseOptions(int argc, char** argv, Options& o, std::string& problem) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc)
        throw std::invalid_argument(arg + " needs a value");
      return argv[++i];
    };
    try {
      if (arg == "--out") {
        o.out = value();
      } else if (arg == "--config") {
        o.config_dir = value();
      } else if (arg == "--intrinsics") {
        if (!qs::parseIntrinsics(value(), o.intrinsics))
          throw std::invalid_argument("--intrinsics takes fx,fy,cx,cy");
      } else if (arg == "--baseline") {
        o.baseline = std::stod(value());
        if (!(o.baseline > 0.0 && o.baseline < 1.0))
          throw std::invalid_argument("--baseline must be in (0, 1) m");
      } else if (arg == "--every") {
        o.every = std::stol(value());
        if (o.every < 1)
          throw std::invalid_argument("--every must be >= 1");
      } else if (arg == "--max-frames") {
        o.max_frames = std::stol(value());
      } else if (arg == "--grid") {
        const std::string g = value();
        const std::size_t x = g.find('x');
        if (x == std::string::npos)
          throw std::invalid_argument("--grid takes COLSxROWS");
        o.estimator.cols = std::stoi(g.substr(0, x));
        o.estimator.rows = std::stoi(g.substr(x + 1));
      } else if (!arg.empty() && arg[0] == '-') {
        throw std::invalid_argument("unknown option " + arg);
      } else if (o.input.empty()) {
        o.input = arg;
      } else {
        throw std::invalid_argument("more than one INPUT given");
      }
    } catch (const std::exception& e) {
      problem = e.what();
      return false;
    }
  }
  if (o.input.empty())
    problem = "no INPUT given";
  else if (o.out.empty())
    problem = "--out is required";
  return problem.empty();
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  std::string problem;
  if (!parseOptions(argc, argv, o, problem))
    return usage(problem);
  try {
    const qs::SlamParams params = qs::loadSlamParams(o.config_dir);
    qs::NormalEstimator normals(params.normals);
    qs::QuadricSegmenter segmenter(params.segmentation);
    qs::BackProjectionParams back_projection = params.back_projection;
    back_projection.decimation = 1;  // the segments' pixels at full resolution
    std::unique_ptr<qs::FrameSource> source =
        qs::openRecording(o.input, qs::RecordingOptions{false, o.intrinsics});
    std::unique_ptr<qs::DepthCorrectionEstimator> estimator;
    qs::RgbdFrame frame;
    long index = 0, used_frames = 0;
    for (; source->next(frame); ++index) {
      if (o.max_frames >= 0 && index >= o.max_frames)
        break;
      if (index % o.every != 0)
        continue;
      const qs::CameraIntrinsics& k = frame.intrinsics;
      if (!estimator)
        estimator = std::make_unique<qs::DepthCorrectionEstimator>(k.width, k.height,
                                                                   k.fx * o.baseline, o.estimator);
      const pcl::PointCloud<pcl::PointNormal> cloud =
          normals.compute(qs::backProject(qs::depthViewOf(frame.depth_m), k, back_projection));
      const qs::Segmentation segmentation = segmenter.segment(cloud);
      ++used_frames;
      for (const qs::QuadricDetection& detection : segmentation.detections) {
        if (detection.shape.quadric_class != qs::QuadricClass::kPlane)
          continue;
        std::vector<Eigen::Vector2d> pixels;
        std::vector<double> depths;
        for (int v = 0; v < segmentation.labels.rows; ++v) {
          const std::uint16_t* row = segmentation.labels.ptr<std::uint16_t>(v);
          for (int u = 0; u < segmentation.labels.cols; ++u) {
            if (row[u] != detection.label)
              continue;
            const float z = cloud(u, v).z;
            if (!std::isfinite(z))
              continue;
            pixels.emplace_back(u, v);
            depths.push_back(z);
          }
        }
        estimator->addPlane(pixels, depths);
      }
    }
    if (!estimator || estimator->segments() == 0)
      throw std::runtime_error("no planar segment found in " + std::to_string(used_frames) +
                               " frames: nothing to calibrate from");
    const qs::DepthCorrection correction = estimator->solve();
    const qs::DepthCorrectionEstimator::Fit fit = estimator->fit(correction);
    double largest = 0.0;
    for (double d : correction.offsets())
      largest = std::max(largest, std::abs(d));
    std::printf("frames %ld\nsegments %d\npixels %lld\n", used_frames, estimator->segments(),
                estimator->pixels());
    std::printf(
        "disparity_rms_before_px %.5f\ndisparity_rms_after_px %.5f\nlargest_offset_px %.5f\n",
        fit.rms_before, fit.rms_after, largest);
    writeDepthCorrectionYaml(o.out, correction,
                             "from " + std::to_string(estimator->segments()) +
                                 " planar segments of " + std::to_string(used_frames) +
                                 " frames of " + o.input);
    std::printf("correction %s\n", o.out.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "calibrate_depth: " << e.what() << "\n";
    return 1;
  }
}
