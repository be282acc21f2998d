// warp_odometry_bench: odometry on real depth frames under known motions. Each real frame (TUM
// depth PNG) is the keyframe; the same frame seen from a camera moved by a known motion
// (sim/depth_warp.h: re-projected with a z-buffer, so occlusions and disoccluded holes appear, no
// fill) is the current frame. Both go through the pipeline's front-end (QuadricSlam: normals,
// quadric segmentation, odometry with the quadric motion guess, config/*.yaml) with nothing known
// about the motion (the constant-velocity prior is the identity after the first frame). The
// estimated motion is compared with the known one.
//
// Motions: for every step size s in --steps (default 5 10 15 20 25 30), --motions-per-step
// motions of s cm along a random direction combined with a turn of s degrees about a random axis
// (seeded: the same motions with and without --no-guess).
//
// Per step size: recovered (status ok and error < 2 cm and < 2 deg), ok but wrong (status ok and
// error > 5 cm or > 5 deg: the dishonest case), degenerate, lost (shares of the trials), median
// translation / rotation error over all trials (a lost frame keeps the keyframe's pose, so its
// error is the whole motion), median odometry time. Also the quadric motion guess alone, timed per
// call on the trials' observations (QuadricMotionGuesser::guess, keyframe vs warped frame).
//
//   warp_odometry_bench [--frame PNG]... [--intrinsics fx,fy,cx,cy] [--config DIR] [--out DIR]
//                       [--steps "5 10 ..."] [--motions-per-step N] [--seed N] [--no-guess]
//                       [--no-noise] [--quiet]
//   --frame PNG: a TUM depth PNG (5000 units per metre), repeatable; intrinsics from the name of
//     its folder (fr1/fr2/fr3, see io/tum_folder_reader.h) unless --intrinsics. Default: the depth
//     frames of ../shared/data/tum_frames (fr1_xyz, fr2_desk, fr3_long_office_household).
//   --no-noise: the warped frame without fresh depth noise (default: Kinect v1 axial noise after
//     Nguyen et al. 2012 is added, as a second measurement of the surface would have).
//   --out DIR: writes DIR/trials.csv (one row per trial), DIR/summary.csv and DIR/summary.md.
// Prints the Markdown table.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/tum_folder_reader.h"
#include "quadric_slam/odometry/quadric_motion_guess.h"
#include "quadric_slam/pipeline/quadric_slam.h"
#include "quadric_slam/sim/depth_warp.h"

namespace qs = quadric_slam;
namespace fs = std::filesystem;

namespace {

// Recovered: ok within these; dishonest: ok beyond the wrong-pose limits.
constexpr double kRecoveredTranslation = 0.02, kRecoveredRotationDeg = 2.0;
constexpr double kWrongTranslation = 0.05, kWrongRotationDeg = 5.0;
constexpr double kFrameInterval = 1.0 / 30.0;  // s between keyframe and warped frame stamps

struct Options {
  std::vector<std::string> frames;
  qs::CameraIntrinsics intrinsics;  // fx = 0: from the folder name
  std::string config_dir = QUADRIC_SLAM_CONFIG_DIR;
  std::string out_dir;
  std::vector<int> steps = {5, 10, 15, 20, 25, 30};
  int motions_per_step = 4;
  unsigned seed = 1;
  bool guess = true;
  bool quiet = false;
  bool depth_noise = true;  // fresh axial noise on the warped frame (a second measurement)
};

void usage() {
  std::cerr << "usage: warp_odometry_bench [--frame PNG]... [--intrinsics fx,fy,cx,cy] "
               "[--config DIR] [--out DIR]\n"
               "       [--steps \"5 10 15 20 25 30\"] [--motions-per-step N] [--seed N] "
               "[--no-guess] [--no-noise] [--quiet]\n";
}

std::vector<std::string> defaultFrames() {
  const fs::path root = fs::path(QUADRIC_SLAM_SHARED_DATA_DIR) / "tum_frames";
  return {(root / "fr1_xyz/1305031102.160407.png").string(),
          (root / "fr1_xyz/1305031102.262886.png").string(),
          (root / "fr2_desk/a_depth.png").string(),
          (root / "fr2_desk/b_depth.png").string(),
          (root / "fr3_long_office_household/1341847980.723020.png").string(),
          (root / "fr3_long_office_household/1341847982.998830.png").string()};
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc)
        throw std::invalid_argument(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--frame") {
      o.frames.push_back(value());
    } else if (arg == "--intrinsics") {
      if (!qs::parseIntrinsics(value(), o.intrinsics))
        throw std::invalid_argument("--intrinsics must be fx,fy,cx,cy");
    } else if (arg == "--config") {
      o.config_dir = value();
    } else if (arg == "--out") {
      o.out_dir = value();
    } else if (arg == "--steps") {
      std::istringstream in(value());
      o.steps.clear();
      for (int s; in >> s;) {
        if (s < 1 || s > 90)
          throw std::invalid_argument("--steps: each step must be in [1, 90] (cm and degrees)");
        o.steps.push_back(s);
      }
      if (o.steps.empty())
        throw std::invalid_argument("--steps needs at least one step size");
    } else if (arg == "--motions-per-step") {
      o.motions_per_step = std::stoi(value());
      if (o.motions_per_step < 1)
        throw std::invalid_argument("--motions-per-step must be >= 1");
    } else if (arg == "--seed") {
      o.seed = static_cast<unsigned>(std::stoul(value()));
    } else if (arg == "--no-noise") {
      o.depth_noise = false;
    } else if (arg == "--no-guess") {
      o.guess = false;
    } else if (arg == "--quiet") {
      o.quiet = true;
    } else {
      throw std::invalid_argument("unknown option " + arg);
    }
  }
  if (o.frames.empty())
    o.frames = defaultFrames();
  return o;
}

// A motion of exactly step cm along a random direction and step degrees about a random axis,
// the same for a given (seed, frame, step, motion).
Eigen::Isometry3d knownMotion(unsigned seed, int frame, int step, int motion) {
  std::seed_seq sequence{seed, static_cast<unsigned>(frame), static_cast<unsigned>(step),
                         static_cast<unsigned>(motion)};
  std::mt19937 rng(sequence);
  std::normal_distribution<double> normal;
  auto direction = [&] {
    Eigen::Vector3d d;
    do {
      d = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    } while (d.norm() < 1e-6);
    return d.normalized();
  };
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = 0.01 * step * direction();
  T.linear() = Eigen::AngleAxisd(step * M_PI / 180.0, direction()).toRotationMatrix();
  return T;
}

struct Trial {
  std::string frame;
  int step = 0, motion = 0;
  Eigen::Isometry3d truth, estimate;
  qs::TrackingStatus status = qs::TrackingStatus::kLost;
  double translation_error = 0, rotation_error_deg = 0;
  double hole_fraction = 0;  // warped pixels without depth
  double odometry_ms = 0;
  int keyframe_observations = 0, observations = 0;
  bool guess_found = false, started_from_guess = false;
  double guess_ms = NAN;  // the quadric guess alone, median of repeated calls
  double inlier_fraction = 0;
};

double angleDeg(const Eigen::Isometry3d& T) {
  return Eigen::AngleAxisd(T.rotation()).angle() * 180.0 / M_PI;
}

bool recovered(const Trial& t) {
  return t.status == qs::TrackingStatus::kOk && t.translation_error < kRecoveredTranslation &&
         t.rotation_error_deg < kRecoveredRotationDeg;
}
bool okButWrong(const Trial& t) {
  return t.status == qs::TrackingStatus::kOk &&
         (t.translation_error > kWrongTranslation || t.rotation_error_deg > kWrongRotationDeg);
}

double median(std::vector<double> v) {
  if (v.empty())
    return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
double percentile(std::vector<double> v, double q) {
  if (v.empty())
    return NAN;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::round(q * (v.size() - 1)))];
}

// A second measurement of the surface: the warped depths carry the reference frame's noise (it
// moves with the surface), and a real second frame adds its own. Axial noise of a Kinect v1 after
// Nguyen et al. 2012: sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2 m.
void addAxialNoise(cv::Mat& depth, std::mt19937& rng) {
  std::normal_distribution<float> normal;
  for (int v = 0; v < depth.rows; ++v) {
    float* row = depth.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u) {
      if (!std::isfinite(row[u]))
        continue;
      const float z = row[u];
      row[u] = z + (0.0012f + 0.0019f * (z - 0.4f) * (z - 0.4f)) * normal(rng);
    }
  }
}

double holeFraction(const cv::Mat& depth) {
  int holes = 0;
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u)
      holes += std::isfinite(depth.at<float>(v, u)) ? 0 : 1;
  return static_cast<double>(holes) / (depth.rows * depth.cols);
}

// The guess alone on the two frames' observations: median of a few calls (ms).
double timeGuess(const qs::QuadricMotionGuesser& guesser,
                 const std::vector<qs::QuadricMeasurement>& reference,
                 const std::vector<qs::QuadricMeasurement>& current) {
  std::vector<double> ms;
  for (int repeat = 0; repeat < 5; ++repeat) {
    const auto start = std::chrono::steady_clock::now();
    const qs::QuadricMotionGuess g =
        guesser.guess(reference, current, Eigen::Isometry3d::Identity());
    const auto stop = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(stop - start).count());
    volatile bool found = g.found;  // the result is used: the call cannot be optimised away
    (void)found;
  }
  return median(ms);
}

std::vector<Trial> runFrame(const std::string& png, int frame_index, const Options& o,
                            const qs::SlamParams& params) {
  qs::RgbdFrame keyframe;
  keyframe.depth_m = qs::readTumDepthPng(png);
  keyframe.intrinsics = o.intrinsics.fx > 0 ? o.intrinsics
                                            : qs::tumIntrinsicsForSequence(
                                                  fs::path(png).parent_path().filename().string());
  keyframe.intrinsics.width = keyframe.depth_m.cols;
  keyframe.intrinsics.height = keyframe.depth_m.rows;
  keyframe.stamp = 1.0;
  keyframe.frame_id = "camera";

  // The keyframe through the pipeline once; every trial continues from a copy of that state.
  qs::QuadricSlam after_keyframe(params);
  const qs::SlamFrameResult first = after_keyframe.process(keyframe);
  if (!first.processed || !first.tracking)
    throw std::runtime_error(png + ": the keyframe was not usable: " + first.message);
  const qs::QuadricMotionGuesser guesser(params.odometry.guess);

  std::vector<Trial> trials;
  for (int step : o.steps) {
    for (int m = 0; m < o.motions_per_step; ++m) {
      Trial t;
      t.frame = fs::path(png).parent_path().filename().string() + "/" +
                fs::path(png).filename().string();
      t.step = step;
      t.motion = m;
      t.truth = knownMotion(o.seed, frame_index, step, m);
      qs::RgbdFrame current = keyframe;
      current.depth_m = qs::warpDepthImage(keyframe.depth_m, keyframe.intrinsics, t.truth);
      if (o.depth_noise) {
        std::seed_seq noise_seed{o.seed, static_cast<unsigned>(frame_index),
                                 static_cast<unsigned>(step), static_cast<unsigned>(m), 7u};
        std::mt19937 rng(noise_seed);
        addAxialNoise(current.depth_m, rng);
      }
      current.stamp = keyframe.stamp + kFrameInterval;
      t.hole_fraction = holeFraction(current.depth_m);

      qs::QuadricSlam slam = after_keyframe;
      const qs::SlamFrameResult r = slam.process(current);
      t.status = r.odometry.status;
      t.estimate = r.odometry.T_odom_camera;
      t.translation_error = (t.estimate.translation() - t.truth.translation()).norm();
      t.rotation_error_deg = angleDeg(t.truth.inverse() * t.estimate);
      // The odometry stage has run twice in this copy: on the keyframe (which only stores it) and
      // on the warped frame, by far the longer of the two.
      const auto timing = slam.timer().summaries();
      t.odometry_ms = timing.count("odometry") ? timing.at("odometry").max_ms : NAN;
      t.keyframe_observations = static_cast<int>(first.measurements.observations.size());
      t.observations = static_cast<int>(r.measurements.observations.size());
      t.guess_found = r.odometry.guess.found;
      t.started_from_guess = r.odometry.started_from_guess;
      t.inlier_fraction = r.odometry.icp.inlier_fraction;
      if (o.guess)
        t.guess_ms = timeGuess(guesser, first.measurements.observations,
                               r.measurements.observations);
      if (!o.quiet)
        std::fprintf(stderr,
                     "%s step %2d motion %d: %-10s error %6.1f cm %5.1f deg, holes %4.1f%%, "
                     "observations %d/%d%s\n",
                     t.frame.c_str(), step, m, qs::toString(t.status), 100 * t.translation_error,
                     t.rotation_error_deg, 100 * t.hole_fraction, t.keyframe_observations,
                     t.observations, t.started_from_guess ? ", from the guess" : "");
      trials.push_back(t);
    }
  }
  return trials;
}

void writeTrials(const std::string& path, const std::vector<Trial>& trials) {
  std::ofstream f(path);
  f << std::setprecision(9);
  f << "frame,step_cm_deg,motion,true_tx,true_ty,true_tz,true_angle_deg,status,"
       "translation_error_m,rotation_error_deg,recovered,ok_but_wrong,hole_fraction,"
       "keyframe_observations,observations,guess_found,started_from_guess,inlier_fraction,"
       "odometry_ms,guess_ms\n";
  for (const Trial& t : trials) {
    const Eigen::Vector3d p = t.truth.translation();
    f << t.frame << "," << t.step << "," << t.motion << "," << p.x() << "," << p.y() << ","
      << p.z() << "," << angleDeg(t.truth) << ","
      << qs::toString(t.status) << "," << t.translation_error << "," << t.rotation_error_deg
      << "," << recovered(t) << "," << okButWrong(t) << "," << t.hole_fraction << ","
      << t.keyframe_observations << "," << t.observations << "," << t.guess_found << ","
      << t.started_from_guess << "," << t.inlier_fraction << "," << t.odometry_ms << ","
      << t.guess_ms << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  qs::SlamParams params;
  try {
    o = parse(argc, argv);
    params = qs::loadSlamParams(o.config_dir);
    params.odometry.quadric_motion_guess = o.guess;
    params.validate();
  } catch (const std::exception& e) {
    std::cerr << "warp_odometry_bench: " << e.what() << "\n";
    usage();
    return 2;
  }

  std::vector<Trial> trials;
  try {
    for (std::size_t i = 0; i < o.frames.size(); ++i) {
      const std::vector<Trial> t = runFrame(o.frames[i], static_cast<int>(i), o, params);
      trials.insert(trials.end(), t.begin(), t.end());
    }
  } catch (const std::exception& e) {
    std::cerr << "warp_odometry_bench: " << e.what() << "\n";
    return 1;
  }

  std::ostringstream md, csv;
  char line[512];
  md << "Real depth frames warped by known motions (" << o.frames.size() << " frames x "
     << o.motions_per_step << " motions per step, seed " << o.seed << ", quadric guess "
     << (o.guess ? "on" : "off") << ", " << (o.depth_noise ? "fresh axial noise" : "no new noise")
     << " on the warped frame)\n\n"
     << "| step | trials | recovered | ok but wrong | degenerate | lost | median error cm | "
        "median error deg | p95 error cm | holes | started from guess | odometry ms (median) |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  csv << "step_cm_deg,trials,recovered,ok_but_wrong,degenerate,lost,median_translation_error_m,"
         "median_rotation_error_deg,p95_translation_error_m,median_hole_fraction,"
         "started_from_guess,median_odometry_ms\n";
  for (int step : o.steps) {
    std::vector<double> te, re, holes, ms;
    int n = 0, rec = 0, wrong = 0, degenerate = 0, lost = 0, from_guess = 0;
    for (const Trial& t : trials) {
      if (t.step != step)
        continue;
      ++n;
      rec += recovered(t);
      wrong += okButWrong(t);
      degenerate += t.status == qs::TrackingStatus::kDegenerate;
      lost += t.status == qs::TrackingStatus::kLost;
      from_guess += t.started_from_guess;
      te.push_back(t.translation_error);
      re.push_back(t.rotation_error_deg);
      holes.push_back(t.hole_fraction);
      ms.push_back(t.odometry_ms);
    }
    auto share = [n](int k) { return 100.0 * k / std::max(n, 1); };
    std::snprintf(line, sizeof(line),
                  "| %d cm, %d deg | %d | %.0f%% | %.0f%% | %.0f%% | %.0f%% | %.2f | %.2f | %.1f | "
                  "%.0f%% | %.0f%% | %.1f |\n",
                  step, step, n, share(rec), share(wrong), share(degenerate), share(lost),
                  100 * median(te), median(re), 100 * percentile(te, 0.95), 100 * median(holes),
                  share(from_guess), median(ms));
    md << line;
    std::snprintf(line, sizeof(line), "%d,%d,%d,%d,%d,%d,%.6f,%.4f,%.6f,%.4f,%d,%.3f\n", step, n,
                  rec, wrong, degenerate, lost, median(te), median(re), percentile(te, 0.95),
                  median(holes), from_guess, median(ms));
    csv << line;
  }
  if (o.guess) {
    std::vector<double> guess_ms;
    for (const Trial& t : trials)
      guess_ms.push_back(t.guess_ms);
    std::snprintf(line, sizeof(line),
                  "\nQuadric motion guess alone (QuadricMotionGuesser::guess, keyframe vs warped "
                  "frame observations): median %.3f ms, p95 %.3f ms, max %.3f ms per call over %zu "
                  "frame pairs\n",
                  median(guess_ms), percentile(guess_ms, 0.95), percentile(guess_ms, 1.0),
                  guess_ms.size());
    md << line;
  }
  std::cout << md.str();
  if (!o.out_dir.empty()) {
    fs::create_directories(o.out_dir);
    writeTrials(o.out_dir + "/trials.csv", trials);
    std::ofstream(o.out_dir + "/summary.csv") << csv.str();
    std::ofstream(o.out_dir + "/summary.md") << md.str();
  }
  return 0;
}
