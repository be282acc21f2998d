// QuadricSegmenter on real Kinect frames:
// - OSD table-top scenes (../shared/data/mosd_cylinders, learn33..44; research-use, not shipped:
//   skipped when absent): the table is a plane in every scene, and
//   at least 90% of the upright cylindrical objects are cylinders whose labels overlap the
//   object's labelled pixels with IoU >= 0.5.
// - TUM fr3_long_office_household, depth 1341847980.723020 (test/data): the globe is a sphere,
//   the desk top and the floor are planes.
#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>

#include "../real_frames.h"
#include "../test_data.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/io/segmentation_input.h"

namespace qs = quadric_slam;
using qs::QuadricClass;

namespace {

qs::Segmentation segmentCloud(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                              const qs::QuadricSegmenter::Params& params) {
  const auto with_normals = qs::NormalEstimator(qs::NormalEstimator::Params()).compute(cloud);
  return qs::QuadricSegmenter(params).segment(with_normals);
}

// Per detection label, its pixels' overlap with each ground-truth label.
struct Overlap {
  std::map<int, int> detection_size, truth_size;
  std::map<std::pair<int, int>, int> both;  // (detection, truth) -> pixels

  double iou(int detection, int truth) const {
    const auto it = both.find({detection, truth});
    const int b = it == both.end() ? 0 : it->second;
    const int u = at(detection_size, detection) + at(truth_size, truth) - b;
    return u > 0 ? static_cast<double>(b) / u : 0.0;
  }
  static int at(const std::map<int, int>& m, int k) {
    const auto it = m.find(k);
    return it == m.end() ? 0 : it->second;
  }
};

// The upright cylindrical objects of each OSD scene (scene -> object labels; label 1 is the table
// in every scene). Chosen by fitting each labelled object of >= 1000 points with a cylinder
// whose axis starts along the table's normal (ShapeRefiner): listed when the fitted axis is within
// 10 deg of the table normal, the radius in [2, 12] cm and the fit RMS <= 8 mm (the mugs, cups and
// the straight walls of the round boxes/bowls, each label a separately labelled part), and checked
// against the colour images (learn33: two mugs; learn38: two white cups and the yellow bowl's
// outer and inner wall). Not listed: the lying tin (learn38), the hemispherical bowls, and
// objects tilted 11-37 deg from the table normal or with RMS 9-20 mm (e.g. learn43 label 40:
// 8.8 mm, a cup with a lid).
const std::map<std::string, std::set<int>> kUprightCylinders = {{"learn33", {50, 51, 60, 61}},
                                                                {"learn34", {}},
                                                                {"learn35", {}},
                                                                {"learn36", {40, 43}},
                                                                {"learn37", {40, 43}},
                                                                {"learn38", {20, 30, 50, 53}},
                                                                {"learn39", {30, 31, 40, 41}},
                                                                {"learn40", {30}},
                                                                {"learn41", {}},
                                                                {"learn42", {30}},
                                                                {"learn43", {}},
                                                                {"learn44", {30, 40, 41}}};

void checkOsdTablesAndCylinders(const qs::QuadricSegmenter::Params& params) {
  const std::string dir = qs::test::sharedData("mosd_cylinders").string();
  QS_SKIP_WITHOUT_SHARED_DATA(dir, qs::test::kResearchUseOnly);
  int cylinders = 0, found = 0;
  for (const auto& [scene, objects] : kUprightCylinders) {
    pcl::PointCloud<pcl::PointXYZRGBL> labelled;
    ASSERT_EQ(pcl::io::loadPCDFile(dir + "/" + scene + ".pcd", labelled), 0) << scene;
    pcl::PointCloud<pcl::PointXYZ> cloud(labelled.width, labelled.height);
    for (std::size_t i = 0; i < labelled.size(); ++i) {
      cloud.points[i].x = labelled.points[i].x;
      cloud.points[i].y = labelled.points[i].y;
      cloud.points[i].z = labelled.points[i].z;
    }
    const qs::Segmentation result = segmentCloud(cloud, params);
    Overlap overlap;
    for (std::size_t i = 0; i < labelled.size(); ++i) {
      const int d = result.labels.at<std::uint16_t>(static_cast<int>(i / labelled.width),
                                                    static_cast<int>(i % labelled.width));
      const int t = static_cast<int>(labelled.points[i].label);
      if (std::isfinite(labelled.points[i].z))
        ++overlap.truth_size[t];
      ++overlap.detection_size[d];
      ++overlap.both[{d, t}];
    }
    // The table is label 1 in every scene (the largest object, one plane).
    bool table = false;
    Eigen::Vector3d table_normal = Eigen::Vector3d::Zero();
    for (const qs::QuadricDetection& d : result.detections) {
      if (d.shape.quadric_class == QuadricClass::kPlane && overlap.iou(d.label, 1) > 0.7) {
        table = true;
        table_normal = d.shape.direction;
      }
    }
    EXPECT_TRUE(table) << scene << ": no plane covers the table";
    if (std::getenv("QS_DEBUG_DIR")) {
      for (const auto& [t, size] : overlap.truth_size) {
        if (t == 0)
          continue;
        int best = 0;
        double best_iou = 0;
        for (const qs::QuadricDetection& d : result.detections)
          if (overlap.iou(d.label, t) > best_iou) {
            best_iou = overlap.iou(d.label, t);
            best = d.label;
          }
        std::printf(
            "%s object %d pixels %d best %s iou %.2f\n", scene.c_str(), t, size,
            best ? qs::toString(result.detections[best - 1].shape.quadric_class).c_str() : "-",
            best_iou);
      }
      cv::imwrite(std::string(std::getenv("QS_DEBUG_DIR")) + "/" + scene + ".png",
                  qs::colouriseLabels(result.labels));
      cv::Mat rgb(labelled.height, labelled.width, CV_8UC3);
      for (std::size_t i = 0; i < labelled.size(); ++i)
        rgb.at<cv::Vec3b>(i / labelled.width, i % labelled.width) =
            cv::Vec3b(labelled.points[i].b, labelled.points[i].g, labelled.points[i].r);
      cv::imwrite(std::string(std::getenv("QS_DEBUG_DIR")) + "/" + scene + "_rgb.png", rgb);
    }
    for (int object : objects) {
      ++cylinders;
      double best_iou = 0;
      for (const qs::QuadricDetection& d : result.detections)
        if (d.shape.quadric_class == QuadricClass::kCylinder)
          best_iou = std::max(best_iou, overlap.iou(d.label, object));
      if (best_iou >= 0.5)
        ++found;
      else
        std::printf("%s: upright cylinder %d not found (best cylinder IoU %.2f)\n", scene.c_str(),
                    object, best_iou);
    }
  }
  ASSERT_GT(cylinders, 0);
  std::printf("upright cylinders found: %d of %d\n", found, cylinders);
  // The segmentation issue's bar: >= 90% of the upright cylinders (19 of 21 today).
  EXPECT_GE(found, 0.9 * cylinders);
}

}  // namespace

TEST(QuadricSegmenterReal, OsdTablesArePlanesAndUprightCylindersAreCylinders) {
  checkOsdTablesAndCylinders(qs::QuadricSegmenter::Params());
}

namespace {

// Pixel (u, v) of a camera-frame point with the Freiburg3 intrinsics.
Eigen::Vector2d project(const Eigen::Vector3d& p) {
  return Eigen::Vector2d(535.4 * p.x() / p.z() + 320.1, 539.2 * p.y() / p.z() + 247.6);
}

void checkFr3GlobeDeskAndFloor(const qs::QuadricSegmenter::Params& params) {
  const std::string file = qs::test::shippedData(qs::test::kFr3HouseholdDepth).string();
  qs::CameraIntrinsics k;
  k.fx = 535.4;
  k.fy = 539.2;
  k.cx = 320.1;
  k.cy = 247.6;
  const qs::Segmentation result = segmentCloud(qs::loadOrganizedCloud(file, k, 5000.0), params);

  // The globe: a sphere in the top-left part of the image, of a globe's size.
  int globes = 0;
  for (const qs::QuadricDetection& d : result.detections) {
    if (d.shape.quadric_class != QuadricClass::kSphere)
      continue;
    const Eigen::Vector2d uv = project(d.shape.point);
    if (uv.x() < 220 && uv.y() < 160) {
      ++globes;
      std::printf("globe: centre (%.3f, %.3f, %.3f) m, radius %.3f m, %d points, rms %.4f m\n",
                  d.shape.point.x(), d.shape.point.y(), d.shape.point.z(), d.shape.size,
                  d.num_points, d.fit_rms);
      // The globe's radius (issue 11): 0.21 m, to within 1 cm.
      EXPECT_NEAR(d.shape.size, 0.21, 0.01);
      EXPECT_GT(d.num_points, 2000);
    }
  }
  EXPECT_EQ(globes, 1) << "the globe is one sphere";

  // The floor: the plane holding most of the floor strip (rows 430-475, the README's robust
  // fit region). The desk top: a plane parallel to it, 0.4-1.0 m closer to the camera along the
  // normal (a desk is ~0.7 m high), with >= 3000 points.
  std::map<int, int> strip;
  for (int v = 430; v < 476; ++v)
    for (int u = 0; u < result.labels.cols; ++u)
      ++strip[result.labels.at<std::uint16_t>(v, u)];
  int floor_label = 0, floor_count = 0;
  for (const auto& [label, count] : strip)
    if (label != 0 && count > floor_count &&
        result.detections[label - 1].shape.quadric_class == QuadricClass::kPlane) {
      floor_label = label;
      floor_count = count;
    }
  ASSERT_GT(floor_label, 0) << "no plane in the floor strip";
  const qs::PrimitiveShape& floor = result.detections[floor_label - 1].shape;
  bool desk = false;
  for (const qs::QuadricDetection& d : result.detections) {
    if (d.shape.quadric_class != QuadricClass::kPlane || d.num_points < 3000)
      continue;
    const double cos_angle = d.shape.direction.dot(floor.direction);
    if (cos_angle < std::cos(10 * M_PI / 180))
      continue;
    const double height = std::abs(floor.planeOffset()) - std::abs(d.shape.planeOffset());
    if (height > 0.4 && height < 1.0) {
      desk = true;
      std::printf("desk top %.2f m above the floor (%d points)\n", height, d.num_points);
    }
  }
  EXPECT_TRUE(desk) << "no desk-top plane parallel to the floor";
}

}  // namespace

TEST(QuadricSegmenterReal, Fr3GlobeIsASphereDeskTopAndFloorArePlanes) {
  checkFr3GlobeDeskAndFloor(qs::QuadricSegmenter::Params());
}

// The same with the curved stages on a grid decimated once more (curved_decimation).
TEST(QuadricSegmenterReal, Fr3GlobeWithCurvedShapesOnACoarserGrid) {
  qs::QuadricSegmenter::Params params;
  params.curved_decimation = 2;
  checkFr3GlobeDeskAndFloor(params);
}

// The curved candidates are verified in parallel, and again in order where an earlier kept one
// took pixels that a verdict read: the segmentation with two threads is the one with one, on the
// shipped TUM frames, where that happens.
TEST(QuadricSegmenterReal, ParallelCurvedVerificationGivesTheSequentialSegmentation) {
  int verified_again = 0, curved = 0;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(qs::test::shippedData("tum_frames"))) {
    // Depth frames only (a colour image lies beside them).
    if (entry.path().extension() != ".png" ||
        cv::imread(entry.path().string(), cv::IMREAD_UNCHANGED).depth() != CV_16U)
      continue;
    const std::string sequence = entry.path().parent_path().filename().string();
    const cv::Mat depth_m = qs::readTumDepthPng(entry.path().string());
    qs::CameraIntrinsics k = qs::tumIntrinsicsForSequence(sequence);
    k.width = depth_m.cols;
    k.height = depth_m.rows;
    const auto cloud = qs::NormalEstimator(qs::NormalEstimator::Params())
                           .compute(qs::backProject(qs::depthViewOf(depth_m), k, {}));
    qs::QuadricSegmenter::Params params;
    params.threads = 1;
    const qs::Segmentation one = qs::QuadricSegmenter(params).segment(cloud);
    params.threads = 2;
    const qs::Segmentation two = qs::QuadricSegmenter(params).segment(cloud);
    const std::string frame = entry.path().string();
    EXPECT_EQ(one.timings.curved_verified_again, 0) << frame;
    verified_again += two.timings.curved_verified_again;
    ASSERT_EQ(one.detections.size(), two.detections.size()) << frame;
    EXPECT_EQ(cv::countNonZero(one.labels != two.labels), 0) << frame;
    for (std::size_t i = 0; i < one.detections.size(); ++i) {
      const qs::QuadricDetection &a = one.detections[i], &b = two.detections[i];
      curved += a.shape.quadric_class != QuadricClass::kPlane;
      EXPECT_EQ(a.shape.quadric_class, b.shape.quadric_class) << frame << " #" << i;
      EXPECT_EQ(a.shape.point, b.shape.point) << frame << " #" << i;
      EXPECT_EQ(a.shape.direction, b.shape.direction) << frame << " #" << i;
      EXPECT_EQ(a.shape.size, b.shape.size) << frame << " #" << i;
      EXPECT_EQ(a.num_points, b.num_points) << frame << " #" << i;
      // The full-resolution tallies are summed per thread: the last bits may differ.
      EXPECT_NEAR(a.fit_rms, b.fit_rms, 1e-12) << frame << " #" << i;
    }
  }
  std::printf("%d curved detections, %d verdicts verified again\n", curved, verified_again);
  EXPECT_GT(curved, 5);
  EXPECT_GT(verified_again, 0) << "no frame took the path of verifying again";
}
