#include "quadric_slam/pipeline/quadric_slam.h"

#include <filesystem>
#include <stdexcept>
#include <vector>

#include "quadric_slam/frontend/detection_measurement.h"
#include "quadric_slam/pipeline/pipeline_params.h"
#include "quadric_slam/pipeline/segmenter_params.h"

namespace quadric_slam {

namespace {

// The points of each label 1..count of a segmentation's label image (index label - 1).
std::vector<std::vector<Eigen::Vector3f>> pointsPerLabel(
    const pcl::PointCloud<pcl::PointNormal>& cloud, const cv::Mat& labels, std::size_t count) {
  std::vector<std::vector<Eigen::Vector3f>> points(count);
  if (labels.empty() || labels.cols != static_cast<int>(cloud.width) ||
      labels.rows != static_cast<int>(cloud.height))
    return points;
  for (int v = 0; v < labels.rows; ++v) {
    for (int u = 0; u < labels.cols; ++u) {
      const unsigned label = labels.at<std::uint16_t>(v, u);
      if (label >= 1 && label <= count)
        points[label - 1].push_back(cloud(u, v).getVector3fMap());
    }
  }
  return points;
}

}  // namespace

void SlamParams::validate() const {
  back_projection.validate();
  normals.validate();
  segmentation.validate();
  odometry.validate();
  mapping.validate();
  reconstruction.validate();
}

SlamParams loadSlamParams(const std::string& config_dir, ParamLog* log) {
  SlamParams params;
  ParamLog discarded;
  ParamLog& effective = log ? *log : discarded;
  auto reader = [&](const std::string& name) {
    const std::string path = config_dir + "/" + name;
    return std::filesystem::exists(path) ? YamlParamReader::fromFile(path)
                                         : YamlParamReader(YAML::Node(YAML::NodeType::Map));
  };
  readNormalEstimationParams(reader("normal_estimation.yaml"), params.back_projection,
                             params.normals, effective);
  readSegmentationParams(reader("segmentation.yaml"), params.segmentation, effective);
  readOdometryParams(reader("odometry.yaml"), params.odometry, effective);
  readMappingParams(reader("mapping.yaml"), params.mapping, params.reconstruction, effective);
  params.validate();
  return params;
}

QuadricSlam::QuadricSlam(const SlamParams& params)
    : params_((params.validate(), params)),
      normals_(params.normals),
      segmenter_(params.segmentation),
      odometry_(params.odometry),
      mapper_(params.mapping),
      reconstruction_(params.reconstruction) {}

void QuadricSlam::reset() {
  odometry_.reset();
  mapper_.reset();
  reconstruction_.clear();
  has_stamp_ = false;
}

SlamFrameResult QuadricSlam::process(const RgbdFrame& frame) {
  SlamFrameResult out;
  out.stamp = frame.stamp;
  if (!std::isfinite(frame.stamp)) {
    out.message = "stamp is not finite";
    return out;
  }
  if (has_stamp_ && frame.stamp <= last_stamp_) {
    reset();
    out.reset = true;
  }
  const CameraIntrinsics& k = frame.intrinsics;
  const std::string size_problem = imageSizeProblem(k, frame.depth_m.cols, frame.depth_m.rows);
  if (!size_problem.empty()) {
    out.message = size_problem;
    return out;
  }
  if (frame.depth_m.type() != CV_32FC1) {
    out.message = "depth image must be CV_32FC1 metres";
    return out;
  }
  has_stamp_ = true;
  last_stamp_ = frame.stamp;
  out.processed = true;

  timer_.time("normals", [&] {
    normals_.compute(backProject(depthViewOf(frame.depth_m), k, params_.back_projection), cloud_);
  });
  segmentation_ = Segmentation();
  if (params_.mapping_enabled) {
    segmentation_ = timer_.time("segmentation", [&] { return segmenter_.segment(cloud_); });
    out.measurements = toFrameMeasurements(segmentation_, frame.stamp, frame.frame_id);
  }
  out.odometry = timer_.time("odometry", [&] { return odometry_.track(cloud_, k, frame.stamp); });
  out.tracking = odometry_.initialized();
  if (!params_.mapping_enabled || !out.tracking)
    return out;

  OdometryInput odometry_input;
  odometry_input.T_odom_camera = out.odometry.T_odom_camera;
  out.mapping =
      timer_.time("mapping", [&] { return mapper_.process(out.measurements, odometry_input); });
  out.mapped = out.mapping.status == FrameStatus::kOk;
  if (!out.mapped) {
    out.message = "mapper refused the frame: " + out.mapping.message;
    return out;
  }
  if (out.mapping.keyframe)
    timer_.time("reconstruction", [&] { addToReconstruction(out.measurements, out.mapping); });
  return out;
}

// The supporting points of the keyframe's landmark observations, on their landmarks' surfaces.
void QuadricSlam::addToReconstruction(const FrameMeasurements& measurements,
                                      const MapperFrameResult& mapped) {
  const auto points =
      pointsPerLabel(cloud_, segmentation_.labels, segmentation_.detections.size());
  // update.measurements lists the accepted measurements in input order, the rejected left out.
  std::size_t input = 0;
  for (const MeasurementResult& fate : mapped.update.measurements) {
    while (input < measurements.observations.size() &&
           !QuadricMapper::validateMeasurement(measurements.observations[input]).empty())
      ++input;
    if (input >= measurements.observations.size())
      break;
    const int label = measurements.observations[input++].label;
    if ((fate.fate != MeasurementFate::kLandmark && fate.fate != MeasurementFate::kPromoted) ||
        label < 1 || label > static_cast<int>(points.size()))
      continue;
    const auto landmark = mapper_.map().landmarks().find(fate.id);
    if (landmark != mapper_.map().landmarks().end())
      reconstruction_.addPoints(fate.id, landmark->second.quadric_map, mapped.T_map_camera,
                                points[label - 1]);
  }
}

pcl::PointCloud<pcl::PointXYZL> QuadricSlam::reconstructionCloud() const {
  std::map<int, QuadricModel> surfaces;
  for (const auto& [id, landmark] : mapper_.map().landmarks())
    surfaces[id] = landmark.quadric_map;
  return reconstruction_.cloud(surfaces);
}

}  // namespace quadric_slam
