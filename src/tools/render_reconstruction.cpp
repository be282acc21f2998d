// render_reconstruction: draws a reconstruction cloud (run_bag's DIR/reconstruction.pcd or a saved
// map's .pcd: x y z rgb label in the map frame) as a PNG seen by a virtual pinhole camera, points
// as small z-buffered squares in their rgb colour. The map frame is the first camera's optical
// frame (x right, y down, z forward), so the default view is the first frame's, moved back along
// its optical axis and up to show the surroundings.
//
//   render_reconstruction CLOUD.pcd OUT.png [--back M] [--up M] [--pitch DEG] [--size WxH]
//                         [--focal PX] [--splat PX]
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <string>

namespace {

int usage(const std::string& problem) {
  std::cerr
      << "render_reconstruction: " << problem << "\n"
      << "usage: render_reconstruction CLOUD.pcd OUT.png [--back M (0.8)] [--up M (0.3)]\n"
      << "       [--pitch DEG (10, looking down)] [--size WxH (1280x960)] [--focal PX (900)]\n"
      << "       [--splat PX (2)]\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3)
    return usage("CLOUD.pcd and OUT.png are required");
  const std::string cloud_path = argv[1], out_path = argv[2];
  double back = 0.8, up = 0.3, pitch_deg = 10.0, focal = 900.0;
  int width = 1280, height = 960, splat = 2;
  try {
    for (int i = 3; i < argc; ++i) {
      const std::string arg = argv[i];
      if (i + 1 >= argc)
        return usage(arg + " needs a value");
      const std::string value = argv[++i];
      if (arg == "--back")
        back = std::stod(value);
      else if (arg == "--up")
        up = std::stod(value);
      else if (arg == "--pitch")
        pitch_deg = std::stod(value);
      else if (arg == "--focal")
        focal = std::stod(value);
      else if (arg == "--splat")
        splat = std::stoi(value);
      else if (arg == "--size" && std::sscanf(value.c_str(), "%dx%d", &width, &height) == 2)
        continue;
      else
        return usage("bad option " + arg + " " + value);
    }
  } catch (const std::exception& e) {
    return usage(e.what());
  }
  if (width < 16 || height < 16 || width > 8192 || height > 8192 || !(focal > 0.0) || splat < 0)
    return usage("--size within 16..8192, --focal > 0, --splat >= 0");

  pcl::PointCloud<pcl::PointXYZRGBL> cloud;
  if (pcl::io::loadPCDFile(cloud_path, cloud) != 0) {
    std::cerr << "render_reconstruction: cannot read " << cloud_path << "\n";
    return 1;
  }
  // The virtual camera in the map frame: back along -z, up along -y (y points down), pitched down.
  Eigen::Isometry3d T_map_view = Eigen::Isometry3d::Identity();
  T_map_view.translation() = Eigen::Vector3d(0.0, -up, -back);
  T_map_view.linear() =
      Eigen::AngleAxisd(-pitch_deg * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Isometry3d T_view_map = T_map_view.inverse();

  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::Mat depth(height, width, CV_32FC1, cv::Scalar(std::numeric_limits<float>::infinity()));
  std::size_t drawn = 0;
  for (const pcl::PointXYZRGBL& p : cloud) {
    const Eigen::Vector3d q = T_view_map * Eigen::Vector3d(p.x, p.y, p.z);
    if (!(q.z() > 0.05))
      continue;
    const int u = static_cast<int>(std::lround(focal * q.x() / q.z() + 0.5 * width));
    const int v = static_cast<int>(std::lround(focal * q.y() / q.z() + 0.5 * height));
    const cv::Vec3b bgr(p.b, p.g, p.r);
    bool any = false;
    for (int dv = -splat; dv <= splat; ++dv)
      for (int du = -splat; du <= splat; ++du) {
        const int x = u + du, y = v + dv;
        if (x < 0 || y < 0 || x >= width || y >= height || depth.at<float>(y, x) <= q.z())
          continue;
        depth.at<float>(y, x) = static_cast<float>(q.z());
        image.at<cv::Vec3b>(y, x) = bgr;
        any = true;
      }
    drawn += any;
  }
  if (!cv::imwrite(out_path, image)) {
    std::cerr << "render_reconstruction: cannot write " << out_path << "\n";
    return 1;
  }
  std::printf("render_reconstruction: %zu of %zu points drawn into %s\n", drawn, cloud.size(),
              out_path.c_str());
  return 0;
}
