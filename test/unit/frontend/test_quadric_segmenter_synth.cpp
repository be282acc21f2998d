// The segmenter on a short sequence of the synthetic generator (the `synth` tool built beside this
// test: desk scene, hand-held motion, Kinect depth model, label images), scored with
// SegmentationScore: every plane/sphere/cylinder/cone with >= 2000 valid pixels in a frame is
// detected with its class in >= 95% of those frames, and there are <= 0.5 spurious detections per
// frame on average, not counting detections on the ellipsoid cushion (a class the segmenter does
// not model; it is reported). (The full-length figure comes from the eval_segmentation tool.)
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/frontend/segmentation_score.h"
#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/map_yaml.h"

namespace qs = quadric_slam;
namespace fs = std::filesystem;

TEST(QuadricSegmenterSynth, DeskSequencePrimitivesFoundWithFewSpuriousDetections) {
  const fs::path synth = fs::read_symlink("/proc/self/exe").parent_path() / "synth";
  if (!fs::exists(synth))
    GTEST_SKIP() << "the synth tool is not built at " << synth;
  const fs::path dir = fs::path(testing::TempDir()) / "segmenter_synth_desk";
  fs::remove_all(dir);
  const std::string command = synth.string() + " --out " + dir.string() +
                              " --seconds 1 --rate 5 --no-bag --seed 3 --threads 1 > /dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;

  std::map<int, std::string> classes;
  for (const qs::MapFileQuadric& q : qs::readMapYaml((dir / "quadrics_gt.yaml").string()).quadrics)
    classes[q.id] = q.quadric_class;
  qs::SegmentationScore score(classes, 2000);
  qs::CameraIntrinsics k;
  k.fx = k.fy = 525.0;
  k.cx = 319.5;
  k.cy = 239.5;
  const qs::NormalEstimator normals{qs::NormalEstimator::Params()};
  const qs::QuadricSegmenter segmenter{qs::QuadricSegmenter::Params()};
  std::ifstream list(dir / "depth.txt");
  ASSERT_TRUE(list.good());
  for (std::string line; std::getline(list, line);) {
    if (line.empty() || line[0] == '#')
      continue;
    std::istringstream in(line);
    std::string stamp, file;
    in >> stamp >> file;
    const cv::Mat depth = qs::readTumDepthPng((dir / file).string());
    const cv::Mat truth =
        cv::imread((dir / "labels" / fs::path(file).filename()).string(), cv::IMREAD_ANYDEPTH);
    ASSERT_EQ(truth.type(), CV_16UC1);
    k.width = depth.cols;
    k.height = depth.rows;
    qs::DepthImageView<float> view;
    view.data = depth.data;
    view.width = depth.cols;
    view.height = depth.rows;
    view.row_step_bytes = depth.step[0];
    const auto cloud = normals.compute(qs::backProject(view, k, qs::BackProjectionParams()));
    score.addFrame(segmenter.segment(cloud), truth, depth == depth);
  }
  std::printf("%s", score.report().c_str());
  ASSERT_GE(score.frames(), 4);
  ASSERT_FALSE(score.surfaces().empty());
  for (const auto& [id, s] : score.surfaces())
    EXPECT_GE(s.rate(), 0.95) << "surface " << id << " (" << s.quadric_class << ")";
  // Spurious detections on the four modelled classes' surfaces or on nothing. Not counted here:
  // detections on the cushion, an ellipsoid (no class of the segmenter), which comes out as a
  // sphere in most frames; the report above prints them and they are in score.spurious().
  EXPECT_LE(score.spuriousPerFrameOnModelled(), 0.5);
  fs::remove_all(dir);
}
