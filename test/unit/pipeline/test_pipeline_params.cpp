// The parameter key tables read config/*.yaml exactly as the nodelets read their private
// parameters: every key of the shipped files is known, values arrive, bad values are refused.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "quadric_slam/pipeline/pipeline_params.h"

namespace qs = quadric_slam;

namespace {

const std::string kConfigDir = std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/";

}  // namespace

TEST(PipelineParams, NormalEstimationYamlKeysAreAllRead) {
  const YAML::Node file = YAML::LoadFile(kConfigDir + "normal_estimation.yaml");
  qs::BackProjectionParams back_projection;
  qs::NormalEstimator::Params normals;
  qs::ParamLog log;
  qs::readNormalEstimationParams(qs::YamlParamReader(file), back_projection, normals, log);
  // Nodelet-level keys, read beside the table.
  int queue_size = 5;
  std::string output_frame;
  qs::readParam(qs::YamlParamReader(file), "queue_size", queue_size, log);
  qs::readParam(qs::YamlParamReader(file), "output_frame", output_frame, log);
  for (const auto& entry : file) {
    const std::string key = entry.first.as<std::string>();
    EXPECT_NE(log.str().find("\n  " + key + ": "), std::string::npos)
        << "config/normal_estimation.yaml key '" << key << "' is read by nobody";
  }
  EXPECT_EQ(normals.method, file["normal_method"].as<std::string>());
  EXPECT_EQ(back_projection.decimation, file["decimation"].as<int>());
}

TEST(PipelineParams, ValuesOverrideDefaultsAndBadValuesAreRefused) {
  qs::BackProjectionParams back_projection;
  qs::NormalEstimator::Params normals;
  qs::ParamLog log;
  qs::readNormalEstimationParams(
      qs::YamlParamReader(YAML::Load("{decimation: 2, normal_method: covariance_matrix}")),
      back_projection, normals, log);
  EXPECT_EQ(back_projection.decimation, 2);
  EXPECT_EQ(normals.method, "covariance_matrix");
  EXPECT_DOUBLE_EQ(back_projection.max_range, qs::BackProjectionParams().max_range);

  EXPECT_THROW(qs::readNormalEstimationParams(qs::YamlParamReader(YAML::Load("{decimation: 0}")),
                                              back_projection, normals, log),
               std::invalid_argument);
  EXPECT_THROW(
      qs::readNormalEstimationParams(qs::YamlParamReader(YAML::Load("{decimation: [1, 2]}")),
                                     back_projection, normals, log),
      std::invalid_argument);
  EXPECT_THROW(qs::YamlParamReader::fromFile("/nonexistent.yaml"), std::runtime_error);
}

TEST(PipelineParams, OdometryYamlKeysAreAllRead) {
  const YAML::Node file = YAML::LoadFile(kConfigDir + "odometry.yaml");
  const qs::YamlParamReader reader(file);
  qs::OdometryTracker::Params params;
  qs::ParamLog log;
  qs::readOdometryParams(reader, params, log);
  // Nodelet-level keys, read beside the table.
  std::string frame;
  bool publish_tf = true;
  int queue_size = 5;
  bool use_observations = false;
  qs::readParam(reader, "odom_frame", frame, log);
  qs::readParam(reader, "camera_frame", frame, log);
  qs::readParam(reader, "publish_tf", publish_tf, log);
  qs::readParam(reader, "queue_size", queue_size, log);
  qs::readParam(reader, "use_observations", use_observations, log);
  int rgb_buffer_size = 0;
  double rgb_max_stamp_difference = 0;
  qs::readParam(reader, "rgb_buffer_size", rgb_buffer_size, log);
  qs::readParam(reader, "rgb_max_stamp_difference", rgb_max_stamp_difference, log);
  for (const auto& entry : file) {
    const std::string key = entry.first.as<std::string>();
    EXPECT_NE(log.str().find("\n  " + key + ": "), std::string::npos)
        << "config/odometry.yaml key '" << key << "' is read by nobody";
  }
  EXPECT_EQ(params.icp.pyramid_levels, file["pyramid_levels"].as<int>());
  EXPECT_DOUBLE_EQ(params.keyframe_translation, file["keyframe_translation"].as<double>());
  EXPECT_EQ(params.quadric_motion_guess, file["quadric_motion_guess"].as<bool>());
  EXPECT_EQ(params.guess.max_direction_features, file["guess_max_direction_features"].as<int>());
  EXPECT_DOUBLE_EQ(params.increment_covariance_scale,
                   file["increment_covariance_scale"].as<double>());
  EXPECT_DOUBLE_EQ(params.increment_translation_fraction,
                   file["increment_translation_fraction"].as<double>());
  EXPECT_DOUBLE_EQ(params.increment_rotation_per_metre,
                   file["increment_rotation_per_metre"].as<double>());
  EXPECT_EQ(params.photometric_refinement, file["photometric_refinement"].as<bool>());
  EXPECT_EQ(params.photometric.levels, file["photometric_levels"].as<int>());
  EXPECT_DOUBLE_EQ(params.photometric.huber, file["photometric_huber"].as<double>());
  EXPECT_DOUBLE_EQ(params.photometric.max_translation,
                   file["photometric_max_translation"].as<double>());
  EXPECT_DOUBLE_EQ(params.photometric_depth_floor_translation,
                   file["photometric_depth_floor_translation"].as<double>());
  EXPECT_DOUBLE_EQ(params.photometric_depth_floor_rotation,
                   file["photometric_depth_floor_rotation"].as<double>());
}

TEST(PipelineParams, MappingYamlKeysAreAllRead) {
  const YAML::Node file = YAML::LoadFile(kConfigDir + "mapping.yaml");
  const qs::YamlParamReader reader(file);
  qs::QuadricMapper::Params mapper;
  qs::QuadricReconstruction::Params reconstruction;
  qs::TrackingRecovery::Params recovery;
  qs::ParamLog log;
  qs::readMappingParams(reader, mapper, reconstruction, log);
  qs::readTrackingRecoveryParams(reader, recovery, log);
  // The offline runner's batch refinement (never read by the nodelet).
  bool batch_refinement = false;
  qs::BatchRefiner::Params batch;
  qs::readBatchRefinementParams(reader, batch_refinement, batch, log);
  // Whether the odometry factors carry the odometry's increment covariance (QuadricSlam and the
  // nodelet).
  bool increment_covariance = !file["odometry_increment_covariance"].as<bool>();
  qs::readOdometryIncrementParams(reader, increment_covariance, log);
  EXPECT_EQ(increment_covariance, file["odometry_increment_covariance"].as<bool>());
  // Nodelet-level keys, read beside the tables.
  std::string text;
  bool flag = false;
  int count = 0;
  double period = 1.0;
  for (const char* key : {"map_frame", "odom_frame", "map_file"})
    qs::readParam(reader, key, text, log);
  for (const char* key : {"publish_tf", "localization_only", "use_rgb"})
    qs::readParam(reader, key, flag, log);
  for (const char* key :
       {"queue_size", "reconstruction_every_keyframes", "max_path_poses", "rgb_buffer_size"})
    qs::readParam(reader, key, count, log);
  qs::readParam(reader, "diagnostic_period", period, log);
  qs::readParam(reader, "rgb_max_stamp_difference", period, log);
  for (const auto& entry : file) {
    const std::string key = entry.first.as<std::string>();
    EXPECT_NE(log.str().find("\n  " + key + ": "), std::string::npos)
        << "config/mapping.yaml key '" << key << "' is read by nobody";
  }
  EXPECT_EQ(recovery.confirm_frames, file["recovery_confirm_frames"].as<int>());
  EXPECT_EQ(recovery.min_landmark_associations,
            file["recovery_min_landmark_associations"].as<int>());
  EXPECT_EQ(recovery.relocaliser.enabled, file["relocalisation_enabled"].as<bool>());
  EXPECT_EQ(recovery.relocaliser.min_supporting_surfaces,
            file["relocalisation_min_supporting_surfaces"].as<int>());
  EXPECT_DOUBLE_EQ(recovery.relocaliser.matcher.max_offset_difference,
                   file["relocalisation_max_offset_difference"].as<double>());
  EXPECT_EQ(batch_refinement, file["batch_refinement"].as<bool>());
  EXPECT_EQ(batch.max_iterations, file["batch_max_iterations"].as<int>());
  EXPECT_EQ(batch.max_keyframes, file["batch_max_keyframes"].as<int>());
  EXPECT_EQ(batch.compute_covariance, file["batch_compute_covariance"].as<bool>());
  EXPECT_EQ(batch.noise_rounds, file["batch_noise_rounds"].as<int>());
  EXPECT_DOUBLE_EQ(batch.noise_tolerance, file["batch_noise_tolerance"].as<double>());
  EXPECT_EQ(batch.merge_rounds, file["batch_merge_rounds"].as<int>());
}

// The measurement model error (mapping/measurement_model_error.h): the file's values reach the
// mapper, and a value out of range is refused naming the key's field.
TEST(PipelineParams, ModelErrorKeysAreReadAndValidated) {
  const YAML::Node file = YAML::LoadFile(kConfigDir + "mapping.yaml");
  qs::QuadricMapper::Params mapper;
  qs::QuadricReconstruction::Params reconstruction;
  qs::ParamLog log;
  qs::readMappingParams(qs::YamlParamReader(file), mapper, reconstruction, log);
  EXPECT_DOUBLE_EQ(mapper.model_error.sigma, file["model_error_sigma"].as<double>());
  EXPECT_DOUBLE_EQ(mapper.model_error.correlation_angle,
                   file["model_error_correlation_angle"].as<double>());
  for (const char* bad : {"{model_error_sigma: -0.001}", "{model_error_correlation_angle: 0}"}) {
    try {
      qs::readMappingParams(qs::YamlParamReader(YAML::Load(bad)), mapper, reconstruction, log);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("MeasurementModelError"), std::string::npos) << e.what();
    }
  }
}

// The gate's correlated depth noise (mapping/association.h): the file's values reach the
// associator, and a value out of range is refused naming the field.
TEST(PipelineParams, CorrelatedNoiseKeysAreReadAndValidated) {
  const YAML::Node file = YAML::LoadFile(kConfigDir + "mapping.yaml");
  qs::QuadricMapper::Params mapper;
  qs::QuadricReconstruction::Params reconstruction;
  qs::ParamLog log;
  qs::readMappingParams(qs::YamlParamReader(file), mapper, reconstruction, log);
  EXPECT_DOUBLE_EQ(mapper.map.association.correlated_noise_fraction,
                   file["correlated_noise_fraction"].as<double>());
  EXPECT_DOUBLE_EQ(mapper.map.association.noise_correlation_angle,
                   file["noise_correlation_angle"].as<double>());
  EXPECT_DOUBLE_EQ(mapper.map.association.cross_class_distance,
                   file["cross_class_distance"].as<double>());
  EXPECT_DOUBLE_EQ(mapper.map.association.cross_class_rms_factor,
                   file["cross_class_rms_factor"].as<double>());
  for (const auto& [bad, field] : std::vector<std::pair<std::string, std::string>>{
           {"{cross_class_distance: -0.01}", "cross_class_distance"},
           {"{cross_class_rms_factor: -1}", "cross_class_rms_factor"},
           {"{correlated_noise_fraction: 1.01}", "correlated_noise_fraction"},
           {"{correlated_noise_fraction: -0.1}", "correlated_noise_fraction"},
           {"{noise_correlation_angle: 0}", "noise_correlation_angle"},
           {"{noise_correlation_angle: 0.6}", "noise_correlation_angle"}}) {
    qs::QuadricMapper::Params fresh;
    try {
      qs::readMappingParams(qs::YamlParamReader(YAML::Load(bad)), fresh, reconstruction, log);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  }
}

// Off unless a file turns it on; a bad iteration count is refused naming the field.
TEST(PipelineParams, BatchRefinementKeysAreValidated) {
  bool enabled = false;
  qs::BatchRefiner::Params batch;
  qs::ParamLog log;
  qs::readBatchRefinementParams(qs::YamlParamReader(YAML::Load("{window_size: 5}")), enabled, batch,
                                log);
  EXPECT_FALSE(enabled);
  EXPECT_EQ(batch.max_iterations, qs::BatchRefiner::Params().max_iterations);
  qs::readBatchRefinementParams(
      qs::YamlParamReader(YAML::Load("{batch_refinement: true, batch_max_iterations: 7}")), enabled,
      batch, log);
  EXPECT_TRUE(enabled);
  EXPECT_EQ(batch.max_iterations, 7);
  qs::readBatchRefinementParams(
      qs::YamlParamReader(YAML::Load("{batch_noise_rounds: 0, batch_noise_tolerance: 0.5}")),
      enabled, batch, log);
  EXPECT_EQ(batch.noise_rounds, 0);
  EXPECT_EQ(batch.noise_tolerance, 0.5);
  qs::readBatchRefinementParams(qs::YamlParamReader(YAML::Load("{batch_merge_rounds: 0}")), enabled,
                                batch, log);
  EXPECT_EQ(batch.merge_rounds, 0);
  for (const auto& [bad, field] : std::vector<std::pair<std::string, std::string>>{
           {"{batch_max_iterations: 0}", "max_iterations"},
           {"{batch_max_iterations: 10001}", "max_iterations"},
           {"{batch_max_keyframes: 0}", "max_keyframes"},
           {"{batch_noise_rounds: 11}", "noise_rounds"},
           {"{batch_noise_tolerance: 0}", "noise_tolerance"},
           {"{batch_noise_tolerance: 11}", "noise_tolerance"},
           {"{batch_merge_rounds: -1}", "merge_rounds"},
           {"{batch_merge_rounds: 11}", "merge_rounds"}}) {
    qs::BatchRefiner::Params fresh;
    try {
      qs::readBatchRefinementParams(qs::YamlParamReader(YAML::Load(bad)), enabled, fresh, log);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  }
}
