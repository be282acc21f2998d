// SegmentationScore on hand-made label images: detection rates, spurious detections, and the
// parameter errors of found detections kept apart by the range of their support.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "quadric_slam/frontend/segmentation_score.h"

namespace qs = quadric_slam;

namespace {

constexpr double kDeg = M_PI / 180.0;

// A detection of `shape` labelled `label`, its support centred on the shape's own point.
qs::QuadricDetection detectionOf(const qs::PrimitiveShape& shape, std::uint16_t label) {
  qs::QuadricDetection d;
  d.shape = shape;
  d.label = label;
  return d;
}

}  // namespace

TEST(SegmentationScore, ErrorsKeptApartByRangeOfTheSupport) {
  // Two walls facing the camera, 1 m and 3 m away: the left and right halves of a 4 x 4 image.
  const std::map<int, std::string> classes = {{1, "plane"}, {2, "plane"}};
  const std::map<int, qs::PrimitiveShape> truth_camera = {
      {1, qs::PrimitiveShape::plane(Eigen::Vector3d::UnitZ(), 1.0)},
      {2, qs::PrimitiveShape::plane(Eigen::Vector3d::UnitZ(), 3.0)}};
  cv::Mat truth(4, 4, CV_16UC1, cv::Scalar(1)), valid(4, 4, CV_8UC1, cv::Scalar(1));
  truth.colRange(2, 4).setTo(2);
  qs::Segmentation segmentation;
  segmentation.labels = truth.clone();
  // The near wall found 1 degree off, the far one 2 cm off.
  const Eigen::Vector3d tilted(std::sin(kDeg), 0.0, std::cos(kDeg));
  segmentation.detections.push_back(detectionOf(qs::PrimitiveShape::plane(tilted, 1.0), 1));
  segmentation.detections.push_back(
      detectionOf(qs::PrimitiveShape::plane(Eigen::Vector3d::UnitZ(), 3.02), 2));
  qs::SegmentationScore score(classes, 4);
  score.addFrame(segmentation, truth, valid, truth_camera);

  EXPECT_EQ(score.frames(), 1);
  EXPECT_EQ(score.spurious(), 0);
  EXPECT_TRUE(score.lastSpurious().empty());
  ASSERT_EQ(score.surfaces().size(), 2u);
  for (const auto& [id, surface] : score.surfaces())
    EXPECT_DOUBLE_EQ(surface.rate(), 1.0) << "surface " << id;

  const auto near = score.parameterErrors(0.0, 2.0), far = score.parameterErrors(2.0, 4.0);
  ASSERT_EQ(near.count("plane"), 1u);
  ASSERT_EQ(far.count("plane"), 1u);
  ASSERT_EQ(near.at("plane").first.size(), 1u);
  ASSERT_EQ(far.at("plane").first.size(), 1u);
  EXPECT_NEAR(near.at("plane").first[0], 1.0, 1e-6);   // normal angle (deg)
  EXPECT_NEAR(far.at("plane").first[0], 0.0, 1e-6);    // normal angle (deg)
  EXPECT_NEAR(far.at("plane").second[0], 0.02, 1e-9);  // offset (m)
  EXPECT_TRUE(score.parameterErrors(4.0, 10.0).empty());

  const std::string report = score.report();
  EXPECT_NE(report.find("median errors plane    0-2 m (   1 fits)"), std::string::npos) << report;
  EXPECT_NE(report.find("median errors plane    2-4 m (   1 fits)"), std::string::npos) << report;
}

TEST(SegmentationScore, DetectionOfAnotherClassIsSpuriousAndMissesTheSurface) {
  const std::map<int, std::string> classes = {{1, "plane"}};
  cv::Mat truth(4, 4, CV_16UC1, cv::Scalar(1)), valid(4, 4, CV_8UC1, cv::Scalar(1));
  qs::Segmentation segmentation;
  segmentation.labels = cv::Mat(4, 4, CV_16UC1, cv::Scalar(1));
  segmentation.detections.push_back(detectionOf(
      qs::PrimitiveShape::cylinder(Eigen::Vector3d(0, 0, 2), Eigen::Vector3d::UnitY(), 0.5), 1));
  qs::SegmentationScore score(classes, 4);
  score.addFrame(segmentation, truth, valid,
                 {{1, qs::PrimitiveShape::plane(Eigen::Vector3d::UnitZ(), 1.0)}});
  EXPECT_EQ(score.spurious(), 1);
  ASSERT_EQ(score.lastSpurious().size(), 1u);
  EXPECT_EQ(score.lastSpurious()[0], "cylinder 1 on plane 1");
  ASSERT_EQ(score.lastMissed().size(), 1u);
  EXPECT_EQ(score.lastMissed()[0], 1);
  EXPECT_TRUE(score.parameterErrors(0.0, 100.0).empty());
}
