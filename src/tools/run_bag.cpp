// run_bag: the offline runner. Pushes every frame of a TUM rosbag or TUM folder through the same
// core classes the nodelets use (back-projection + normals, quadric segmentation, odometry,
// mapping), with the same config/*.yaml parameters, as fast as the machine allows: no master, no
// real-time pacing. Writes DIR/trajectory.txt (TUM format, camera optical frame in the odom frame),
// DIR/timing.json (per-stage median/p95/max) and, unless --odometry-only, the mapper's
// DIR/trajectory_map.txt (camera in the map frame), DIR/map.yaml (the landmarks, map schema) and
// DIR/reconstruction.pcd (landmark points projected onto their surfaces, label = landmark id);
// with --gt prints the ATE and RPE of the odometry (ate_rmse_m ...) and of the mapper
// (map_ate_rmse_m ...).
//
//   run_bag INPUT --out DIR [--odometry-only] [--gt GROUNDTRUTH] [--config DIR] [--max-frames N]
//           [--intrinsics fx,fy,cx,cy] [--quiet]
#include <pcl/io/pcd_io.h>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>

#include "quadric_slam/eval/stage_timing.h"
#include "quadric_slam/eval/trajectory_metrics.h"
#include "quadric_slam/frontend/detection_measurement.h"
#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/frontend/segmenter_params.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/io/landmark_map_file.h"
#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/io/pipeline_params.h"
#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/io/tum_folder_reader.h"
#include "quadric_slam/mapping/quadric_mapper.h"
#include "quadric_slam/mapping/reconstruction.h"
#include "quadric_slam/odometry/odometry_tracker.h"
#include "quadric_slam/ros/tum_bag_reader.h"

namespace qs = quadric_slam;
namespace fs = std::filesystem;

namespace {

struct Options {
  std::string input, out_dir, gt_path;
  std::string config_dir = QUADRIC_SLAM_CONFIG_DIR;
  bool odometry_only = false;
  bool quiet = false;
  long max_frames = -1;
  qs::CameraIntrinsics intrinsics;  // fx = 0: from the input
};

int usage(const std::string& problem) {
  std::cerr
      << "run_bag: " << problem << "\n"
      << "usage: run_bag INPUT --out DIR [--odometry-only] [--gt GROUNDTRUTH] [--config DIR]\n"
      << "               [--max-frames N] [--intrinsics fx,fy,cx,cy] [--quiet]\n"
      << "  INPUT: a TUM rosbag (.bag) or a TUM folder (rgb.txt, depth.txt, depth/)\n";
  return 2;
}

bool parseOptions(int argc, char** argv, Options& o, std::string& problem) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc)
        throw std::invalid_argument(arg + " needs a value");
      return argv[++i];
    };
    try {
      if (arg == "--out") {
        o.out_dir = value();
      } else if (arg == "--gt") {
        o.gt_path = value();
      } else if (arg == "--config") {
        o.config_dir = value();
      } else if (arg == "--max-frames") {
        o.max_frames = std::stol(value());
      } else if (arg == "--odometry-only") {
        o.odometry_only = true;
      } else if (arg == "--quiet") {
        o.quiet = true;
      } else if (arg == "--intrinsics") {
        if (!qs::parseIntrinsics(value(), o.intrinsics))
          throw std::invalid_argument("--intrinsics takes fx,fy,cx,cy");
      } else if (!arg.empty() && arg[0] == '-') {
        throw std::invalid_argument("unknown option " + arg);
      } else if (o.input.empty()) {
        o.input = arg;
      } else {
        throw std::invalid_argument("more than one INPUT given");
      }
    } catch (const std::exception& e) {
      problem = e.what();
      return false;
    }
  }
  if (o.input.empty())
    problem = "no INPUT given";
  else if (o.out_dir.empty())
    problem = "--out is required";
  return problem.empty();
}

std::unique_ptr<qs::FrameSource> openInput(const Options& o) {
  if (fs::is_directory(o.input)) {
    qs::TumFolderReader::Params params;
    params.load_rgb = false;  // depth is all the pipeline uses
    if (o.intrinsics.fx > 0)
      params.intrinsics = o.intrinsics;
    return std::make_unique<qs::TumFolderReader>(o.input, params);
  }
  if (fs::is_regular_file(o.input)) {
    qs::TumBagReader::Params params;
    params.rgb_topic.clear();  // depth only
    if (o.intrinsics.fx > 0)
      params.intrinsics = o.intrinsics;
    return std::make_unique<qs::TumBagReader>(o.input, params);
  }
  throw std::runtime_error("INPUT " + o.input + " is neither a TUM folder nor a bag file");
}

qs::YamlParamReader configFile(const Options& o, const std::string& name) {
  return qs::YamlParamReader::fromFile(o.config_dir + "/" + name);
}

// Prints <prefix>ate_rmse_m, <prefix>pairs and <prefix>rpe_m_per_s.
void printTrajectoryErrors(const std::string& gt_path, const qs::Trajectory& estimate,
                           const std::string& prefix = "") {
  const qs::Trajectory gt = qs::readTumTrajectory(gt_path);
  const auto ate =
      qs::AbsoluteTrajectoryError(qs::AbsoluteTrajectoryError::Params{}).evaluate(gt, estimate);
  std::printf("%sate_rmse_m %.6f\n%spairs %zu\n", prefix.c_str(), ate.rmse(), prefix.c_str(),
              ate.pairs());
  try {
    const auto rpe = qs::RelativePoseError(qs::RelativePoseError::Params{}).evaluate(gt, estimate);
    std::printf("%srpe_m_per_s %.6f\n", prefix.c_str(), rpe.translation.rmse);
  } catch (const std::runtime_error& e) {
    std::printf("%srpe_m_per_s nan\n", prefix.c_str());
    std::cerr << "run_bag: no RPE: " << e.what() << "\n";
  }
}

// The points of each label 1..count of a segmentation's label image (index label - 1).
std::vector<std::vector<Eigen::Vector3f>> pointsPerLabel(
    const pcl::PointCloud<pcl::PointNormal>& cloud, const cv::Mat& labels, std::size_t count) {
  std::vector<std::vector<Eigen::Vector3f>> points(count);
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

int main(int argc, char** argv) {
  Options o;
  std::string problem;
  if (!parseOptions(argc, argv, o, problem))
    return usage(problem);

  try {
    qs::ParamLog log;
    qs::BackProjectionParams back_projection;
    qs::NormalEstimator::Params normal_params;
    qs::readNormalEstimationParams(configFile(o, "normal_estimation.yaml"), back_projection,
                                   normal_params, log);
    qs::OdometryTracker::Params odometry_params;
    qs::readOdometryParams(configFile(o, "odometry.yaml"), odometry_params, log);
    qs::QuadricSegmenter::Params segmenter_params;
    qs::readSegmentationParams(configFile(o, "segmentation.yaml"), segmenter_params, log);
    const qs::NormalEstimator normals(normal_params);
    const qs::QuadricSegmenter segmenter(segmenter_params);
    qs::OdometryTracker odometry(odometry_params);
    // The mapping back-end with its default parameters (no config file yet).
    qs::QuadricMapper mapper;
    qs::QuadricReconstruction reconstruction;
    qs::Trajectory map_trajectory;

    std::unique_ptr<qs::FrameSource> source = openInput(o);
    const std::size_t total =
        o.max_frames >= 0 ? std::min<std::size_t>(source->size(), o.max_frames) : source->size();
    fs::create_directories(o.out_dir);
    if (!o.quiet) {
      std::cerr << "run_bag: " << o.input << ": " << total << " frames, config " << o.config_dir
                << (o.odometry_only ? ", odometry only" : "") << "\n";
    }

    qs::StageTimer timer;
    qs::Trajectory trajectory;
    int status_counts[3] = {0, 0, 0};
    std::map<std::string, std::size_t> observations_per_class;
    std::size_t frames = 0, skipped = 0;
    double last_stamp = -1e300;
    const auto start = std::chrono::steady_clock::now();
    qs::RgbdFrame frame;
    pcl::PointCloud<pcl::PointNormal> cloud;  // storage reused from frame to frame
    while (frames < total && timer.time("read", [&] { return source->next(frame); })) {
      ++frames;
      if (frame.stamp <= last_stamp) {
        // Same rule as the nodelets: time going backwards starts a new odom frame.
        std::cerr << "\nrun_bag: time went backwards at " << frame.stamp << ": resetting\n";
        odometry.reset();
        mapper.reset();
        reconstruction.clear();
      }
      last_stamp = frame.stamp;
      const qs::CameraIntrinsics& k = frame.intrinsics;
      const std::string size_problem =
          qs::imageSizeProblem(k, frame.depth_m.cols, frame.depth_m.rows);
      if (!size_problem.empty()) {
        std::cerr << "\nrun_bag: skipping frame " << frame.stamp << ": " << size_problem << "\n";
        ++skipped;
        continue;
      }
      timer.time("normals", [&] {
        normals.compute(qs::backProject(qs::depthViewOf(frame.depth_m), k, back_projection), cloud);
      });
      qs::Segmentation segmentation;
      if (!o.odometry_only) {
        segmentation = timer.time("segmentation", [&] { return segmenter.segment(cloud); });
        for (const qs::QuadricDetection& detection : segmentation.detections)
          ++observations_per_class[qs::toString(detection.shape.quadric_class)];
      }
      const qs::OdometryTracker::Result result =
          timer.time("odometry", [&] { return odometry.track(cloud, k, frame.stamp); });
      ++status_counts[static_cast<int>(result.status)];
      if (odometry.initialized())
        trajectory.push_back({frame.stamp, result.T_odom_camera});
      if (!o.odometry_only && odometry.initialized()) {
        const qs::FrameMeasurements measurements =
            qs::toFrameMeasurements(segmentation, frame.stamp, "camera");
        qs::OdometryInput odometry_input;
        odometry_input.T_odom_camera = result.T_odom_camera;
        const qs::MapperFrameResult mapped =
            timer.time("mapping", [&] { return mapper.process(measurements, odometry_input); });
        if (mapped.status != qs::FrameStatus::kOk) {
          std::cerr << "\nrun_bag: mapper refused frame " << frame.stamp << ": " << mapped.message
                    << "\n";
        } else {
          map_trajectory.push_back({frame.stamp, mapped.T_map_camera});
          // Reconstruction: the supporting points of the keyframes' landmark observations.
          if (mapped.keyframe) {
            timer.time("reconstruction", [&] {
              const auto points =
                  pointsPerLabel(cloud, segmentation.labels, segmentation.detections.size());
              for (std::size_t i = 0; i < mapped.update.measurements.size(); ++i) {
                const qs::MeasurementResult& fate = mapped.update.measurements[i];
                const int label = measurements.observations[i].label;
                if ((fate.fate != qs::MeasurementFate::kLandmark &&
                     fate.fate != qs::MeasurementFate::kPromoted) ||
                    label < 1 || label > static_cast<int>(points.size()))
                  continue;
                const auto landmark = mapper.map().landmarks().find(fate.id);
                if (landmark != mapper.map().landmarks().end())
                  reconstruction.addPoints(fate.id, landmark->second.quadric_map,
                                           mapped.T_map_camera, points[label - 1]);
              }
            });
          }
        }
      }
      if (!o.quiet && (frames % 30 == 0 || frames == total)) {
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::fprintf(stderr, "\rframe %zu/%zu  %.1f fps  ok %d degenerate %d lost %d", frames,
                     total, frames / elapsed, status_counts[0], status_counts[1], status_counts[2]);
      }
    }
    const double wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!o.quiet)
      std::fprintf(stderr, "\n");

    qs::writeTumTrajectory(trajectory, o.out_dir + "/trajectory.txt",
                           "quadric_slam run_bag: camera optical frame in the odom frame");
    std::ofstream(o.out_dir + "/timing.json") << timer.json(frames, wall_s);

    std::printf("frames %zu\nskipped %zu\nwall_s %.3f\nfps %.2f\n", frames, skipped, wall_s,
                frames / std::max(wall_s, 1e-9));
    std::printf("tracking ok %d degenerate %d lost %d\n", status_counts[0], status_counts[1],
                status_counts[2]);
    if (!o.odometry_only) {
      std::printf("observations per frame:");
      for (const auto& [name, count] : observations_per_class)
        std::printf(" %s %.2f", name.c_str(),
                    static_cast<double>(count) / std::max<std::size_t>(frames, 1));
      std::printf("\n");
    }
    std::fputs(timer.table().c_str(), stdout);
    std::printf("trajectory %s/trajectory.txt\ntiming %s/timing.json\n", o.out_dir.c_str(),
                o.out_dir.c_str());
    if (!o.odometry_only) {
      qs::writeTumTrajectory(map_trajectory, o.out_dir + "/trajectory_map.txt",
                             "quadric_slam run_bag: camera optical frame in the map frame");
      const std::vector<qs::QuadricLandmark> landmarks = mapper.landmarks();
      qs::writeMapYaml(qs::mapFileFromLandmarks(landmarks, "map"), o.out_dir + "/map.yaml");
      std::map<int, qs::QuadricModel> surfaces;
      std::map<std::string, int> per_class;
      for (const qs::QuadricLandmark& landmark : landmarks) {
        surfaces[landmark.id] = landmark.quadric_map;
        ++per_class[qs::toString(landmark.quadric_map.quadricClass())];
      }
      const pcl::PointCloud<pcl::PointXYZL> points = reconstruction.cloud(surfaces);
      if (!points.empty())
        pcl::io::savePCDFileBinary(o.out_dir + "/reconstruction.pcd", points);
      std::printf("map landmarks %zu:", landmarks.size());
      for (const auto& [name, count] : per_class)
        std::printf(" %s %d", name.c_str(), count);
      std::printf("\nreconstruction points %zu\n", points.size());
      std::printf("map %s/map.yaml\ntrajectory_map %s/trajectory_map.txt\n", o.out_dir.c_str(),
                  o.out_dir.c_str());
    }
    if (!o.gt_path.empty()) {
      printTrajectoryErrors(o.gt_path, trajectory);
      if (!o.odometry_only)
        printTrajectoryErrors(o.gt_path, map_trajectory, "map_");
    }
  } catch (const std::exception& e) {
    std::cerr << "\nrun_bag: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
