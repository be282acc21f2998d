// segment: one frame -> quadric observations, with the same core classes the nodelet uses.
//
//   segment INPUT --out DIR [--intrinsics fx,fy,cx,cy] [--depth-scale UNITS_PER_M]
//           [--config segmentation.yaml] [--set KEY=VALUE]...
//
// INPUT is a 16-bit depth PNG (back-projected with --intrinsics, default the ROS Kinect defaults
// 525,525,319.5,239.5, and --depth-scale units per metre, default 5000) or an organized PCD (x y z
// fields). Normals come from the project's NormalEstimator (default parameters). Writes
//   DIR/observations.yaml  each observation's label, class, num_points, fit_rms and the map
//                          schema's `shape` block, in the camera frame
//   DIR/labels.png         16-bit, the input's size, 0 = unassigned, else the observation's label
//   DIR/segmentation.png   a colour per segment
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/io/segmentation_input.h"
#include "quadric_slam/pipeline/segmenter_params.h"

namespace qs = quadric_slam;

namespace {

int usage() {
  std::fprintf(
      stderr,
      "usage: segment INPUT(.png|.pcd) --out DIR [--intrinsics fx,fy,cx,cy] "
      "[--depth-scale UNITS_PER_M (5000)] [--config segmentation.yaml] [--set KEY=VALUE]...\n");
  return 2;
}

std::string observationsYaml(const qs::Segmentation& segmentation) {
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "frame_id" << YAML::Value << "camera";
  out << YAML::Key << "observations" << YAML::Value << YAML::BeginSeq;
  for (const qs::QuadricDetection& d : segmentation.detections) {
    out << YAML::BeginMap;
    out << YAML::Key << "label" << YAML::Value << d.label;
    out << YAML::Key << "class" << YAML::Value << qs::toString(d.shape.quadric_class);
    out << YAML::Key << "num_points" << YAML::Value << d.num_points;
    out << YAML::Key << "fit_rms" << YAML::Value << d.fit_rms;
    out << YAML::Key << "shape" << YAML::Value << YAML::BeginMap;
    for (const auto& [key, values] : d.shape.schemaShape()) {
      out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
      for (double v : values)
        out << v;
      out << YAML::EndSeq;
    }
    out << YAML::EndMap << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2)
    return usage();
  const std::string input = argv[1];
  if (input == "--help" || input == "-h")
    return usage();
  std::string out_dir;
  qs::CameraIntrinsics intrinsics;  // ROS default intrinsics of the Kinect, as in TUM bags
  intrinsics.fx = intrinsics.fy = 525.0;
  intrinsics.cx = 319.5;
  intrinsics.cy = 239.5;
  double units_per_metre = 5000.0;
  std::string config;
  std::vector<std::pair<std::string, double>> overrides;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 >= argc)
      return usage();
    const std::string value = argv[++i];
    if (arg == "--out") {
      out_dir = value;
    } else if (arg == "--intrinsics") {
      if (!qs::parseIntrinsics(value, intrinsics))
        return usage();
    } else if (arg == "--depth-scale") {
      units_per_metre = std::atof(value.c_str());
    } else if (arg == "--config") {
      config = value;
    } else if (arg == "--set") {
      const std::size_t eq = value.find('=');
      if (eq == std::string::npos)
        return usage();
      overrides.emplace_back(value.substr(0, eq), std::atof(value.c_str() + eq + 1));
    } else {
      return usage();
    }
  }
  if (out_dir.empty() || !(units_per_metre > 0))
    return usage();

  try {
    const pcl::PointCloud<pcl::PointXYZ> cloud =
        qs::loadOrganizedCloud(input, intrinsics, units_per_metre);
    const qs::NormalEstimator estimator{qs::NormalEstimator::Params()};
    qs::QuadricSegmenter::Params params =
        config.empty() ? qs::QuadricSegmenter::Params() : qs::loadSegmenterParams(config);
    for (const auto& [key, value] : overrides)
      qs::setSegmenterParam(params, key, value);
    const qs::QuadricSegmenter segmenter(params);
    const auto t0 = std::chrono::steady_clock::now();
    const pcl::PointCloud<pcl::PointNormal> with_normals = estimator.compute(cloud);
    const auto t1 = std::chrono::steady_clock::now();
    const qs::Segmentation segmentation = segmenter.segment(with_normals);
    const auto t2 = std::chrono::steady_clock::now();

    std::filesystem::create_directories(out_dir);
    const std::string yaml_file = out_dir + "/observations.yaml";
    std::ofstream(yaml_file) << observationsYaml(segmentation);
    if (!cv::imwrite(out_dir + "/labels.png", segmentation.labels))
      throw std::runtime_error("cannot write " + out_dir + "/labels.png");
    cv::Mat bgr;
    cv::cvtColor(qs::colouriseLabels(segmentation.labels), bgr, cv::COLOR_RGB2BGR);
    if (!cv::imwrite(out_dir + "/segmentation.png", bgr))
      throw std::runtime_error("cannot write " + out_dir + "/segmentation.png");

    using ms = std::chrono::duration<double, std::milli>;
    const qs::SegmentationTimings& t = segmentation.timings;
    std::printf(
        "segment: %s: %zu observations (normals %.1f ms, segmentation %.1f ms: planes %.1f, "
        "ransac %.1f on %d points -> %d candidates, verification %.1f)\n",
        input.c_str(), segmentation.detections.size(), ms(t1 - t0).count(), ms(t2 - t1).count(),
        t.planes_ms, t.ransac_ms, t.ransac_points, t.ransac_candidates, t.verify_ms);
    for (const qs::QuadricDetection& d : segmentation.detections) {
      std::printf("  label %u %-8s points %6d rms %.4f m shape", d.label,
                  qs::toString(d.shape.quadric_class).c_str(), d.num_points, d.fit_rms);
      for (double v : d.shape.shapeVector())
        std::printf(" %.4f", v);
      std::printf("\n");
    }
    std::printf("wrote %s, labels.png, segmentation.png\n", yaml_file.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "segment: %s\n", e.what());
    return 1;
  }
  return 0;
}
