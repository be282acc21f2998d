// A short sequence of the synthetic generator (the `synth` tool built beside the test binary),
// segmented frame by frame with the default normal estimator and segmenter and scored against its
// label images with SegmentationScore (primitives with at least min_pixels valid pixels in a frame;
// parameter errors of the detections within error_range metres).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <optional>
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

namespace quadric_slam {
namespace test {

// The synth tool beside this test binary; empty when it is not built.
inline std::filesystem::path synthTool() {
  const std::filesystem::path synth =
      std::filesystem::read_symlink("/proc/self/exe").parent_path() / "synth";
  return std::filesystem::exists(synth) ? synth : std::filesystem::path();
}

// The synth arguments of a scene of config/scenes ("desk", "room") under the default (harsh) depth
// model at 1 Hz for 30 s: the sequences of docs/segmentation/README.md.
inline std::string sceneSequenceArguments(const std::string& scene, int seed) {
  return "--scene " + std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/" + scene +
         ".yaml --seconds 30 --rate 1 --no-bag --seed " + std::to_string(seed);
}

// Expects surface `id` to be of `quadric_class`, scored in at least min_frames frames and detected
// in at least min_rate of them.
inline void expectSurfaceFound(const SegmentationScore& score, int id,
                               const std::string& quadric_class, int min_frames, double min_rate) {
  const auto surface = score.surfaces().find(id);
  ASSERT_NE(surface, score.surfaces().end()) << "surface " << id << " never scored";
  ASSERT_EQ(surface->second.quadric_class, quadric_class);
  EXPECT_GE(surface->second.frames_scored, min_frames) << "surface " << id;
  EXPECT_GE(surface->second.rate(), min_rate) << "surface " << id;
}

// Renders `synth_arguments` (everything but --out) into a temporary folder named `name` and scores
// the segmenter on every frame; nullopt (with a test failure) when rendering or reading fails.
inline std::optional<SegmentationScore> scoreSynthSequence(const std::string& name,
                                                           const std::string& synth_arguments,
                                                           int min_pixels) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(testing::TempDir()) / name;
  fs::remove_all(dir);
  const std::string command =
      synthTool().string() + " --out " + dir.string() + " " + synth_arguments + " > /dev/null";
  if (std::system(command.c_str()) != 0) {
    ADD_FAILURE() << command;
    return std::nullopt;
  }
  std::map<int, std::string> classes;
  std::map<int, PrimitiveShape> truth_world;
  for (const MapFileQuadric& q : readMapYaml((dir / "quadrics_gt.yaml").string()).quadrics) {
    classes[q.id] = q.quadric_class;
    if (q.quadric_class == "plane" || q.quadric_class == "sphere" ||
        q.quadric_class == "cylinder" || q.quadric_class == "cone")
      truth_world[q.id] = PrimitiveShape::fromQuadric(
          quadricFromShapeMap(quadricClassFromString(q.quadric_class), q.shape));
  }
  std::map<long long, Eigen::Isometry3d> poses;  // stamp (us) -> T_world_camera
  for (const StampedPose& pose : readTumTrajectory((dir / "groundtruth.txt").string()))
    poses[std::llround(pose.stamp * 1e6)] = pose.T_world_sensor;
  SegmentationScore score(classes, min_pixels);
  CameraIntrinsics k;
  k.fx = k.fy = 525.0;
  k.cx = 319.5;
  k.cy = 239.5;
  const NormalEstimator normals{NormalEstimator::Params()};
  const QuadricSegmenter segmenter{QuadricSegmenter::Params()};
  std::ifstream list(dir / "depth.txt");
  if (!list.good()) {
    ADD_FAILURE() << "no depth.txt in " << dir;
    return std::nullopt;
  }
  for (std::string line; std::getline(list, line);) {
    if (line.empty() || line[0] == '#')
      continue;
    std::istringstream in(line);
    std::string stamp, file;
    in >> stamp >> file;
    const cv::Mat depth = readTumDepthPng((dir / file).string());
    const cv::Mat truth =
        cv::imread((dir / "labels" / fs::path(file).filename()).string(), cv::IMREAD_ANYDEPTH);
    const auto pose = poses.find(std::llround(std::stod(stamp) * 1e6));
    if (truth.type() != CV_16UC1 || pose == poses.end()) {
      ADD_FAILURE() << "no labels or no ground-truth pose at " << stamp;
      return std::nullopt;
    }
    k.width = depth.cols;
    k.height = depth.rows;
    const auto cloud = normals.compute(backProject(depthViewOf(depth), k, BackProjectionParams()));
    std::map<int, PrimitiveShape> truth_camera;
    for (const auto& [id, shape] : truth_world)
      truth_camera[id] = shape.transformed(pose->second.inverse());
    score.addFrame(segmenter.segment(cloud), truth, depth == depth, truth_camera);
  }
  fs::remove_all(dir);
  return score;
}

}  // namespace test
}  // namespace quadric_slam
