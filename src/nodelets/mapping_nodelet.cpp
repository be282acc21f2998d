// mapping: quadric observations + odometry -> the quadric map (the paper's back-end), with the core
// QuadricMapper and QuadricReconstruction, computing per frame what QuadricSlam computes offline.
//
// Subscribes  observations (quadric_slam/QuadricObservationArray, camera optical frame; from
//             quadric_slam/QuadricSegmentation) and odom (nav_msgs/Odometry, pose of the camera in
//             ~odom_frame; from quadric_slam/Odometry; its twist covariance times dt^2 is the
//             covariance of the step from the previous odom message, which the mapper's odometry
//             factors carry with ~odometry_increment_covariance), paired by exact stamp
//             (message_filters).
//             The observations are taken to be in odom's child frame (the tracked camera); a
//             frame id that differs gets a throttled warning (normal_estimation's ~output_frame
//             names the clouds' frame, odometry's ~camera_frame the tracked one: set them equal).
//             With ~use_rgb: rgb/image (sensor_msgs/Image rgb8, bgr8 or mono8, through
//             image_transport) and its rgb/camera_info, a colour camera registered to the depth
//             camera (the same optical centre; TUM bags, depth_registered drivers). Each
//             observation array takes the image of the nearest stamp within
//             ~rgb_max_stamp_difference (ros/colour_image_buffer.h); its supporting points (the
//             decimated subset the observations carry) take the colours of their pixels
//             (frontend/support_colours.h), which the reconstruction keeps. A frame without a
//             matching image is mapped uncoloured, never dropped.
// Publishes   map (quadric_slam/QuadricMap in ~map_frame, latched: on keyframes, after a load or
//             a reset; ids of landmarks merged into others in merged_ids / merged_into)
//             markers (visualization_msgs/MarkerArray, latched, with the map)
//             reconstruction (sensor_msgs/PointCloud2 x y z rgb label in ~map_frame, latched: every
//             ~reconstruction_every_keyframes keyframes, on ~save_map and after ~load_map; rgb =
//             the pixel's colour with ~use_rgb, else the landmark's colour)
//             path (nav_msgs/Path of T_map_camera per frame in ~map_frame, at most ~max_path_poses)
//             tf ~map_frame -> ~odom_frame (T_map_odom, REP-105; when ~publish_tf)
//             /diagnostics (landmarks per class, window, solve time, associations, frames
//             processed and dropped, processing time median / p95 of the latest frames, every
//             ~diagnostic_period)
// Services    ~save_map (quadric_slam/SaveMap): map YAML + reconstruction PCD beside it (landmarks
//             that are one surface are merged first)
//             ~load_map (quadric_slam/LoadMap): start from a saved map, optionally localisation
//             only
// All parameters are documented in config/mapping.yaml.
//
// Bad input has a defined behaviour: time going backwards (a looping bag) resets the map (to the
// loaded map, if one was loaded) with a warning; a frame with a non-finite or non-unit pose, a
// non-finite or negative covariance, an odom frame other than ~odom_frame or a repeated stamp is
// dropped; an observation that does not convert (bad class, pose, scale, covariance size) or that
// the mapper refuses is dropped, the rest of the frame is used. Each gets a throttled error naming
// the problem and is counted on /diagnostics. A frame whose odometry says tracking is lost
// (ros/odometry_status.h) adds nothing to the map; after it the mapper localises only until the
// surfaces anchor the pose in the map again (mapping/tracking_recovery.h; on /diagnostics). No
// callback lets an exception escape (it would take the whole manager down).
#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <image_transport/image_transport.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/transform_broadcaster.h>

#include <Eigen/Cholesky>
#include <chrono>
#include <cmath>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <pluginlib/class_list_macros.hpp>
#include <string>
#include <vector>

#include "quadric_slam/LoadMap.h"
#include "quadric_slam/QuadricObservationArray.h"
#include "quadric_slam/SaveMap.h"
#include "quadric_slam/eval/recent_durations.h"
#include "quadric_slam/eval/resource_usage.h"
#include "quadric_slam/frontend/support_colours.h"
#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/mapping/quadric_mapper.h"
#include "quadric_slam/mapping/reconstruction.h"
#include "quadric_slam/mapping/recovery_relocalisation.h"
#include "quadric_slam/mapping/tracking_recovery.h"
#include "quadric_slam/pipeline/pipeline_params.h"
#include "quadric_slam/ros/colour_image_buffer.h"
#include "quadric_slam/ros/conversions.h"
#include "quadric_slam/ros/depth_image.h"
#include "quadric_slam/ros/diagnostics.h"
#include "quadric_slam/ros/drop_reporter.h"
#include "quadric_slam/ros/frame_ids.h"
#include "quadric_slam/ros/map_files.h"
#include "quadric_slam/ros/map_publisher.h"
#include "quadric_slam/ros/odometry_status.h"
#include "quadric_slam/ros/params.h"
#include "quadric_slam/ros/reconstruction_cloud.h"

namespace quadric_slam {

namespace {

// Empty when the odometry message is usable, else the problem.
std::string odometryProblem(const nav_msgs::Odometry& odom, const std::string& odom_frame) {
  if (!sameFrame(odom.header.frame_id, odom_frame))
    return "odom is in frame '" + odom.header.frame_id + "', not ~odom_frame '" + odom_frame + "'";
  const auto& p = odom.pose.pose.position;
  const auto& q = odom.pose.pose.orientation;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
    return "odom position is not finite";
  if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z) || !std::isfinite(q.w))
    return "odom orientation is not finite";
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (std::abs(norm - 1.0) > 1e-3)
    return "odom orientation is not a unit quaternion (norm " + std::to_string(norm) +
           "): not a rotation";
  for (int i = 0; i < 36; ++i) {
    if (!std::isfinite(odom.pose.covariance[i]))
      return "odom pose covariance is not finite";
  }
  for (int i = 0; i < 6; ++i) {
    if (odom.pose.covariance[7 * i] < 0.0)
      return "odom pose covariance has a negative variance (entry " + std::to_string(7 * i) + ")";
  }
  return "";
}

// The odometry nodelet's increment from the previous odom message (dt s before) to this one,
// carried as a velocity held over dt: the step is (twist.linear dt, exp(twist.angular dt)) and its
// covariance ([rho; phi] in this frame's body tangent) the twist covariance times dt^2. False when
// the twist covariance is not estimated (the 1e6 diagonal of the first message after a start or
// reset), not finite or not positive definite, or dt <= 0.
bool incrementFromTwist(const nav_msgs::Odometry& odom, double dt, Eigen::Isometry3d* increment,
                        Matrix6d* covariance) {
  if (!(dt > 0.0))
    return false;
  Matrix6d twist_covariance;
  bool not_estimated = true;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c)
      twist_covariance(r, c) = odom.twist.covariance[6 * r + c];
    not_estimated = not_estimated && twist_covariance(r, r) >= 1e6;
  }
  if (not_estimated || !twist_covariance.allFinite())
    return false;
  *covariance = 0.5 * (twist_covariance + twist_covariance.transpose()) * (dt * dt);
  if (covariance->llt().info() != Eigen::Success)
    return false;
  const auto& v = odom.twist.twist.linear;
  const auto& w = odom.twist.twist.angular;
  const Eigen::Vector3d rotation = Eigen::Vector3d(w.x, w.y, w.z) * dt;
  increment->setIdentity();
  increment->linear() = expSO3(rotation);
  increment->translation() = Eigen::Vector3d(v.x, v.y, v.z) * dt;
  return true;
}

geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& T) {
  const geometry_msgs::Pose pose = toPoseMsg(T);
  geometry_msgs::Transform transform;
  transform.translation.x = pose.position.x;
  transform.translation.y = pose.position.y;
  transform.translation.z = pose.position.z;
  transform.rotation = pose.orientation;
  return transform;
}

}  // namespace

class MappingNodelet : public nodelet::Nodelet {
 public:
  ~MappingNodelet() override {
    // The synchroniser calls back into this object: disconnect it before the members go.
    sync_.reset();
    rgb_sub_.shutdown();
  }

 private:
  using SyncPolicy =
      message_filters::sync_policies::ExactTime<QuadricObservationArray, nav_msgs::Odometry>;

  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& private_nh = getPrivateNodeHandle();

    ParamLog log;
    QuadricMapper::Params mapper_params;
    QuadricReconstruction::Params reconstruction_params;
    TrackingRecovery::Params recovery_params;
    int queue_size = 10;
    double diagnostic_period = 1.0;
    bool localization_only = false;
    int rgb_buffer_size = 60;
    double rgb_max_stamp_difference = 0.02;
    try {
      const RosParamReader reader(private_nh);
      readFrameParam(reader, "map_frame", map_frame_, log);
      readFrameParam(reader, "odom_frame", odom_frame_, log);
      readParam(reader, "publish_tf", publish_tf_, log);
      readParam(reader, "queue_size", queue_size, log);
      readParam(reader, "reconstruction_every_keyframes", reconstruction_every_keyframes_, log);
      readParam(reader, "max_path_poses", max_path_poses_, log);
      readParam(reader, "map_file", map_file_, log);
      readParam(reader, "localization_only", localization_only, log);
      readParam(reader, "diagnostic_period", diagnostic_period, log);
      readParam(reader, "use_rgb", use_rgb_, log);
      readParam(reader, "rgb_buffer_size", rgb_buffer_size, log);
      readParam(reader, "rgb_max_stamp_difference", rgb_max_stamp_difference, log);
      rgb_max_stamp_difference_ = rgb_max_stamp_difference;
      if (rgb_buffer_size < 1)
        throw std::invalid_argument("rgb_buffer_size must be >= 1");
      colour_images_ = std::make_unique<ColourImageBuffer>(
          static_cast<std::size_t>(rgb_buffer_size), rgb_max_stamp_difference);
      readMappingParams(reader, mapper_params, reconstruction_params, log);
      readTrackingRecoveryParams(reader, recovery_params, log);
      readOdometryIncrementParams(reader, use_increment_covariance_, log);
      if (map_frame_.empty() || odom_frame_.empty() || map_frame_ == odom_frame_)
        throw std::invalid_argument("map_frame and odom_frame must be non-empty and differ");
      if (queue_size < 1)
        throw std::invalid_argument("queue_size must be >= 1");
      if (reconstruction_every_keyframes_ < 1)
        throw std::invalid_argument("reconstruction_every_keyframes must be >= 1");
      if (max_path_poses_ < 1)
        throw std::invalid_argument("max_path_poses must be >= 1");
      if (!(diagnostic_period > 0.0))
        throw std::invalid_argument("diagnostic_period must be > 0 s");
      mapper_ = std::make_unique<QuadricMapper>(mapper_params);
      reconstruction_ = std::make_unique<QuadricReconstruction>(reconstruction_params);
      mapper_->setLocalizationOnly(localization_only);
      user_localization_only_ = localization_only;
      recovery_ = TrackingRecovery(recovery_params);
    } catch (const std::invalid_argument& e) {
      NODELET_FATAL("mapping: invalid parameter: %s", e.what());
      throw;
    }
    NODELET_INFO("mapping parameters:%s", log.str().c_str());

    // A map to start from: loaded when the file exists; otherwise ~save_map will write it.
    if (!map_file_.empty()) {
      std::string message;
      if (std::filesystem::exists(map_file_)) {
        if (!loadMap(map_file_, localization_only, &message)) {
          NODELET_FATAL("mapping: cannot load ~map_file: %s", message.c_str());
          throw std::runtime_error(message);
        }
        NODELET_INFO("mapping: %s", message.c_str());
      } else if (localization_only) {
        NODELET_FATAL("mapping: ~localization_only needs a map, but ~map_file %s does not exist",
                      map_file_.c_str());
        throw std::runtime_error("~map_file " + map_file_ + " does not exist");
      } else {
        NODELET_WARN(
            "mapping: ~map_file %s does not exist yet: starting with an empty map "
            "(~save_map will write it)",
            map_file_.c_str());
      }
    } else if (localization_only) {
      NODELET_WARN(
          "mapping: ~localization_only without ~map_file: localising against an empty "
          "map until ~load_map is called");
    }

    tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
    map_publisher_ = QuadricMapPublisher(nh, "map", "markers");
    reconstruction_pub_ = nh.advertise<sensor_msgs::PointCloud2>("reconstruction", 1, true);
    path_pub_ = nh.advertise<nav_msgs::Path>("path", queue_size);
    save_service_ = private_nh.advertiseService("save_map", &MappingNodelet::onSaveMap, this);
    load_service_ = private_nh.advertiseService("load_map", &MappingNodelet::onLoadMap, this);

    diagnostics_ = std::make_unique<diagnostic_updater::Updater>(nh, private_nh, getName());
    diagnostics_->setHardwareID("quadric_slam");
    diagnostics_->add("mapping", this, &MappingNodelet::diagnose);
    diagnostics_timer_ = nh.createWallTimer(ros::WallDuration(diagnostic_period),
                                            &MappingNodelet::onDiagnosticsTimer, this);

    // Latched outputs from the start (the empty or loaded map).
    publishMap(ros::Time::now());
    publishReconstruction(ros::Time::now());

    observations_sub_.subscribe(nh, "observations", queue_size);
    odom_sub_.subscribe(nh, "odom", queue_size);
    observations_sub_.registerCallback(&MappingNodelet::onObservationsArrived, this);
    odom_sub_.registerCallback(&MappingNodelet::onOdomArrived, this);
    sync_ = std::make_unique<message_filters::Synchronizer<SyncPolicy>>(
        SyncPolicy(static_cast<std::uint32_t>(queue_size)), observations_sub_, odom_sub_);
    sync_->registerCallback(&MappingNodelet::onFrame, this);
    if (use_rgb_) {
      // rgb/image and rgb/camera_info, paired by image_transport (any transport it has a plugin
      // for, e.g. compressed: ~image_transport).
      image_transport_ = std::make_unique<image_transport::ImageTransport>(nh);
      rgb_sub_ = image_transport_->subscribeCamera(
          "rgb/image", static_cast<std::uint32_t>(rgb_buffer_size), &MappingNodelet::onRgb, this,
          image_transport::TransportHints("raw", ros::TransportHints(), private_nh));
    }
  }

  // A colour image and its camera_info into the buffer the observations look their colours up in.
  void onRgb(const sensor_msgs::ImageConstPtr& image, const sensor_msgs::CameraInfoConstPtr& info) {
    try {
      {
        std::lock_guard<std::mutex> lock(stats_mutex_);
        ++stats_.rgb_images;
      }
      ColourImageBuffer::Entry entry;
      const std::string problem = colourEntryFromMessages(image, info, &entry);
      if (!problem.empty()) {
        rgb_drops_.report(problem);
        std::lock_guard<std::mutex> lock(stats_mutex_);
        ++stats_.rgb_images_refused;
        stats_.last_rgb_problem = problem;
        return;
      }
      colour_images_->add(std::move(entry));
    } catch (const std::exception& e) {
      rgb_drops_.report(std::string("unexpected error: ") + e.what());
    }
  }

  // The supporting points' colours from the colour image of the frame's stamp, if there is one.
  void colourFrame(FrameMeasurements& frame, const ros::Time& stamp) {
    ColourImageBuffer::Entry image;
    bool coloured = colour_images_->nearest(stamp.toSec(), &image);
    if (!coloured) {
      double oldest = 0.0, newest = 0.0;
      rgb_drops_.report(colour_images_->span(&oldest, &newest)
                            ? (stamp.toSec() < oldest
                                   ? "the observations are older than every buffered colour "
                                     "image (raise ~rgb_buffer_size)"
                                   : "no colour image within ~rgb_max_stamp_difference of "
                                     "the observations")
                            : "no colour image received on rgb/image yet");
    }
    colour_images_->dropBefore(stamp.toSec() - rgb_max_stamp_difference_);
    if (coloured) {
      try {
        colourSupportPoints(frame, image.rgb->image, image.intrinsics);
      } catch (const std::invalid_argument& e) {
        rgb_drops_.report(e.what());
        coloured = false;
      }
    }
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++(coloured ? stats_.frames_coloured : stats_.frames_without_rgb);
  }

  // --- Input ------------------------------------------------------------------------------------

  // Arrivals are counted (against synchronised pairs) to show unmatched inputs on /diagnostics.
  void onObservationsArrived(const QuadricObservationArrayConstPtr&) { countArrival(true); }
  void onOdomArrived(const nav_msgs::OdometryConstPtr&) { countArrival(false); }
  void countArrival(bool observations) {
    try {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++(observations ? stats_.observation_messages : stats_.odom_messages);
    } catch (const std::exception& e) {
      NODELET_ERROR_THROTTLE(30.0, "mapping: %s", e.what());
    }
  }

  void onFrame(const QuadricObservationArrayConstPtr& observations,
               const nav_msgs::OdometryConstPtr& odom) {
    // roscpp does not catch what a callback throws: the manager, and every nodelet in it, would
    // die. Whatever goes wrong drops this frame with a reason instead.
    try {
      std::lock_guard<std::mutex> lock(mutex_);
      processFrame(*observations, *odom);
    } catch (const std::exception& e) {
      dropFrame(std::string("unexpected error: ") + e.what());
    } catch (...) {
      dropFrame("unexpected error of an unknown type");
    }
  }

  void dropFrame(const std::string& reason) {
    frame_drops_.report(reason);
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.frames_dropped;
    stats_.last_drop_reason = reason;
  }

  void processFrame(const QuadricObservationArray& observations, const nav_msgs::Odometry& odom) {
    const auto start = std::chrono::steady_clock::now();
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++stats_.synchronised;
    }
    const ros::Time stamp = observations.header.stamp;
    // 1. Time rule.
    if (have_stamp_ && stamp < last_stamp_) {
      NODELET_WARN(
          "mapping: time went backwards (%.3f s after %.3f s; a looping bag?): resetting "
          "the map%s",
          stamp.toSec(), last_stamp_.toSec(), base_map_ ? " to the loaded map" : "");
      reset();
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++stats_.resets;
    } else if (have_stamp_ && stamp == last_stamp_) {
      dropFrame("repeated stamp " + std::to_string(stamp.toSec()) + " s");
      return;
    }

    // 2. Odometry.
    const std::string problem = odometryProblem(odom, odom_frame_);
    if (!problem.empty()) {
      dropFrame(problem);
      return;
    }
    checkObservationFrame(observations.header.frame_id, odom.child_frame_id);
    composeIncrement(odom);
    if (isLost(odom)) {
      // The odometry lost track: its pose is the last one before the loss, not this frame's.
      // Nothing of the frame reaches the map; afterwards the mapper localises until the surfaces
      // anchor the pose again (mapping/tracking_recovery.h).
      takeTrackingLoss(&recovery_, mapper_.get());
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++stats_.frames_lost;
      return;
    }
    const bool localise_only = user_localization_only_ || recovery_.recovering();
    if (mapper_->localizationOnly() != localise_only)
      mapper_->setLocalizationOnly(localise_only);
    OdometryInput odometry;
    odometry.T_odom_camera = fromPoseMsg(odom.pose.pose);
    // The odometry's pose covariance is cumulative since its start; the increments since the last
    // frame the mapper took come from the twist covariance (composeIncrement), as QuadricSlam
    // passes the tracker's (mapping.yaml odometry_increment_covariance; else, and until a frame
    // was mapped since the odometry started, the mapper's own odometry_* model).
    if (use_increment_covariance_ && increment_since_mapped_valid_)
      odometry.increment_covariance = increment_covariance_since_mapped_;

    // 3. Observations: those that do not convert are dropped, the rest of the frame is used.
    FrameMeasurements frame;
    frame.stamp = stamp.toSec();
    frame.frame_id = withoutLeadingSlash(observations.header.frame_id);
    frame.observations.reserve(observations.observations.size());
    int bad = 0;
    std::string why;
    for (const QuadricObservation& observation : observations.observations) {
      try {
        frame.observations.push_back(fromObservationMsg(observation));
      } catch (const std::invalid_argument& e) {
        ++bad;
        why = e.what();
      }
    }
    if (bad > 0)
      observation_drops_.report(why);

    if (use_rgb_)
      colourFrame(frame, stamp);

    // 4. While the map waits to be anchored after a loss, a frame that does not anchor is first
    // relocalised against the landmarks; where found, the odometry is re-anchored in the map
    // (mapping/recovery_relocalisation.h).
    if (recovery_.recovering() && !user_localization_only_) {
      const RecoveryRelocalisation relocalisation = relocaliseWhileRecovering(
          &recovery_, mapper_.get(), frame.observations, odometry.T_odom_camera, T_map_odom_);
      if (relocalisation.attempted) {
        if (relocalisation.reanchored)
          NODELET_INFO("mapping: relocalised in the map with %d of %d surfaces (%.1f ms)",
                       relocalisation.result.supporting_surfaces,
                       relocalisation.result.usable_observations, 1e3 * relocalisation.seconds);
        std::lock_guard<std::mutex> lock(stats_mutex_);
        stats_.last_relocalisation =
            relocalisation.result.found
                ? (relocalisation.reanchored ? "re-anchored" : "found at the odometry's pose")
                : relocalisation.result.message;
        stats_.relocalisation_ms.add(1e3 * relocalisation.seconds);
      }
    }

    // 5. The mapper.
    const MapperFrameResult result = mapper_->process(frame, odometry);
    if (result.status == FrameStatus::kOk) {
      increment_covariance_since_mapped_.setZero();
      increment_since_mapped_valid_ = true;
    }
    if (result.status != FrameStatus::kOk) {
      dropFrame("mapper refused the frame: " + result.message);
      return;
    }
    have_stamp_ = true;
    last_stamp_ = stamp;
    T_map_odom_ = result.T_map_odom;
    recovery_.frameMapped(landmarkAssociations(result.update));
    if (result.rejected_measurements > 0)
      observation_drops_.report("the mapper refused: " + result.message);

    // 6. The reconstruction grows on keyframes (after the points of merged landmarks moved).
    if (result.keyframe) {
      applyMergesToReconstruction(result.merges, reconstruction_.get());
      addKeyframeToReconstruction(frame, result, mapper_->map(), reconstruction_.get());
      ++keyframes_;
    }

    // 6. Outputs.
    appendPath(stamp, result.T_map_camera);
    if (publish_tf_) {
      geometry_msgs::TransformStamped tf;
      tf.header.stamp = stamp;
      tf.header.frame_id = map_frame_;
      tf.child_frame_id = odom_frame_;
      tf.transform = toTransformMsg(result.T_map_odom);
      tf_broadcaster_->sendTransform(tf);
    }
    if (result.keyframe) {
      publishMap(stamp);
      if (keyframes_ % reconstruction_every_keyframes_ == 0)
        publishReconstruction(stamp);
    }

    countLandmarks();
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.frames_processed;
    stats_.keyframes += result.keyframe;
    stats_.observations += static_cast<long>(observations.observations.size());
    stats_.observations_dropped += bad + result.rejected_measurements;
    if (bad + result.rejected_measurements > 0)
      stats_.last_observation_problem = bad > 0 ? why : result.message;
    stats_.last = FrameStats{};
    for (const MeasurementResult& m : result.update.measurements) {
      switch (m.fate) {
        case MeasurementFate::kLandmark:
        case MeasurementFate::kJoined:
          ++stats_.last.to_landmarks;
          break;
        case MeasurementFate::kCandidate:
          ++stats_.last.to_candidates;
          break;
        case MeasurementFate::kNewCandidate:
          ++stats_.last.new_candidates;
          break;
        case MeasurementFate::kPromoted:
          ++stats_.last.promoted;
          break;
      }
    }
    stats_.total_to_landmarks += stats_.last.to_landmarks;
    stats_.total_promoted += stats_.last.promoted;
    stats_.association_ms = 1e3 * result.association_seconds;
    if (result.keyframe) {
      stats_.window = result.window;
      stats_.solve_ms = 1e3 * result.optimisation_seconds;
    }
    stats_.processing_times.add(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
  }

  // The observations are used in the frame whose pose odom gives (its child frame). Another frame
  // id is most likely the same sensor under another name (normal_estimation's ~output_frame unset,
  // a bag's optical frame), so the frame is used, with a warning and both names on /diagnostics.
  void checkObservationFrame(const std::string& observation_frame,
                             const std::string& camera_frame) {
    const std::string observed = withoutLeadingSlash(observation_frame);
    const std::string camera = withoutLeadingSlash(camera_frame);
    if (observed != camera) {
      NODELET_WARN_THROTTLE(
          30.0,
          "mapping: observations are in frame '%s', but odom gives the pose of '%s'; they are "
          "used as if in '%s' (set normal_estimation's ~output_frame to odometry's "
          "~camera_frame)",
          observed.c_str(), camera.c_str(), camera.c_str());
    }
    std::lock_guard<std::mutex> lock(stats_mutex_);
    stats_.observation_frame = observed;
    stats_.camera_frame = camera;
  }

  // Forgets the map (back to the loaded one, if any), the reconstruction and the path.
  // Composes the odometry's increment into those since the last frame the mapper took (lost and
  // refused frames in between; right perturbations: Cov_mc = Ad(T_pc^-1) Cov_mp Ad^T + Cov_pc,
  // as QuadricSlam does offline). A message without an estimated increment (the odometry started
  // or reset) starts over: until the mapper takes a frame, its own noise model is used.
  void composeIncrement(const nav_msgs::Odometry& odom) {
    const double dt = have_odom_stamp_ ? (odom.header.stamp - last_odom_stamp_).toSec() : 0.0;
    have_odom_stamp_ = true;
    last_odom_stamp_ = odom.header.stamp;
    Eigen::Isometry3d increment;
    Matrix6d covariance;
    if (!incrementFromTwist(odom, dt, &increment, &covariance)) {
      increment_covariance_since_mapped_.setZero();
      increment_since_mapped_valid_ = false;
      return;
    }
    const Matrix6d ad = adjointSE3(increment.inverse());
    increment_covariance_since_mapped_ =
        ad * increment_covariance_since_mapped_ * ad.transpose() + covariance;
  }

  void reset() {
    have_odom_stamp_ = false;
    increment_covariance_since_mapped_.setZero();
    increment_since_mapped_valid_ = false;
    mapper_->reset();
    recovery_.reset();
    mapper_->setLocalizationOnly(user_localization_only_);
    reconstruction_->clear();
    path_.clear();
    keyframes_ = 0;
    have_stamp_ = false;
    T_map_odom_ = Eigen::Isometry3d::Identity();
    if (base_map_)
      seed(*base_map_, Eigen::Isometry3d::Identity());
    publishMap(ros::Time::now());
    publishReconstruction(ros::Time::now());
    countLandmarks();
  }

  // --- Saved maps
  // ---------------------------------------------------------------------------------

  struct BaseMap {
    LoadedMap map;
    bool fixed = false;
  };

  // The mapper and the reconstruction from a loaded map, the odometry placed with T_map_odom.
  void seed(const BaseMap& base, const Eigen::Isometry3d& T_map_odom) {
    mapper_->loadLandmarks(base.map.landmarks, base.fixed, T_map_odom);
    reconstruction_->clear();
    std::map<int, std::vector<Eigen::Vector3f>> points;
    std::map<int, std::vector<std::uint32_t>> colours;  // alpha 0: the landmark's colour
    for (const pcl::PointXYZRGBL& p : base.map.reconstruction) {
      points[static_cast<int>(p.label)].emplace_back(p.x, p.y, p.z);
      colours[static_cast<int>(p.label)].push_back(p.rgba);
    }
    for (const auto& [id, landmark_points] : points)
      reconstruction_->addPoints(id, mapper_->map().landmark(id).quadric_map,
                                 Eigen::Isometry3d::Identity(), landmark_points, colours[id]);
  }

  // Replaces the map with the saved one at `path`; false (mapper untouched) with *message saying
  // why, or true with *message saying what was loaded.
  bool loadMap(const std::string& path, bool localization_only, std::string* message) {
    auto base = std::make_unique<BaseMap>();
    try {
      base->map = loadMapFiles(path);
      base->fixed = localization_only;
      // The odometry keeps its place in the map (identity before the first frame or after a
      // reset).
      seed(*base, T_map_odom_);
    } catch (const std::exception& e) {
      *message = e.what();
      return false;
    }
    mapper_->setLocalizationOnly(localization_only);
    user_localization_only_ = localization_only;
    recovery_.reset();
    const std::size_t points = base->map.reconstruction.size();
    *message = "loaded " + std::to_string(base->map.landmarks.size()) + " quadrics from " + path +
               (base->map.reconstruction_path.empty()
                    ? std::string(" (no reconstruction beside it)")
                    : " and " + std::to_string(points) + " reconstruction points from " +
                          base->map.reconstruction_path) +
               (localization_only ? "; localisation only" : "; mapping on");
    if (!sameFrame(base->map.frame_id, map_frame_))
      *message += "; the file's frame '" + base->map.frame_id + "' is taken as ~map_frame '" +
                  map_frame_ + "'";
    base_map_ = std::move(base);
    loaded_from_ = path;
    path_.clear();
    keyframes_ = 0;
    countLandmarks();
    return true;
  }

  // The file a ~save_map or ~load_map request means: its path, else ~map_file. "" when neither is
  // set, with the response failed and saying so.
  template <typename Response>
  std::string mapPathFor(const std::string& requested_path, Response& response) const {
    const std::string path = requested_path.empty() ? map_file_ : requested_path;
    if (path.empty()) {
      response.success = false;
      response.message = "no path given and ~map_file is empty";
    }
    return path;
  }

  bool onSaveMap(SaveMap::Request& request, SaveMap::Response& response) {
    try {
      std::lock_guard<std::mutex> lock(mutex_);
      const std::string path = mapPathFor(request.path, response);
      if (path.empty())
        return true;
      // Each surface once in the saved map (QuadricMapper::mergeDuplicates).
      applyMergesToReconstruction(mapper_->mergeDuplicates(), reconstruction_.get());
      const std::vector<QuadricLandmark> landmarks = mapper_->landmarks();
      const sensor_msgs::PointCloud2Ptr cloud = reconstructionCloud(ros::Time::now());
      saveMapFiles(path, landmarks, map_frame_, *cloud, mapper_->map().mergedInto());
      // The latched outputs show what was saved (the map's counts move on between keyframes).
      publishMap(cloud->header.stamp);
      reconstruction_pub_.publish(cloud);
      response.success = true;
      response.num_quadrics = static_cast<std::uint32_t>(landmarks.size());
      response.message = "wrote " + std::to_string(landmarks.size()) + " quadrics to " + path;
      if (cloud->width > 0)
        response.message += " and " + std::to_string(cloud->width) + " reconstruction points to " +
                            reconstructionPathFor(path);
      NODELET_INFO("mapping: %s", response.message.c_str());
    } catch (const std::exception& e) {
      response.success = false;
      response.message = e.what();
      NODELET_ERROR("mapping: ~save_map failed: %s", e.what());
    }
    return true;
  }

  bool onLoadMap(LoadMap::Request& request, LoadMap::Response& response) {
    try {
      std::lock_guard<std::mutex> lock(mutex_);
      const std::string path = mapPathFor(request.path, response);
      if (path.empty())
        return true;
      response.success = loadMap(path, request.localization_only, &response.message);
      if (response.success) {
        response.num_quadrics = static_cast<std::uint32_t>(mapper_->map().landmarks().size());
        publishMap(ros::Time::now());
        publishReconstruction(ros::Time::now());
        NODELET_INFO("mapping: %s", response.message.c_str());
      } else {
        NODELET_ERROR("mapping: ~load_map failed, the map is unchanged: %s",
                      response.message.c_str());
      }
    } catch (const std::exception& e) {
      response.success = false;
      response.message = e.what();
      NODELET_ERROR("mapping: ~load_map failed: %s", e.what());
    }
    return true;
  }

  // --- Outputs ----------------------------------------------------------------------------------

  void publishMap(const ros::Time& stamp) {
    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = map_frame_;
    map_publisher_.publish(mapper_->landmarks(), header, mapper_->map().mergedInto());
  }

  sensor_msgs::PointCloud2Ptr reconstructionCloud(const ros::Time& stamp) const {
    std::map<int, QuadricModel> surfaces;
    for (const auto& [id, landmark] : mapper_->map().landmarks())
      surfaces[id] = landmark.quadric_map;
    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = map_frame_;
    return boost::make_shared<sensor_msgs::PointCloud2>(
        reconstructionCloudMsg(reconstruction_->cloud(surfaces), header));
  }

  void publishReconstruction(const ros::Time& stamp) {
    reconstruction_pub_.publish(reconstructionCloud(stamp));
    // The whole-map cloud and its message were the largest buffers of the frame and grow with the
    // map: give their pages back, or the manager's resident memory ratchets up by a cloud's size
    // every few publications (eval/resource_usage.h).
    releaseFreeHeapMemory();
  }

  void appendPath(const ros::Time& stamp, const Eigen::Isometry3d& T_map_camera) {
    geometry_msgs::PoseStamped pose;
    pose.header.stamp = stamp;
    pose.header.frame_id = map_frame_;
    pose.pose = toPoseMsg(T_map_camera);
    path_.push_back(pose);
    while (static_cast<int>(path_.size()) > max_path_poses_)
      path_.pop_front();
    if (path_pub_.getNumSubscribers() == 0)
      return;
    auto path = boost::make_shared<nav_msgs::Path>();
    path->header.stamp = stamp;
    path->header.frame_id = map_frame_;
    path->poses.assign(path_.begin(), path_.end());
    path_pub_.publish(path);
  }

  // --- Diagnostics
  // --------------------------------------------------------------------------------

  struct FrameStats {
    int to_landmarks = 0, to_candidates = 0, new_candidates = 0, promoted = 0;
  };
  struct Stats {
    long observation_messages = 0, odom_messages = 0, synchronised = 0;
    long frames_processed = 0, frames_dropped = 0, keyframes = 0, resets = 0;
    long frames_lost = 0;  // odometry lost track: nothing of the frame reached the map
    int losses = 0, recoveries = 0, recovery_timeouts = 0;
    bool recovering = false;
    int relocalisation_attempts = 0, relocalisations = 0;
    std::string last_relocalisation = "none";  // the latest attempt's outcome
    RecentDurations relocalisation_ms{100};    // of the latest attempts
    long observations = 0, observations_dropped = 0, total_to_landmarks = 0, total_promoted = 0;
    std::string last_drop_reason, last_observation_problem;
    FrameStats last;
    WindowStatistics window;
    double solve_ms = 0.0, association_ms = 0.0;
    RecentDurations processing_times{300};  // of processed frames, the latest 300
    std::map<std::string, int> landmarks_per_class;
    int landmarks = 0, candidates = 0;
    long reconstruction_points = 0;  // what a long run grows until the surfaces are covered
    bool reconstruction_full = false;
    std::string observation_frame, camera_frame;  // of the latest frame (observations, odom child)
    std::string mode = "mapping";                 // or "localisation only"
    std::string loaded_from;                      // the loaded map file, if any
    long rgb_images = 0, rgb_images_refused = 0, frames_coloured = 0, frames_without_rgb = 0;
    std::string last_rgb_problem;
    // At the previous report.
    long reported_processed = 0, reported_dropped = 0, reported_observations_dropped = 0;
  };

  // Landmark counts and mode for the diagnostics (called with mutex_ held).
  void countLandmarks() {
    std::map<std::string, int> per_class;
    for (QuadricClass c : kAllQuadricClasses)
      per_class[toString(c)] = 0;
    for (const auto& [id, landmark] : mapper_->map().landmarks())
      ++per_class[toString(landmark.quadric_map.quadricClass())];
    std::lock_guard<std::mutex> lock(stats_mutex_);
    stats_.landmarks_per_class = per_class;
    stats_.landmarks = static_cast<int>(mapper_->map().landmarks().size());
    stats_.candidates = static_cast<int>(mapper_->map().candidates().size());
    stats_.reconstruction_points = static_cast<long>(reconstruction_->size());
    stats_.reconstruction_full = reconstruction_->full();
    stats_.mode = recovery_.recovering() && !user_localization_only_
                      ? "relocalising after a loss of tracking (localisation only)"
                  : mapper_->localizationOnly() ? "localisation only"
                                                : "mapping";
    stats_.losses = recovery_.losses();
    stats_.recoveries = recovery_.recoveries();
    stats_.recovery_timeouts = recovery_.timeouts();
    stats_.recovering = recovery_.recovering();
    stats_.relocalisation_attempts = recovery_.relocalisationAttempts();
    stats_.relocalisations = recovery_.relocalisations();
    stats_.loaded_from = loaded_from_;
  }

  void onDiagnosticsTimer(const ros::WallTimerEvent&) {
    try {
      diagnostics_->force_update();
    } catch (const std::exception& e) {
      NODELET_ERROR_THROTTLE(30.0, "mapping: diagnostics failed: %s", e.what());
    }
  }

  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    Stats& s = stats_;
    const long processed = s.frames_processed - s.reported_processed;
    const long dropped = s.frames_dropped - s.reported_dropped;
    const long observations_dropped = s.observations_dropped - s.reported_observations_dropped;
    s.reported_processed = s.frames_processed;
    s.reported_dropped = s.frames_dropped;
    s.reported_observations_dropped = s.observations_dropped;
    using diagnostic_msgs::DiagnosticStatus;
    if (dropped > 0 && processed == 0)
      status.summary(DiagnosticStatus::ERROR, "dropping every frame: " + s.last_drop_reason);
    else if (dropped > 0)
      status.summary(DiagnosticStatus::WARN, "dropping some frames: " + s.last_drop_reason);
    else if (observations_dropped > 0)
      status.summary(DiagnosticStatus::WARN,
                     "dropping observations: " + s.last_observation_problem);
    else if (processed == 0)
      status.summary(DiagnosticStatus::OK, "waiting for input");
    else
      status.summary(DiagnosticStatus::OK, s.mode);

    status.add("mode", s.mode);
    status.add("loaded map", s.loaded_from.empty() ? std::string("none") : s.loaded_from);
    status.add("landmarks", s.landmarks);
    status.add("reconstruction points", s.reconstruction_points);
    status.add("reconstruction full (reconstruction_max_points: new points dropped)",
               s.reconstruction_full ? "yes" : "no");
    // Of the whole process (every nodelet of the manager): the resident memory a long run should
    // keep flat, and how much of it is data in use rather than freed memory the allocator holds.
    const HeapUsage heap = heapUsage();
    status.addf("process resident memory (MB)", "%.1f", residentMemoryBytes() / 1048576.0);
    status.addf("process heap in use (MB)", "%.1f", heap.in_use / 1048576.0);
    status.addf("process heap held free (MB)", "%.1f", heap.held_free / 1048576.0);
    for (const auto& [name, count] : s.landmarks_per_class)
      status.add("landmarks: " + name, count);
    status.add("candidates", s.candidates);
    status.add("frames received", s.synchronised);
    status.add("frames processed", s.frames_processed);
    status.add("frames dropped", s.frames_dropped);
    status.add("last drop reason", s.last_drop_reason);
    status.add("keyframes", s.keyframes);
    status.add("resets (time went backwards)", s.resets);
    status.add("frames while tracking was lost", s.frames_lost);
    status.add("tracking losses", s.losses);
    status.add("recoveries (pose anchored in the map again)", s.recoveries);
    status.add("recoveries given up (recovery_max_frames)", s.recovery_timeouts);
    status.add("recovering (localisation only until anchored)", s.recovering ? "yes" : "no");
    status.add("relocalisation attempts", s.relocalisation_attempts);
    status.add("relocalisations (odometry re-anchored in the map)", s.relocalisations);
    status.add("last relocalisation", s.last_relocalisation);
    const TimingSummary relocalisation = s.relocalisation_ms.summary();
    status.add("relocalisation time median (ms)", relocalisation.median_ms);
    status.add("relocalisation time p95 (ms)", relocalisation.p95_ms);
    status.add("observations received", s.observations);
    status.add("observations dropped", s.observations_dropped);
    status.add("last observation problem", s.last_observation_problem);
    status.add("observation frame", s.observation_frame);
    status.add("camera frame (odom child)", s.camera_frame);
    status.add("observation messages", s.observation_messages);
    status.add("odom messages", s.odom_messages);
    status.add("synchronised pairs", s.synchronised);
    status.add("last frame: to landmarks", s.last.to_landmarks);
    status.add("last frame: to candidates", s.last.to_candidates);
    status.add("last frame: new candidates", s.last.new_candidates);
    status.add("last frame: promoted", s.last.promoted);
    status.add("associations to landmarks (total)", s.total_to_landmarks);
    status.add("landmarks promoted (total)", s.total_promoted);
    status.add("window keyframes", s.window.keyframes);
    status.add("window landmarks", s.window.landmark_blocks);
    status.add("window residual blocks", s.window.residual_blocks);
    status.add("window iterations", s.window.iterations);
    status.add("window final cost", s.window.final_cost);
    status.add("solve time (ms, last keyframe)", s.solve_ms);
    status.add("association time (ms, last frame)", s.association_ms);
    if (use_rgb_) {
      status.add("rgb images received", s.rgb_images);
      status.add("rgb images refused", s.rgb_images_refused);
      status.add("last rgb problem", s.last_rgb_problem);
      status.add("frames coloured", s.frames_coloured);
      status.add("frames without a matching rgb image", s.frames_without_rgb);
    }
    addTimingValues(status, s.processing_times.summary());
  }

  // Parameters.
  std::string map_frame_ = "map";
  std::string odom_frame_ = "odom";
  bool publish_tf_ = true;
  int reconstruction_every_keyframes_ = 5;
  int max_path_poses_ = 10000;
  std::string map_file_;
  bool use_rgb_ = false;
  double rgb_max_stamp_difference_ = 0.02;  // s

  // State (mutex_): the core objects and what the outputs need.
  std::mutex mutex_;
  std::unique_ptr<QuadricMapper> mapper_;
  // mapping.yaml odometry_increment_covariance, and the odometry's increments since the last frame
  // the mapper took (composeIncrement).
  bool use_increment_covariance_ = true;
  Matrix6d increment_covariance_since_mapped_ = Matrix6d::Zero();
  bool increment_since_mapped_valid_ = false;
  bool have_odom_stamp_ = false;
  ros::Time last_odom_stamp_;
  std::unique_ptr<QuadricReconstruction> reconstruction_;
  TrackingRecovery recovery_;
  bool user_localization_only_ = false;  // ~localization_only or the last ~load_map request
  std::unique_ptr<BaseMap> base_map_;    // the loaded map a reset returns to
  std::string loaded_from_;
  bool have_stamp_ = false;
  ros::Time last_stamp_;
  Eigen::Isometry3d T_map_odom_ = Eigen::Isometry3d::Identity();
  long keyframes_ = 0;  // since the last reset or load
  std::deque<geometry_msgs::PoseStamped> path_;

  // Diagnostics (stats_mutex_).
  std::mutex stats_mutex_;
  // Errors on rosout, throttled per reason (the counts go to stats_).
  DropReporter frame_drops_{"mapping: dropping frame", nullptr};
  DropReporter observation_drops_{"mapping: dropping observations", nullptr};
  DropReporter rgb_drops_{"mapping: no colours from rgb/image", nullptr};
  Stats stats_;

  QuadricMapPublisher map_publisher_;
  ros::Publisher reconstruction_pub_, path_pub_;
  ros::ServiceServer save_service_, load_service_;
  ros::WallTimer diagnostics_timer_;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
  message_filters::Subscriber<QuadricObservationArray> observations_sub_;
  message_filters::Subscriber<nav_msgs::Odometry> odom_sub_;
  std::unique_ptr<message_filters::Synchronizer<SyncPolicy>> sync_;
  std::unique_ptr<ColourImageBuffer> colour_images_;
  std::unique_ptr<image_transport::ImageTransport> image_transport_;
  image_transport::CameraSubscriber rgb_sub_;
};

}  // namespace quadric_slam

PLUGINLIB_EXPORT_CLASS(quadric_slam::MappingNodelet, nodelet::Nodelet)
