// estimate_normals: one depth PNG -> normals with the same core classes the nodelet uses; writes a
// colour-coded normal map and prints what it found.
//
//   estimate_normals DEPTH_PNG --out DIR [--intrinsics fx,fy,cx,cy] [--depth-scale UNITS_PER_M]
//                    [--method NAME]
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/frame_source.h"

namespace qs = quadric_slam;

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: estimate_normals DEPTH_PNG --out DIR [--intrinsics fx,fy,cx,cy] "
               "[--depth-scale UNITS_PER_M (5000)] [--method NAME]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2)
    return usage();
  const std::string depth_file = argv[1];
  std::string out_dir;
  qs::CameraIntrinsics intrinsics;  // ROS default intrinsics of the Kinect, as in TUM bags
  intrinsics.fx = intrinsics.fy = 525.0;
  intrinsics.cx = 319.5;
  intrinsics.cy = 239.5;
  double units_per_metre = 5000.0;
  qs::NormalEstimator::Params params;
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
    } else if (arg == "--method") {
      params.method = value;
    } else {
      return usage();
    }
  }
  if (out_dir.empty() || !(units_per_metre > 0))
    return usage();

  try {
    const cv::Mat raw = qs::readTumDepthPng(depth_file, units_per_metre);
    intrinsics.width = raw.cols;
    intrinsics.height = raw.rows;
    const qs::NormalEstimator estimator(params);
    const qs::DepthImageView<float> view = qs::depthViewOf(raw);
    const auto t0 = std::chrono::steady_clock::now();
    const auto cloud = estimator.compute(qs::backProject(view, intrinsics, {}));
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

    // Normal map: RGB = (n + 1) / 2, black where there is no normal.
    cv::Mat picture(raw.rows, raw.cols, CV_8UC3, cv::Scalar(0, 0, 0));
    std::size_t points = 0, normals = 0;
    double min_z = 1e9, max_z = 0;
    for (int v = 0; v < raw.rows; ++v) {
      for (int u = 0; u < raw.cols; ++u) {
        const pcl::PointNormal& p = cloud(u, v);
        if (!std::isfinite(p.z))
          continue;
        ++points;
        min_z = std::min<double>(min_z, p.z);
        max_z = std::max<double>(max_z, p.z);
        if (!std::isfinite(p.normal_x))
          continue;
        ++normals;
        picture.at<cv::Vec3b>(v, u) = cv::Vec3b(static_cast<uchar>(127.5 * (p.normal_z + 1)),
                                                static_cast<uchar>(127.5 * (p.normal_y + 1)),
                                                static_cast<uchar>(127.5 * (p.normal_x + 1)));
      }
    }
    std::filesystem::create_directories(out_dir);
    const std::string picture_file = out_dir + "/normals.png";
    if (!cv::imwrite(picture_file, picture)) {
      std::fprintf(stderr, "estimate_normals: cannot write %s\n", picture_file.c_str());
      return 1;
    }
    std::printf(
        "%s: %dx%d, %zu points with depth (%.2f-%.2f m), %zu normals (%.1f%%), "
        "%s %.1f ms -> %s\n",
        depth_file.c_str(), raw.cols, raw.rows, points, points ? min_z : 0.0, max_z, normals,
        100.0 * normals / (raw.cols * raw.rows), params.method.c_str(), ms, picture_file.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "estimate_normals: %s\n", e.what());
    return 1;
  }
  return 0;
}
