// run_bag: the offline runner, a thin shell over the pipeline class QuadricSlam
// (pipeline/quadric_slam.h): every frame of a TUM rosbag or TUM folder through normals, quadric
// segmentation, odometry and mapping, with the same config/*.yaml parameters as the nodelets, as
// fast as the machine allows (no master, no real-time pacing). Writes
//   DIR/trajectory.txt       the SLAM estimate, camera optical frame in the map frame: after the
//                            offline batch refinement (mapping.yaml batch_refinement, on in the
//                            package's config; mapping/batch_refiner.h) the refined trajectory,
//                            else the online one (with --odometry-only: the odometry, camera in
//                            the odom frame)
//   DIR/trajectory_online.txt with the batch refinement: the online SLAM estimate (as the live
//                            nodelet has it), for comparison
//   DIR/trajectory_odom.txt  the odometry, camera optical frame in the odom frame
//   DIR/timing.json          per-stage median/p95/max
//   DIR/map.yaml             the landmarks (map schema), unless --odometry-only; refined by the
//                            batch refinement when it ran (DIR/map_online.yaml: the online map)
//   DIR/reconstruction.pcd   landmark points projected onto their surfaces (label = landmark id;
//                            rgba = the pixel's colour when the input has RGB, alpha 255, else
//                            the landmark's colour, alpha 0: ros/reconstruction_cloud.h)
//   DIR/resources.csv        every --sample-every frames: resident memory, frame time, landmarks,
//                            candidates, reconstruction points (what a long run may grow) and
//                            the heap in use (eval/resource_usage.h: resident memory less what
//                            the allocator holds free)
//   DIR/frames.csv           one line per processed frame, written as it comes: the odometry
//                            status, the back end's times (odometry, mapping and within it
//                            association, window optimisation, merging; ms), keyframe, landmarks,
//                            window size: the cost over the run, e.g. its deciles
//                            (scripts/bounded_cost)
// With --gt prints the ATE and RPE of the odometry (ate_rmse_m ...) and of SLAM (map_ate_rmse_m
// ...); with the batch refinement also the online SLAM's (online_map_ate_rmse_m ...), and the
// refinement's size and time (batch_seconds). INPUT may also be a scene file
// (config/scenes/*.yaml): its frames are rendered as they are needed
// (sim/synthetic_frame_source.h), so a sequence of any length runs without a bag; the truth goes to
// DIR/groundtruth.txt and is used when --gt is not given.
//
//   run_bag INPUT --out DIR [--odometry-only] [--gt GROUNDTRUTH] [--config DIR] [--profile P]
//           [--max-frames N]
//           [--intrinsics fx,fy,cx,cy] [--quiet] [--sample-every N] [--no-rgb] [--no-batch]
//           [--seconds S] [--rate HZ] [--seed N]   (scene INPUT only)
#include <pcl/io/pcd_io.h>
#include <pcl_conversions/pcl_conversions.h>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>

#include "quadric_slam/eval/resource_usage.h"
#include "quadric_slam/eval/trajectory_metrics.h"
#include "quadric_slam/io/depth_correction_yaml.h"
#include "quadric_slam/io/landmark_map_file.h"
#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/pipeline/memory_reuse.h"
#include "quadric_slam/pipeline/quadric_slam.h"
#include "quadric_slam/ros/reconstruction_cloud.h"
#include "quadric_slam/ros/recording_source.h"
#include "quadric_slam/sim/scene_yaml.h"
#include "quadric_slam/sim/synthetic_frame_source.h"

namespace qs = quadric_slam;
namespace fs = std::filesystem;

namespace {

struct Options {
  std::string input, out_dir, gt_path;
  std::string config_dir = QUADRIC_SLAM_CONFIG_DIR;
  std::string profile;  // a configuration profile over config_dir's files (e.g. qvga)
  bool odometry_only = false;
  bool quiet = false;
  bool rgb = true;    // read RGB when the input has it (it colours the reconstruction only)
  bool batch = true;  // false: no batch refinement whatever mapping.yaml says
  // Reading and the front end (normals, segmentation) of the next two frames on threads of their
  // own while the back end (odometry, mapping) works on this one: the same results, sooner on 2+
  // cores.
  bool pipelined = true;
  // Worker threads of the normal estimation and the segmentation; by default 1 when pipelined and
  // the configured `threads` keys when sequential.
  int stage_threads = 1;
  bool stage_threads_given = false;
  long max_frames = -1;
  long sample_every = 30;
  qs::CameraIntrinsics intrinsics;             // fx = 0: from the input
  std::string depth_correction;                // calibrate_depth's file, or empty
  qs::SyntheticFrameSource::Params synthetic;  // a scene INPUT
};

bool isSceneFile(const std::string& input) {
  const fs::path path(input);
  return fs::is_regular_file(path) && (path.extension() == ".yaml" || path.extension() == ".yml");
}

int usage(const std::string& problem) {
  std::cerr
      << "run_bag: " << problem << "\n"
      << "usage: run_bag INPUT --out DIR [--odometry-only] [--gt GROUNDTRUTH] [--config DIR]\n"
      << "               [--profile NAME|DIR] [--max-frames N] [--intrinsics fx,fy,cx,cy] "
         "[--quiet]\n"
      << "               [--sample-every N] [--no-rgb] [--no-batch] [--seconds S] [--rate HZ]\n"
      << "               [--seed N] [--sequential] [--stage-threads N] [--depth-correction F]\n"
      << "  INPUT: a TUM rosbag (.bag), a TUM folder (rgb.txt, depth.txt, depth/), or a scene\n"
      << "         file (config/scenes/*.yaml) rendered frame by frame: --seconds (default 60),\n"
      << "         --rate (default: the scene's), --seed (default 1) apply to it\n"
      << "  --profile: keys that replace --config's, from DIR/{normal_estimation,segmentation,\n"
      << "             odometry,mapping}.yaml; NAME = CONFIG/profiles/NAME (qvga: 320x240\n"
      << "             processing, for machines that cannot keep up at 640x480)\n"
      << "  --sample-every N: a line of DIR/resources.csv every N frames (default 30)\n"
      << "  --no-rgb: depth only (by default RGB, when the input has it, colours the\n"
      << "            reconstruction; frames without an RGB partner run uncoloured)\n"
      << "  --no-batch: no offline batch refinement (mapping.yaml batch_refinement): "
         "trajectory.txt\n"
      << "              and map.yaml are the online estimates\n"
      << "  --sequential: one thread for the whole pipeline (by default the next two frames are\n"
      << "                read and their normals and segmentation computed on threads of their\n"
      << "                own meanwhile; the results are the same)\n"
      << "  --stage-threads N: worker threads inside the normal estimation and the segmentation\n"
      << "                (default: 1 when pipelined, where the pipeline's own threads already\n"
      << "                use the cores; the configured `threads` keys with --sequential)\n"
      << "  --depth-correction F: undo the sensor's fixed depth distortion with F, written by\n"
      << "                scripts/calibrate_depth (frontend/depth_correction.h)\n";
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
      } else if (arg == "--profile") {
        o.profile = value();
      } else if (arg == "--max-frames") {
        o.max_frames = std::stol(value());
      } else if (arg == "--odometry-only") {
        o.odometry_only = true;
      } else if (arg == "--no-rgb") {
        o.rgb = false;
      } else if (arg == "--sequential") {
        o.pipelined = false;
      } else if (arg == "--stage-threads") {
        o.stage_threads = std::stoi(value());
        o.stage_threads_given = true;
        if (o.stage_threads < 1 || o.stage_threads > 64)
          throw std::invalid_argument("--stage-threads must be in [1, 64]");
      } else if (arg == "--no-batch") {
        o.batch = false;
      } else if (arg == "--quiet") {
        o.quiet = true;
      } else if (arg == "--sample-every") {
        o.sample_every = std::stol(value());
        if (o.sample_every < 1)
          throw std::invalid_argument("--sample-every must be >= 1");
      } else if (arg == "--seconds") {
        o.synthetic.seconds = std::stod(value());
      } else if (arg == "--rate") {
        o.synthetic.rate = std::stod(value());
      } else if (arg == "--seed") {
        o.synthetic.seed = std::stoull(value());
      } else if (arg == "--depth-correction") {
        o.depth_correction = value();
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
  if (isSceneFile(o.input)) {
    qs::Scene scene = qs::readSceneYaml(o.input);
    if (o.intrinsics.fx > 0)
      throw std::invalid_argument("--intrinsics does not apply to a scene (set its camera)");
    qs::SyntheticFrameSource::Params params = o.synthetic;
    params.rgb = o.rgb;  // colours the reconstruction only
    return std::make_unique<qs::SyntheticFrameSource>(scene, params);
  }
  // RGB (registered to depth) colours the reconstruction only.
  return qs::openRecording(o.input, qs::RecordingOptions{o.rgb, o.intrinsics});
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

// The offline batch refinement (mapping/batch_refiner.h) of the run: writes the refined
// trajectory to out_dir/trajectory.txt, prints its size, cost and time, and returns the refined
// landmarks, and in `merges` the landmarks it merged. After a reset of the input (time went
// backwards) only the last session was recorded: then, or when the solve is not usable,
// trajectory.txt is the online one and the map stays online.
std::vector<qs::QuadricLandmark> refineOffline(const qs::QuadricSlam& slam, std::size_t resets,
                                               const std::string& out_dir,
                                               std::vector<qs::LandmarkMerge>* merges) {
  const std::string online = out_dir + "/trajectory_online.txt";
  const std::string refined = out_dir + "/trajectory.txt";
  if (resets > 0) {
    std::printf("batch_refinement skipped: the input reset %zu times\n", resets);
    fs::copy_file(online, refined, fs::copy_options::overwrite_existing);
    return slam.mapper().landmarks();
  }
  const auto start = std::chrono::steady_clock::now();
  const qs::BatchSolution solution = slam.refineBatch();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const qs::BatchStatistics& s = solution.statistics;
  std::printf(
      "batch_refinement keyframes %d frames %d landmarks %d observations %d iterations %d cost "
      "%.6g -> %.6g usable %d covariance %d invalid_landmarks %d skipped_observations %d\n",
      s.keyframes, s.frames, s.landmarks, s.observation_factors, s.iterations, s.initial_cost,
      s.final_cost, s.solution_usable, s.covariance_computed, s.invalid_landmarks,
      s.skipped_observations);
  std::printf("batch_seconds %.3f\nbatch_solve_seconds %.3f\nbatch_covariance_seconds %.3f\n",
              seconds, s.solve_seconds, s.covariance_seconds);
  std::printf("batch_report %s\n", s.report.c_str());
  std::printf("batch observation residual (sigmas) median %.2f p95 %.2f\n",
              s.observation_residual_median, s.observation_residual_p95);
  std::printf("batch observation variance factor %.1f (%d solves)\n", s.observation_variance_factor,
              s.solves);
  if (!s.solution_usable) {
    std::printf("batch_refinement not usable (%s): the online estimates are kept\n",
                s.report.c_str());
    fs::copy_file(online, refined, fs::copy_options::overwrite_existing);
    return slam.mapper().landmarks();
  }
  qs::Trajectory trajectory;
  for (const qs::RefinedPose& pose : solution.trajectory)
    trajectory.push_back({pose.stamp, pose.T_map_camera});
  qs::writeTumTrajectory(trajectory, refined,
                         "quadric_slam run_bag: camera optical frame in the map frame, after the "
                         "batch refinement");
  *merges = solution.merges;
  std::printf("batch merged landmarks %d\n", s.merged_landmarks);
  std::printf("batch unobserved landmarks %d (no keyframe observes them: left out of the map)\n",
              s.unobserved_landmarks);
  // Pairs the batch's merge passes left (none once the passes converge).
  std::map<int, qs::QuadricLandmark> refined_by_id;
  for (const qs::QuadricLandmark& landmark : solution.landmarks)
    refined_by_id[landmark.id] = landmark;
  const std::vector<qs::DuplicatePair>& pairs = solution.duplicates;
  std::map<std::string, int> pairs_per_class;
  for (const qs::DuplicatePair& pair : pairs)
    ++pairs_per_class[qs::toString(refined_by_id.at(pair.id_a).quadric_map.quadricClass())];
  std::printf("batch duplicate pairs %zu", pairs.size());
  for (const auto& [name, count] : pairs_per_class)
    std::printf(" %s %d", name.c_str(), count);
  std::printf("\ntrajectory_online %s\n", online.c_str());
  return solution.landmarks;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  std::string problem;
  if (!parseOptions(argc, argv, o, problem))
    return usage(problem);
  if (!qs::keepFreedMemoryForReuse())
    std::fprintf(stderr,
                 "run_bag: the allocator keeps its defaults (frames fault their pages in)\n");

  try {
    const std::string profile_dir = qs::profileDirectory(o.config_dir, o.profile);
    qs::SlamParams params = qs::loadSlamParams(o.config_dir, nullptr, profile_dir);
    params.mapping_enabled = !o.odometry_only;
    params.batch_refinement = params.batch_refinement && o.batch && !o.odometry_only;
    if (o.pipelined && !o.stage_threads_given) {
      // Pipelined, two frames' front ends and the back end are already in flight on their own
      // threads: worker threads inside a stage only contend with them for the cores (kitchen,
      // 1000 frames, 2 cores: 24.6-27.5 fps with the configured 2, 29.6-30.6 fps with 1, the same
      // results, half the system time).
      params.normals.threads = 1;
      params.segmentation.threads = 1;
    } else if (o.stage_threads_given) {
      params.normals.threads = o.stage_threads;
      params.segmentation.threads = o.stage_threads;
    }
    if (!o.depth_correction.empty())
      params.depth_correction = qs::readDepthCorrectionYaml(o.depth_correction);
    const bool batch = params.batch_refinement;
    qs::QuadricSlam slam(params);

    std::unique_ptr<qs::FrameSource> source = openInput(o);
    const std::size_t total =
        o.max_frames >= 0 ? std::min<std::size_t>(source->size(), o.max_frames) : source->size();
    fs::create_directories(o.out_dir);
    if (const auto* synthetic = dynamic_cast<const qs::SyntheticFrameSource*>(source.get())) {
      const std::string truth = o.out_dir + "/groundtruth.txt";
      qs::writeTumTrajectory(synthetic->groundTruth(), truth,
                             "quadric_slam run_bag: ground truth of the rendered scene " + o.input);
      if (o.gt_path.empty())
        o.gt_path = truth;
    }
    // Long-run curves: memory, time per frame and map size every sample_every frames.
    std::ofstream resources(o.out_dir + "/resources.csv");
    resources << "frames,stamp_s,elapsed_s,rss_mb,ms_per_frame,landmarks,candidates,"
                 "reconstruction_points,heap_in_use_mb\n";
    auto last_sample = std::chrono::steady_clock::now();
    std::ofstream frames_csv(o.out_dir + "/frames.csv");
    frames_csv << "frame,stamp_s,status,odometry_ms,mapping_ms,association_ms,optimisation_ms,"
                  "merge_ms,keyframe,landmarks,window_keyframes,window_residuals\n";
    if (!o.quiet) {
      std::cerr << "run_bag: " << o.input << ": " << total << " frames, config " << o.config_dir
                << (profile_dir.empty() ? "" : ", profile " + profile_dir)
                << (o.odometry_only ? ", odometry only" : "") << "\n";
    }

    qs::StageTimer read_timer;
    // Written as the frames come (not kept in memory: flat memory over long runs).
    qs::TumTrajectoryWriter odom_trajectory(
        o.out_dir + "/trajectory_odom.txt",
        "quadric_slam run_bag: camera optical frame in the odom frame");
    // With the batch refinement trajectory.txt is written at the end, from the refined keyframes.
    qs::TumTrajectoryWriter slam_trajectory(
        o.out_dir + (batch ? "/trajectory_online.txt" : "/trajectory.txt"),
        o.odometry_only ? "quadric_slam run_bag: camera optical frame in the odom frame"
                        : "quadric_slam run_bag: camera optical frame in the map frame");
    int status_counts[3] = {0, 0, 0};
    std::size_t frames_recovering = 0;  // the mapper localised only (after a loss of tracking)
    std::map<std::string, std::size_t> observations_per_class;
    std::size_t frames = 0, skipped = 0, keyframes = 0, joined = 0, merged_online = 0, resets = 0;
    // How each measurement fared against the landmarks (AssociationOutcome, mapping/association.h).
    std::map<qs::AssociationOutcome, std::size_t> outcomes;
    const auto start = std::chrono::steady_clock::now();
    // Three slots: while the back end takes one frame, the front end (read, normals, segmentation)
    // works on the next two, each on a thread of its own when pipelined (QuadricSlam::frontEnd is
    // const and may run on two frames at once): on two cores the back end alone would leave one
    // idle most of the time. Reads stay in frame order (each waits for the previous frame's read),
    // and a slot is not written again before its frame's back end has run.
    constexpr int kSlots = 3;
    qs::RgbdFrame slot_frame[kSlots];
    qs::FrontEndFrame slot_front[kSlots];
    std::shared_future<bool> slot_read[kSlots];  // the slot's frame was read (false: no frame)
    std::future<bool> slot_ready[kSlots];        // ... and its front end has run
    std::size_t read_count = 0;
    auto startFrontEnd = [&](int slot, std::shared_future<bool> previous_read) {
      auto read = std::make_shared<std::promise<bool>>();
      slot_read[slot] = read->get_future().share();
      slot_ready[slot] = std::async(
          o.pipelined ? std::launch::async : std::launch::deferred, [&, slot, previous_read, read] {
            bool ok = false;
            try {
              ok = (!previous_read.valid() || previous_read.get()) && read_count < total &&
                   read_timer.time("read", [&] { return source->next(slot_frame[slot]); });
            } catch (...) {  // the frames after this one are not read either
              read->set_exception(std::current_exception());
              throw;
            }
            read_count += ok;
            read->set_value(ok);
            if (ok)
              slam.frontEnd(slot_frame[slot], &slot_front[slot]);
            return ok;
          });
    };
    startFrontEnd(0, {});
    startFrontEnd(1, slot_read[0]);
    int slot = 0;
    while (slot_ready[slot].get()) {
      const int current = slot;
      slot = (slot + 1) % kSlots;
      // The slot two ahead held the previous frame, whose back end has run.
      startFrontEnd((current + 2) % kSlots, slot_read[(current + 1) % kSlots]);
      const qs::RgbdFrame& frame = slot_frame[current];
      ++frames;
      const qs::SlamFrameResult result = slam.backEnd(&slot_front[current]);
      resets += result.reset;
      if (result.reset)
        std::cerr << "\nrun_bag: time went backwards at " << frame.stamp << ": reset\n";
      if (!result.processed) {
        std::cerr << "\nrun_bag: skipping frame " << frame.stamp << ": " << result.message << "\n";
        ++skipped;
        continue;
      }
      for (const qs::QuadricMeasurement& m : result.measurements.observations)
        ++observations_per_class[qs::toString(m.quadric_camera.quadricClass())];
      {
        const qs::MapperFrameResult& mapped = result.mapping;
        frames_csv << frames << ',' << std::fixed << std::setprecision(6) << frame.stamp << ','
                   << (result.tracking ? qs::toString(result.odometry.status) : "uninitialised")
                   << ',' << std::setprecision(3) << result.odometry_ms << ',' << result.mapping_ms
                   << ',' << 1e3 * mapped.association_seconds << ','
                   << 1e3 * mapped.optimisation_seconds << ',' << 1e3 * mapped.merge_seconds << ','
                   << (result.mapped && mapped.keyframe ? 1 : 0) << ','
                   << slam.mapper().map().landmarks().size() << ',' << mapped.window.keyframes
                   << ',' << mapped.window.residuals << '\n';
      }
      ++status_counts[static_cast<int>(result.odometry.status)];
      frames_recovering += result.recovering ? 1 : 0;
      if (result.tracking) {
        odom_trajectory.append({frame.stamp, result.odometry.T_odom_camera});
        if (o.odometry_only)
          slam_trajectory.append({frame.stamp, result.odometry.T_odom_camera});
      }
      if (result.mapped) {
        slam_trajectory.append({frame.stamp, result.mapping.T_map_camera});
        keyframes += result.mapping.keyframe;
        joined += result.mapping.update.joined.size();
        merged_online += result.mapping.merges.size();
        for (const qs::MeasurementResult& m : result.mapping.update.measurements)
          ++outcomes[m.landmark_association.outcome];
      } else if (!o.odometry_only && result.tracking)
        std::cerr << "\nrun_bag: frame " << frame.stamp << ": " << result.message << "\n";
      if (frames % o.sample_every == 0 || frames == total) {
        const auto now = std::chrono::steady_clock::now();
        const std::size_t in_interval =
            frames % o.sample_every == 0 ? o.sample_every : frames % o.sample_every;
        resources << frames << ',' << std::fixed << std::setprecision(6) << frame.stamp << ','
                  << std::setprecision(3) << std::chrono::duration<double>(now - start).count()
                  << ',' << qs::residentMemoryBytes() / 1048576.0 << ','
                  << std::chrono::duration<double, std::milli>(now - last_sample).count() /
                         in_interval
                  << ',' << slam.mapper().map().landmarks().size() << ','
                  << slam.mapper().map().candidates().size() << ',' << slam.reconstruction().size()
                  << ',' << qs::heapUsage().in_use / 1048576.0
                  << std::endl;  // flushed: the curve can be watched during a long run
        last_sample = now;
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

    qs::StageTimer timer = slam.timer();
    timer.merge(read_timer);
    std::ofstream(o.out_dir + "/timing.json") << timer.json(frames, wall_s);

    std::printf("frames %zu\nskipped %zu\nwall_s %.3f\nfps %.2f\n", frames, skipped, wall_s,
                frames / std::max(wall_s, 1e-9));
    std::printf("tracking ok %d degenerate %d lost %d\n", status_counts[0], status_counts[1],
                status_counts[2]);
    if (!o.odometry_only) {
      std::printf(
          "mapping after losses: lost %d times, recovered %d, gave up %d, frames localising only "
          "%zu, relocalised %d of %d attempts\n",
          slam.recovery().losses(), slam.recovery().recoveries(), slam.recovery().timeouts(),
          frames_recovering, slam.recovery().relocalisations(),
          slam.recovery().relocalisationAttempts());
      std::printf("observations per frame:");
      for (const auto& [name, count] : observations_per_class)
        std::printf(" %s %.2f", name.c_str(),
                    static_cast<double>(count) / std::max<std::size_t>(frames, 1));
      std::printf("\n");
    }
    std::fputs(timer.table().c_str(), stdout);
    std::printf(
        "trajectory %s/trajectory.txt\ntrajectory_odom %s/trajectory_odom.txt\n"
        "timing %s/timing.json\nresources %s/resources.csv\n",
        o.out_dir.c_str(), o.out_dir.c_str(), o.out_dir.c_str(), o.out_dir.c_str());
    if (!o.odometry_only) {
      // Each surface once (mapping/landmark_merger.h): duplicates left by the online merging, the
      // merge before saving, and none left after it.
      const qs::LandmarkMerger& merger = slam.mapper().map().merger();
      const std::size_t duplicates_online =
          merger.findDuplicates(slam.mapper().map().landmarks()).size();
      const std::size_t merged_at_save = slam.mergeDuplicateLandmarks().size();
      const std::size_t duplicates_saved =
          merger.findDuplicates(slam.mapper().map().landmarks()).size();
      std::printf("keyframes %zu (%.1f%% of frames)\n", keyframes,
                  100.0 * keyframes / std::max<std::size_t>(frames, 1));
      std::printf(
          "landmark association: matched %zu taken_by_better %zu no_overlap %zu "
          "outside_gate %zu no_target %zu\n",
          outcomes[qs::AssociationOutcome::kMatched],
          outcomes[qs::AssociationOutcome::kTakenByBetter],
          outcomes[qs::AssociationOutcome::kNoOverlap],
          outcomes[qs::AssociationOutcome::kOutsideGate],
          outcomes[qs::AssociationOutcome::kNoTargetOfClass]);
      std::printf(
          "candidates joined at promotion %zu, landmarks merged online %zu, duplicate pairs "
          "left %zu, merged at save %zu, duplicate pairs saved %zu\n",
          joined, merged_online, duplicates_online, merged_at_save, duplicates_saved);
      // Saved maps say which ids were merged into which (the online ones, then the batch's).
      std::vector<qs::QuadricLandmark> landmarks = slam.mapper().landmarks();
      std::map<int, int> merged_into = slam.mapper().map().mergedInto();
      std::vector<qs::LandmarkMerge> batch_merges;
      if (batch) {
        qs::writeMapYaml(qs::mapFileFromLandmarks(landmarks, "map", merged_into),
                         o.out_dir + "/map_online.yaml");
        landmarks = refineOffline(slam, resets, o.out_dir, &batch_merges);
        for (const qs::LandmarkMerge& merge : batch_merges)
          qs::recordMerge(merge.merged_id, merge.survivor_id, &merged_into);
      }
      qs::writeMapYaml(qs::mapFileFromLandmarks(landmarks, "map", merged_into),
                       o.out_dir + "/map.yaml");
      std::map<std::string, int> per_class;
      for (const qs::QuadricLandmark& landmark : landmarks)
        ++per_class[qs::toString(landmark.quadric_map.quadricClass())];
      // The same points and colours as the mapping nodelet's reconstruction topic.
      std_msgs::Header header;
      header.frame_id = "map";
      pcl::PointCloud<pcl::PointXYZRGBL> points;
      // The points on their landmarks' final surfaces (refined ones after the batch refinement).
      std::map<int, qs::QuadricModel> surfaces;
      for (const qs::QuadricLandmark& landmark : landmarks)
        surfaces[landmark.id] = landmark.quadric_map;
      // The points of landmarks the batch merged go to their survivors.
      qs::QuadricReconstruction reconstruction = slam.reconstruction();
      qs::applyMergesToReconstruction(batch_merges, &reconstruction);
      pcl::fromROSMsg(qs::reconstructionCloudMsg(reconstruction.cloud(surfaces), header), points);
      if (!points.empty())
        pcl::io::savePCDFileBinary(o.out_dir + "/reconstruction.pcd", points);
      std::printf("map landmarks %zu:", landmarks.size());
      for (const auto& [name, count] : per_class)
        std::printf(" %s %d", name.c_str(), count);
      std::printf("\nreconstruction points %zu\n", points.size());
      std::printf("map %s/map.yaml\n", o.out_dir.c_str());
    }
    if (!o.gt_path.empty()) {
      printTrajectoryErrors(o.gt_path, qs::readTumTrajectory(odom_trajectory.path()));
      if (!o.odometry_only)
        printTrajectoryErrors(o.gt_path, qs::readTumTrajectory(o.out_dir + "/trajectory.txt"),
                              "map_");
      if (batch)
        printTrajectoryErrors(o.gt_path, qs::readTumTrajectory(slam_trajectory.path()),
                              "online_map_");
    }
  } catch (const std::exception& e) {
    std::cerr << "\nrun_bag: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
