// eval_segmentation: the segmenter over a synthetic sequence written by scripts/synth (TUM folder
// with labels/<stamp>.png and quadrics_gt.yaml): per primitive with enough valid pixels, the share
// of frames in which its class is detected on it, the spurious detections per frame, and the
// median parameter errors of the detections found, per class and band of range from the camera
// (0-2 m, 2-4 m, beyond; truth: quadrics_gt.yaml moved into the camera frame by groundtruth.txt,
// T_world_camera).
//
//   eval_segmentation DIR [--stride K (1)] [--max-frames N (all)] [--min-pixels P (2000)]
//                         [--config segmentation.yaml]
//                         [--verbose 1: per frame, the stamp, the ids of missed surfaces and the
//                          spurious detections ("<class> <label> on <surface class> <id>")]
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/frontend/segmentation_score.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/pipeline/segmenter_params.h"
#include "quadric_slam/sim/sequence_generator.h"

namespace qs = quadric_slam;

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr,
                 "usage: eval_segmentation DIR [--stride K] [--max-frames N] [--min-pixels P] "
                 "[--config segmentation.yaml] [--verbose 1]\n");
    return 2;
  }
  const std::string dir = argv[1];
  int stride = 1, max_frames = 1 << 30, min_pixels = qs::kLargeViewPixels;
  bool verbose = false;
  qs::QuadricSegmenter::Params params;
  try {
    for (int i = 2; i + 1 < argc; i += 2) {
      const std::string arg = argv[i], value = argv[i + 1];
      if (arg == "--stride")
        stride = std::max(1, std::atoi(value.c_str()));
      else if (arg == "--max-frames")
        max_frames = std::atoi(value.c_str());
      else if (arg == "--min-pixels")
        min_pixels = std::atoi(value.c_str());
      else if (arg == "--verbose")
        verbose = value == "1";
      else if (arg == "--config")
        params = qs::loadSegmenterParams(value);
      else
        throw std::invalid_argument("unknown option " + arg);
    }
    const YAML::Node camera = YAML::LoadFile(dir + "/scene.yaml")["camera"];
    qs::CameraIntrinsics k;
    k.fx = camera["fx"].as<double>();
    k.fy = camera["fy"].as<double>();
    k.cx = camera["cx"].as<double>();
    k.cy = camera["cy"].as<double>();
    std::map<int, std::string> classes;
    std::map<int, qs::PrimitiveShape> truth_world;
    for (const qs::MapFileQuadric& q : qs::readMapYaml(dir + "/quadrics_gt.yaml").quadrics) {
      classes[q.id] = q.quadric_class;
      if (q.quadric_class == "plane" || q.quadric_class == "sphere" ||
          q.quadric_class == "cylinder" || q.quadric_class == "cone")
        truth_world[q.id] = qs::PrimitiveShape::fromQuadric(
            qs::quadricFromShapeMap(qs::quadricClassFromString(q.quadric_class), q.shape));
    }
    std::map<long long, Eigen::Isometry3d> poses;  // stamp in microseconds -> T_world_camera
    for (const qs::StampedPose& pose : qs::readTumTrajectory(dir + "/groundtruth.txt"))
      poses[std::llround(pose.stamp * 1e6)] = pose.T_world_sensor;
    qs::SegmentationScore score(classes, min_pixels);
    const qs::NormalEstimator normals{qs::NormalEstimator::Params()};
    const qs::QuadricSegmenter segmenter(params);
    std::ifstream list(dir + "/depth.txt");
    if (!list)
      throw std::runtime_error("cannot read " + dir + "/depth.txt");
    int index = 0, used = 0;
    for (std::string line; std::getline(list, line) && used < max_frames;) {
      if (line.empty() || line[0] == '#')
        continue;
      if (index++ % stride != 0)
        continue;
      std::istringstream in(line);
      std::string stamp, file;
      in >> stamp >> file;
      const cv::Mat depth = qs::readTumDepthPng(dir + "/" + file);
      const std::string name = file.substr(file.find_last_of('/') + 1);
      const cv::Mat truth = cv::imread(dir + "/labels/" + name, cv::IMREAD_ANYDEPTH);
      if (truth.empty() || truth.type() != CV_16UC1)
        throw std::runtime_error("cannot read the label image labels/" + name);
      k.width = depth.cols;
      k.height = depth.rows;
      const qs::DepthImageView<float> view = qs::depthViewOf(depth);
      const auto cloud = normals.compute(qs::backProject(view, k, qs::BackProjectionParams()));
      const qs::Segmentation segmentation = segmenter.segment(cloud);
      cv::Mat valid = depth == depth;  // not NaN
      const auto pose = poses.find(std::llround(std::stod(stamp) * 1e6));
      if (pose == poses.end())
        throw std::runtime_error("no ground-truth pose at stamp " + stamp);
      std::map<int, qs::PrimitiveShape> truth_camera;
      for (const auto& [id, shape] : truth_world)
        truth_camera[id] = shape.transformed(pose->second.inverse());
      score.addFrame(segmentation, truth, valid, truth_camera);
      if (verbose && !score.lastMissed().empty()) {
        std::printf("%s missed:", stamp.c_str());
        for (int id : score.lastMissed())
          std::printf(" %d", id);
        std::printf("\n");
      }
      if (verbose && !score.lastSpurious().empty()) {
        std::printf("%s spurious:", stamp.c_str());
        for (std::size_t k = 0; k < score.lastSpurious().size(); ++k)
          std::printf("%s %s", k ? ";" : "", score.lastSpurious()[k].c_str());
        std::printf("\n");
      }
      ++used;
    }
    std::printf("%s", score.report().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "eval_segmentation: %s\n", e.what());
    return 1;
  }
  return 0;
}
