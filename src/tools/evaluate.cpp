// Trajectory (and map) evaluation against ground truth, as TUM's evaluate_ate.py / evaluate_rpe.py.
//   evaluate --gt GT --est EST [--map MAP --quadrics-gt QGT] [--max-difference 0.02] [--delta 1.0]
// Prints `ate_rmse_m X`, `pairs N`, `rpe_m_per_s X` (plus a few more statistics) and, with maps,
// one line per true primitive, one per class, one per class and range band (`class_range plane 0-2m
// ...`: each true surface's median distance from the true camera path, bands 0-2, 2-4, 4+ m) and a
// `map_summary ...` line. Exit 1 on bad input.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "quadric_slam/eval/map_metrics.h"
#include "quadric_slam/eval/trajectory_metrics.h"
#include "quadric_slam/io/map_yaml.h"
#include "quadric_slam/io/trajectory_io.h"

namespace {

const char* const kUsage =
    "usage: evaluate --gt GROUNDTRUTH.txt --est ESTIMATE.txt [--map MAP.yaml --quadrics-gt "
    "QUADRICS_GT.yaml]\n"
    "                [--max-difference SECONDS] [--delta SECONDS]\n"
    "  --gt              ground-truth trajectory, TUM format (timestamp tx ty tz qx qy qz qw)\n"
    "  --est             estimated trajectory, TUM format; aligned onto the ground truth (rigid, "
    "no "
    "scale)\n"
    "  --map             estimated quadric map (map schema), in the estimate's frame\n"
    "  --quadrics-gt     true quadric map (map schema, e.g. the generator's quadrics_gt.yaml), in "
    "the ground truth's frame\n"
    "  --max-difference  largest stamp difference for a pose pair, s (default 0.02, as "
    "evaluate_ate.py)\n"
    "  --delta           RPE pose-pair spacing, s (default 1.0: rpe_m_per_s is drift per second)\n";

int usageError(const std::string& message) {
  std::cerr << "evaluate: " << message << "\n" << kUsage;
  return 1;
}

bool parseSeconds(const std::string& text, double& value) {
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end != text.c_str() && *end == '\0' && std::isfinite(value) && value > 0.0;
}

void printValue(const char* name, double value) {
  std::printf("%s %.6f\n", name, value);
}

}  // namespace

int main(int argc, char** argv) {
  std::string gt_path, est_path, map_path, quadrics_gt_path;
  double max_difference = 0.02, delta = 1.0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    }
    if (i + 1 >= argc)
      return usageError("option " + arg + " needs a value (or is unknown)");
    const std::string value = argv[++i];
    if (arg == "--gt") {
      gt_path = value;
    } else if (arg == "--est") {
      est_path = value;
    } else if (arg == "--map") {
      map_path = value;
    } else if (arg == "--quadrics-gt") {
      quadrics_gt_path = value;
    } else if (arg == "--max-difference") {
      if (!parseSeconds(value, max_difference)) {
        return usageError("--max-difference needs a positive number of seconds, got '" + value +
                          "'");
      }
    } else if (arg == "--delta") {
      if (!parseSeconds(value, delta)) {
        return usageError("--delta needs a positive number of seconds, got '" + value + "'");
      }
    } else {
      return usageError("unknown option " + arg);
    }
  }
  if (gt_path.empty() || est_path.empty())
    return usageError("--gt and --est are required");
  if (map_path.empty() != quadrics_gt_path.empty()) {
    return usageError("--map and --quadrics-gt go together");
  }

  try {
    const quadric_slam::Trajectory gt = quadric_slam::readTumTrajectory(gt_path);
    const quadric_slam::Trajectory est = quadric_slam::readTumTrajectory(est_path);
    quadric_slam::AbsoluteTrajectoryError::Params ate_params;
    ate_params.association.max_difference = max_difference;
    const auto ate = quadric_slam::AbsoluteTrajectoryError(ate_params).evaluate(gt, est);
    printValue("ate_rmse_m", ate.rmse());
    std::printf("pairs %zu\n", ate.pairs());
    printValue("ate_mean_m", ate.statistics.mean);
    printValue("ate_median_m", ate.statistics.median);
    printValue("ate_max_m", ate.statistics.max);

    quadric_slam::RelativePoseError::Params rpe_params;
    rpe_params.delta = delta;
    try {
      const auto rpe = quadric_slam::RelativePoseError(rpe_params).evaluate(gt, est);
      // Per delta seconds; per second when delta = 1 s (the default).
      printValue("rpe_m_per_s", rpe.translation.rmse / delta);
      printValue("rpe_deg_per_s", rpe.rotation.rmse * 180.0 / M_PI / delta);
      std::printf("rpe_pairs %zu\n", rpe.pairs());
    } catch (const std::runtime_error& e) {
      std::cerr << "evaluate: no RPE: " << e.what() << "\n";
      std::printf("rpe_m_per_s nan\n");
    }

    if (!map_path.empty()) {
      const quadric_slam::MapFile estimate_map = quadric_slam::readMapYaml(map_path);
      const quadric_slam::MapFile truth_map = quadric_slam::readMapYaml(quadrics_gt_path);
      const quadric_slam::MapReport report =
          quadric_slam::MapEvaluator().evaluate(truth_map, estimate_map, ate.T_gt_est);
      // Accuracy per range band: each true surface's median distance from the true camera path.
      std::vector<Eigen::Vector3d> camera_positions;
      for (const auto& pose : gt)
        camera_positions.push_back(pose.T_world_sensor.translation());
      const auto by_range = quadric_slam::summariseByRange(
          report, quadric_slam::truthRanges(truth_map, camera_positions), {2.0, 4.0});
      std::fputs(quadric_slam::formatMapReport(report, &by_range).c_str(), stdout);
    }
  } catch (const std::exception& e) {
    std::cerr << "evaluate: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
