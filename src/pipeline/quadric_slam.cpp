#include "quadric_slam/pipeline/quadric_slam.h"

#include <filesystem>
#include <stdexcept>
#include <vector>

#include "quadric_slam/frontend/detection_measurement.h"
#include "quadric_slam/frontend/support_colours.h"
#include "quadric_slam/pipeline/pipeline_params.h"
#include "quadric_slam/pipeline/segmenter_params.h"

namespace quadric_slam {

void SlamParams::validate() const {
  back_projection.validate();
  normals.validate();
  segmentation.validate();
  odometry.validate();
  mapping.validate();
  reconstruction.validate();
  recovery.validate();
  batch.validate();
  if (max_support_points < 0)
    throw std::invalid_argument("max_support_points must be >= 0, got " +
                                std::to_string(max_support_points));
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
  const YamlParamReader segmentation = reader("segmentation.yaml");
  readSegmentationParams(segmentation, params.segmentation, effective);
  readParam(segmentation, "max_support_points", params.max_support_points, effective);
  readOdometryParams(reader("odometry.yaml"), params.odometry, effective);
  const YamlParamReader mapping = reader("mapping.yaml");
  readMappingParams(mapping, params.mapping, params.reconstruction, effective);
  readTrackingRecoveryParams(mapping, params.recovery, effective);
  readBatchRefinementParams(mapping, params.batch_refinement, params.batch, effective);
  params.validate();
  return params;
}

QuadricSlam::QuadricSlam(const SlamParams& params)
    : params_((params.validate(), params)),
      normals_(params.normals),
      segmenter_(params.segmentation),
      odometry_(params.odometry),
      mapper_(params.mapping),
      reconstruction_(params.reconstruction),
      recovery_(params.recovery) {}

void QuadricSlam::reset() {
  odometry_.reset();
  mapper_.reset();
  reconstruction_.clear();
  recovery_.reset();
  batch_recorder_.clear();
  batch_overflow_ = false;
  mapper_.setLocalizationOnly(false);
  T_map_odom_.setIdentity();
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
    attachSupportPoints(out.measurements, segmentation_, cloud_, params_.max_support_points);
    if (!frame.rgb.empty()) {
      try {
        colourSupportPoints(out.measurements, frame.rgb, k);
      } catch (const std::invalid_argument& e) {
        out.message = std::string("no colours: ") + e.what();  // the points stay uncoloured
      }
    }
  }
  // The segmentation's surfaces give the odometry a motion guess for large steps.
  out.odometry = timer_.time("odometry", [&] {
    return odometry_.track(cloud_, k, frame.stamp,
                           params_.mapping_enabled ? &out.measurements.observations : nullptr);
  });
  out.tracking = odometry_.initialized();
  if (!params_.mapping_enabled || !out.tracking)
    return out;

  if (out.odometry.status == TrackingStatus::kLost) {
    // The pose is the last one before the loss, not this frame's: nothing of it reaches the map.
    recovery_.trackingLost(static_cast<int>(mapper_.map().landmarks().size()));
    out.recovering = recovery_.recovering();
    out.message = "tracking lost: the mapper adds nothing from this frame";
    return out;
  }
  if (mapper_.localizationOnly() != recovery_.recovering())
    mapper_.setLocalizationOnly(recovery_.recovering());
  out.recovering = recovery_.recovering();
  if (recovery_.recovering() && !recovery_.poseVerified())
    out.relocalisation = timer_.time("relocalisation", [&] {
      return relocaliseWhileRecovering(&recovery_, &mapper_, out.measurements.observations,
                                       out.odometry.T_odom_camera, T_map_odom_);
    });

  OdometryInput odometry_input;
  odometry_input.T_odom_camera = out.odometry.T_odom_camera;
  out.mapping =
      timer_.time("mapping", [&] { return mapper_.process(out.measurements, odometry_input); });
  out.mapped = out.mapping.status == FrameStatus::kOk;
  if (params_.batch_refinement && !batch_overflow_) {
    batch_recorder_.record(out.mapping, mapper_);
    // Too large to solve: the recording stops and its memory is freed (refineBatch() says why).
    batch_overflow_ =
        static_cast<int>(batch_recorder_.keyframes().size()) > params_.batch.max_keyframes;
    if (batch_overflow_)
      batch_recorder_.clear();
  }
  if (out.mapped) {
    recovery_.frameMapped(landmarkAssociations(out.mapping.update));
    T_map_odom_ = out.mapping.T_map_odom;
  }
  if (!out.mapped) {
    out.message = "mapper refused the frame: " + out.mapping.message;
    return out;
  }
  if (out.mapping.keyframe)
    timer_.time("reconstruction", [&] { addToReconstruction(out.measurements, out.mapping); });
  return out;
}

// The points of landmarks merged after the keyframe's solve go to their survivors; then the
// supporting points of the keyframe's landmark observations, on their landmarks' surfaces.
void QuadricSlam::addToReconstruction(const FrameMeasurements& measurements,
                                      const MapperFrameResult& mapped) {
  applyMergesToReconstruction(mapped.merges, &reconstruction_);
  addKeyframeToReconstruction(measurements, mapped, mapper_.map(), &reconstruction_);
}

std::vector<LandmarkMerge> QuadricSlam::mergeDuplicateLandmarks() {
  const std::vector<LandmarkMerge> merges = mapper_.mergeDuplicates();
  applyMergesToReconstruction(merges, &reconstruction_);
  if (params_.batch_refinement && !batch_overflow_)
    batch_recorder_.recordMerges(merges);
  return merges;
}

BatchSolution QuadricSlam::refineBatch() const {
  if (!params_.batch_refinement)
    throw std::logic_error("QuadricSlam::refineBatch: batch_refinement is off (nothing recorded)");
  if (batch_overflow_) {
    BatchSolution solution;
    solution.statistics.report = "the run has more than batch_max_keyframes " +
                                 std::to_string(params_.batch.max_keyframes) +
                                 " keyframes: not recorded, not solved";
    return solution;
  }
  return BatchRefiner(params_.batch).refine(batch_recorder_, mapper_);
}

pcl::PointCloud<pcl::PointXYZRGBL> QuadricSlam::reconstructionCloud() const {
  std::map<int, QuadricModel> surfaces;
  for (const auto& [id, landmark] : mapper_.map().landmarks())
    surfaces[id] = landmark.quadric_map;
  return reconstruction_.cloud(surfaces);
}

}  // namespace quadric_slam
