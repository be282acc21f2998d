#include "quadric_slam/pipeline/quadric_slam.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <utility>
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

std::string profileDirectory(const std::string& config_dir, const std::string& profile) {
  if (profile.empty() || profile.find('/') != std::string::npos)
    return profile;
  return config_dir + "/profiles/" + profile;
}

SlamParams loadSlamParams(const std::string& config_dir, ParamLog* log,
                          const std::string& profile_dir) {
  if (!profile_dir.empty() && !std::filesystem::is_directory(profile_dir))
    throw std::runtime_error("configuration profile " + profile_dir + " is not a directory");
  SlamParams params;
  ParamLog discarded;
  ParamLog& effective = log ? *log : discarded;
  auto fileReader = [](const std::string& path) {
    return std::filesystem::exists(path) ? YamlParamReader::fromFile(path)
                                         : YamlParamReader(YAML::Node(YAML::NodeType::Map));
  };
  auto reader = [&](const std::string& name) {
    const YamlParamReader base = fileReader(config_dir + "/" + name);
    return profile_dir.empty() ? base : base.withOverrides(fileReader(profile_dir + "/" + name));
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
  readOdometryIncrementParams(mapping, params.odometry_increment_covariance, effective);
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

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// fn() timed under `stage` in the timer and into *ms; returns what fn() returns.
template <typename Fn>
auto timeStage(StageTimer& timer, const std::string& stage, double* ms, Fn&& fn) {
  const auto start = Clock::now();
  auto result = fn();
  *ms = msSince(start);
  timer.add(stage, *ms);
  return result;
}

}  // namespace

SlamFrameResult QuadricSlam::process(const RgbdFrame& frame) {
  FrontEndFrame front;
  std::swap(front.cloud, spare_cloud_);  // the storage of the frame before last
  frontEnd(frame, &front);
  SlamFrameResult out = backEnd(&front);
  std::swap(front.cloud, spare_cloud_);
  return out;
}

void QuadricSlam::frontEnd(const RgbdFrame& frame, FrontEndFrame* out) const {
  out->stamp = frame.stamp;
  out->frame_id = frame.frame_id;
  out->intrinsics = frame.intrinsics;
  out->problem.clear();
  out->colour_problem.clear();
  out->rgb = frame.rgb;
  out->segmentation = Segmentation();
  out->measurements = FrameMeasurements();
  out->normals_ms = out->segmentation_ms = 0.0;
  const CameraIntrinsics& k = frame.intrinsics;
  if (!std::isfinite(frame.stamp)) {
    out->problem = "stamp is not finite";
    return;
  }
  out->problem = imageSizeProblem(k, frame.depth_m.cols, frame.depth_m.rows);
  if (!out->problem.empty())
    return;
  if (frame.depth_m.type() != CV_32FC1) {
    out->problem = "depth image must be CV_32FC1 metres";
    return;
  }
  if (!params_.depth_correction.empty() && (params_.depth_correction.width() != k.width ||
                                            params_.depth_correction.height() != k.height)) {
    out->problem =
        "the depth correction spans " + std::to_string(params_.depth_correction.width()) + " x " +
        std::to_string(params_.depth_correction.height()) + " pixels, not the depth image's " +
        std::to_string(k.width) + " x " + std::to_string(k.height);
    return;
  }
  auto start = Clock::now();
  pcl::PointCloud<pcl::PointXYZ> points =
      backProject(depthViewOf(frame.depth_m), k, params_.back_projection);
  params_.depth_correction.apply(&points, params_.back_projection.decimation);
  normals_.compute(points, out->cloud);
  out->normals_ms = msSince(start);
  if (!params_.mapping_enabled)
    return;
  start = Clock::now();
  out->segmentation = segmenter_.segment(out->cloud);
  out->segmentation_ms = msSince(start);
  out->measurements = toFrameMeasurements(out->segmentation, frame.stamp, frame.frame_id);
  attachSupportPoints(out->measurements, out->segmentation, out->cloud, params_.max_support_points);
  if (!frame.rgb.empty()) {
    try {
      colourSupportPoints(out->measurements, frame.rgb, k);
    } catch (const std::invalid_argument& e) {
      out->colour_problem = std::string("no colours: ") + e.what();  // the points stay uncoloured
    }
  }
}

SlamFrameResult QuadricSlam::backEnd(FrontEndFrame* front) {
  SlamFrameResult out;
  out.stamp = front->stamp;
  if (!std::isfinite(front->stamp)) {
    out.message = front->problem;
    return out;
  }
  // 1. The time rule, in frame order, before the frame is used (a skipped frame keeps the order
  // as it was, as before the front end was split off).
  if (has_stamp_ && front->stamp <= last_stamp_) {
    reset();
    out.reset = true;
  }
  if (!front->problem.empty()) {
    out.message = front->problem;
    return out;
  }
  has_stamp_ = true;
  last_stamp_ = front->stamp;
  out.processed = true;
  out.message = front->colour_problem;
  timer_.add("normals", front->normals_ms);
  std::swap(cloud_, front->cloud);
  segmentation_ = std::move(front->segmentation);
  front->segmentation = Segmentation();
  if (params_.mapping_enabled)
    timer_.add("segmentation", front->segmentation_ms);
  out.measurements = std::move(front->measurements);
  const CameraIntrinsics& k = front->intrinsics;

  // The segmentation's surfaces give the odometry its normals and a motion guess for large steps.
  const bool tracker_was_initialized = odometry_.initialized();
  out.odometry = timeStage(timer_, "odometry", &out.odometry_ms, [&] {
    if (params_.mapping_enabled)
      odometry_.adoptSurfaceNormals(out.measurements.observations, cloud_);
    return odometry_.track(cloud_, k, front->stamp,
                           params_.mapping_enabled ? &out.measurements.observations : nullptr,
                           front->rgb.empty() ? nullptr : &front->rgb);
  });
  out.tracking = odometry_.initialized();
  if (!params_.mapping_enabled || !out.tracking)
    return out;
  // The tracker's increments reach the mapper composed since the last frame it took (refused
  // frames in between; a lost frame breaks the chain, see below): with T_m_c = T_m_p T_pc and
  // right perturbations, Cov_mc = Ad(T_pc^-1) Cov_mp Ad(T_pc^-1)^T + Cov_pc (as the mapper
  // composes its own).
  if (!tracker_was_initialized) {
    increment_covariance_since_mapped_.setZero();  // a new odom frame: nothing before counts
    increment_since_mapped_valid_ = false;
  } else {
    const Matrix6d ad = adjointSE3(out.odometry.increment.inverse());
    increment_covariance_since_mapped_ = ad * increment_covariance_since_mapped_ * ad.transpose() +
                                         out.odometry.increment_covariance;
  }

  if (out.odometry.status == TrackingStatus::kLost) {
    // The pose is the last one before the loss, not this frame's: nothing of it reaches the map.
    // Nor does its increment: across a loss the tracker knows nothing of the motion, and a factor
    // that weak let the window follow the associations a wrong pose makes while the mapper
    // re-anchors (generated fr1_desk at every 20th frame: SLAM ATE 30 m against 18 cm). The frame
    // after the loss gets the mapper's own odometry model, as after a restart, and the recovery
    // (localising only, relocalisation) re-anchors it.
    increment_since_mapped_valid_ = false;
    const MapUpdate promotion = takeTrackingLoss(&recovery_, &mapper_);
    if (params_.batch_refinement && !batch_overflow_)
      batch_recorder_.recordPromotions(promotion);
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
  if (params_.odometry_increment_covariance && increment_since_mapped_valid_)
    odometry_input.increment_covariance = increment_covariance_since_mapped_;
  out.mapping = timeStage(timer_, "mapping", &out.mapping_ms,
                          [&] { return mapper_.process(out.measurements, odometry_input); });
  out.mapped = out.mapping.status == FrameStatus::kOk;
  if (out.mapped) {
    increment_covariance_since_mapped_.setZero();
    increment_since_mapped_valid_ = true;
  }
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
