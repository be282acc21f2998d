// measure_depth_noise: the depth error of a structured-light sensor measured on the large planar
// surfaces of real (or synthetic) depth frames, beside the simulator's depth models.
//
// Per frame, planes are found by RANSAC (PCL SACSegmentation) on a sub-sampled cloud, then every
// pixel near each plane is refitted robustly in disparity space, where a plane is exactly linear
// in the normalised image coordinates (d = f b / z = a + b x + c y) and Kinect noise is roughly
// range-independent. From the residuals:
//   - per 0.5 m band of depth: the depth residual std (plain and 1.4826 MAD) beside the models;
//   - the low-frequency systematic residual against image position: a coarse grid of cells and a
//     radial profile, each scaled to its size at 3 m (depth error = z^2 / (f b) * disparity error);
//   - the radial disparity distortion D(r) = k2 r^2 + k4 r^4 (r = 1 at the image corners) fitted
//     jointly over all planes (each plane's own [1, x, y] projected out);
//   - the spatial autocorrelation of the residual along rows and columns (after removing D(r)).
//
//   measure_depth_noise [--units-per-metre U (5000)] [--intrinsics fx,fy,cx,cy]
//                       [--stride K (1)] [--max-frames N] [--min-pixels P (15000)] PATH...
// PATH: a depth PNG, or a folder of them (a TUM folder's depth/ is used when present). Without
// --intrinsics, TUM intrinsics are chosen from the path (fr1/fr2/fr3, else 525, 525, 319.5, 239.5).
#include <pcl/ModelCoefficients.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "quadric_slam/io/tum_folder_reader.h"
#include "quadric_slam/sim/kinect_depth_model.h"

namespace qs = quadric_slam;
namespace fs = std::filesystem;

namespace {

constexpr double kFocalBaseline = 580.0 * 0.075;  // nominal Kinect v1 f b (px m)
constexpr double kBandWidth = 0.5;                // m
constexpr int kBands = 10;                        // 0 .. 5 m
constexpr int kGridCols = 8, kGridRows = 6;       // 80 x 80 px cells at 640 x 480
constexpr int kRadialBins = 10;
constexpr int kMaxLag = 12;

struct Options {
  double units_per_metre = 5000.0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int stride = 1, max_frames = 1 << 30, min_pixels = 15000;
  std::vector<std::string> paths;
};

double median(std::vector<double> v) {
  if (v.empty())
    return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

struct Accumulator {
  // Per band of plane depth: depth residuals (m).
  std::vector<std::vector<double>> band_residuals = std::vector<std::vector<double>>(kBands);
  // Residual scaled to 3 m, per grid cell and radial bin: sum and count.
  std::vector<double> cell_sum = std::vector<double>(kGridCols * kGridRows, 0.0);
  std::vector<long> cell_count = std::vector<long>(kGridCols * kGridRows, 0);
  std::vector<double> radial_sum = std::vector<double>(kRadialBins, 0.0);
  std::vector<long> radial_count = std::vector<long>(kRadialBins, 0);
  // Normal equations of the pooled radial distortion fit (Frisch-Waugh-Lovell).
  Eigen::Matrix2d ata = Eigen::Matrix2d::Zero();
  Eigen::Vector2d atb = Eigen::Vector2d::Zero();
  // Autocorrelation sums of disparity residuals at lags 0..kMaxLag along rows / columns.
  std::vector<double> row_prod = std::vector<double>(kMaxLag + 1, 0.0);
  std::vector<long> row_n = std::vector<long>(kMaxLag + 1, 0);
  std::vector<double> col_prod = std::vector<double>(kMaxLag + 1, 0.0);
  std::vector<long> col_n = std::vector<long>(kMaxLag + 1, 0);
  int frames = 0, planes = 0;
  long pixels = 0, valid = 0, total = 0;
};

struct Pixel {
  int u, v;
  double x, y, z, r;  // normalised image coordinates, depth (m), radius (1 at the corners)
};

// Robust least squares d = A p: iteratively drops rows beyond 3.5 robust sigmas. Returns the
// inlier mask; p the solution.
std::vector<char> robustFit(const Eigen::MatrixXd& A, const Eigen::VectorXd& d,
                            Eigen::VectorXd* p) {
  std::vector<char> keep(d.size(), 1);
  for (int iter = 0; iter < 5; ++iter) {
    std::vector<int> rows;
    for (int i = 0; i < d.size(); ++i)
      if (keep[i])
        rows.push_back(i);
    Eigen::MatrixXd Ak(rows.size(), A.cols());
    Eigen::VectorXd dk(rows.size());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      Ak.row(k) = A.row(rows[k]);
      dk(k) = d(rows[k]);
    }
    *p = (Ak.transpose() * Ak).ldlt().solve(Ak.transpose() * dk);
    const Eigen::VectorXd res = d - A * *p;
    std::vector<double> abs_res;
    for (int i : rows)
      abs_res.push_back(std::abs(res(i)));
    const double sigma = 1.4826 * median(abs_res);
    for (int i = 0; i < d.size(); ++i)
      keep[i] = std::abs(res(i)) <= 3.5 * sigma;
  }
  return keep;
}

void analysePlane(const std::vector<Pixel>& px, int width, int height, Accumulator* acc) {
  const int n = static_cast<int>(px.size());
  Eigen::MatrixXd A(n, 3), R(n, 2);
  Eigen::VectorXd d(n);
  for (int i = 0; i < n; ++i) {
    A.row(i) << 1.0, px[i].x, px[i].y;
    R.row(i) << px[i].r * px[i].r, std::pow(px[i].r, 4);
    d(i) = kFocalBaseline / px[i].z;
  }
  Eigen::VectorXd p;
  const std::vector<char> keep = robustFit(A, d, &p);
  std::vector<int> rows;
  for (int i = 0; i < n; ++i)
    if (keep[i])
      rows.push_back(i);
  if (static_cast<int>(rows.size()) < n / 2)
    return;
  ++acc->planes;
  acc->pixels += rows.size();
  // Residuals of the plane-only fit; and r^2, r^4 with [1, x, y] projected out on these pixels.
  Eigen::MatrixXd Ak(rows.size(), 3), Rk(rows.size(), 2);
  Eigen::VectorXd ek(rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    Ak.row(k) = A.row(rows[k]);
    Rk.row(k) = R.row(rows[k]);
    ek(k) = d(rows[k]) - A.row(rows[k]).dot(p);
  }
  const Eigen::MatrixXd Rperp = Rk - Ak * (Ak.transpose() * Ak).ldlt().solve(Ak.transpose() * Rk);
  acc->ata += Rperp.transpose() * Rperp;
  acc->atb += Rperp.transpose() * ek;

  cv::Mat residual_image(height, width, CV_64FC1, cv::Scalar(NAN));
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const Pixel& q = px[rows[k]];
    const double d_plane = A.row(rows[k]).dot(p);
    const double z_plane = kFocalBaseline / d_plane;
    const double z_residual = q.z - z_plane;  // depth error (m)
    const int band = static_cast<int>(z_plane / kBandWidth);
    if (band >= 0 && band < kBands)
      acc->band_residuals[band].push_back(z_residual);
    // Positive: the sensor reports a larger depth than the plane. At 3 m: 9 / (f b) * (-e_d).
    const double at_3m = -ek(k) * 9.0 / kFocalBaseline;
    const int cell = (q.v * kGridRows / height) * kGridCols + q.u * kGridCols / width;
    acc->cell_sum[cell] += at_3m;
    ++acc->cell_count[cell];
    const int bin = std::min(kRadialBins - 1, static_cast<int>(q.r * kRadialBins));
    acc->radial_sum[bin] += at_3m;
    ++acc->radial_count[bin];
    residual_image.at<double>(q.v, q.u) = ek(k);
  }
  // Autocorrelation of the plane residual after removing this plane's own radial term.
  const Eigen::Vector2d k_plane = (Rperp.transpose() * Rperp).ldlt().solve(Rperp.transpose() * ek);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const Pixel& q = px[rows[k]];
    residual_image.at<double>(q.v, q.u) -= Rperp.row(k).dot(k_plane);
  }
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const double a = residual_image.at<double>(v, u);
      if (std::isnan(a))
        continue;
      for (int lag = 0; lag <= kMaxLag; ++lag) {
        if (u + lag < width) {
          const double b = residual_image.at<double>(v, u + lag);
          if (!std::isnan(b)) {
            acc->row_prod[lag] += a * b;
            ++acc->row_n[lag];
          }
        }
        if (v + lag < height) {
          const double b = residual_image.at<double>(v + lag, u);
          if (!std::isnan(b)) {
            acc->col_prod[lag] += a * b;
            ++acc->col_n[lag];
          }
        }
      }
    }
  }
}

void analyseFrame(const cv::Mat& depth_raw, const Options& o, double fx, double fy, double cx,
                  double cy, Accumulator* acc) {
  const int width = depth_raw.cols, height = depth_raw.rows;
  const double r_norm = std::hypot(std::max(cx, width - 1 - cx), std::max(cy, height - 1 - cy));
  cv::Mat z(height, width, CV_64FC1);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const double value = depth_raw.at<std::uint16_t>(v, u) / o.units_per_metre;
      z.at<double>(v, u) = value > 0.4 && value < 5.5 ? value : NAN;
      acc->valid += value > 0.0;
      ++acc->total;
    }
  }
  // RANSAC on every second pixel.
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (int v = 0; v < height; v += 2) {
    for (int u = 0; u < width; u += 2) {
      const double d = z.at<double>(v, u);
      if (!std::isnan(d))
        cloud->push_back(pcl::PointXYZ((u - cx) / fx * d, (v - cy) / fy * d, d));
    }
  }
  pcl::SACSegmentation<pcl::PointXYZ> sac;
  sac.setModelType(pcl::SACMODEL_PLANE);
  sac.setMethodType(pcl::SAC_RANSAC);
  sac.setDistanceThreshold(0.03);
  sac.setMaxIterations(500);
  ++acc->frames;
  for (int plane = 0; plane < 8 && cloud->size() > static_cast<std::size_t>(o.min_pixels / 4);
       ++plane) {
    pcl::ModelCoefficients coefficients;
    pcl::PointIndices inliers;
    sac.setInputCloud(cloud);
    sac.segment(inliers, coefficients);
    if (inliers.indices.size() < static_cast<std::size_t>(o.min_pixels / 4))
      break;
    const Eigen::Vector3d normal(coefficients.values[0], coefficients.values[1],
                                 coefficients.values[2]);
    const double offset = coefficients.values[3];
    // Full-resolution pixels near the plane along their ray, seen at less than 70 deg incidence.
    cv::Mat near(height, width, CV_8UC1, cv::Scalar(0));
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        const double d = z.at<double>(v, u);
        if (std::isnan(d))
          continue;
        const Eigen::Vector3d ray((u - cx) / fx, (v - cy) / fy, 1.0);
        const double denom = normal.dot(ray);
        if (std::abs(denom) < 1e-6)
          continue;
        const double z_plane = -offset / denom;
        if (std::abs(denom) / ray.norm() < 0.34 || !(z_plane > 0.0))
          continue;
        const double tolerance = std::max(0.01, 0.006 * z_plane * z_plane);
        if (std::abs(d - z_plane) <= tolerance)
          near.at<std::uint8_t>(v, u) = 1;
      }
    }
    // Only cells of kCell x kCell pixels whose valid pixels nearly all lie on the plane, and of
    // those the largest 4-connected group: no object borders, no distant coplanar clutter.
    constexpr int kCell = 16;
    const int cells_u = width / kCell, cells_v = height / kCell;
    cv::Mat cell_ok(cells_v, cells_u, CV_8UC1, cv::Scalar(0));
    for (int cv_ = 0; cv_ < cells_v; ++cv_) {
      for (int cu = 0; cu < cells_u; ++cu) {
        int on = 0, valid = 0;
        for (int v = cv_ * kCell; v < (cv_ + 1) * kCell; ++v) {
          for (int u = cu * kCell; u < (cu + 1) * kCell; ++u) {
            valid += !std::isnan(z.at<double>(v, u));
            on += near.at<std::uint8_t>(v, u);
          }
        }
        cell_ok.at<std::uint8_t>(cv_, cu) = valid >= kCell * kCell / 2 && on >= 0.95 * valid;
      }
    }
    cv::Mat components;
    const int count = cv::connectedComponents(cell_ok, components, 4, CV_32S);
    std::vector<int> size(count, 0);
    for (int i = 0; i < cells_v * cells_u; ++i)
      ++size[components.at<int>(i / cells_u, i % cells_u)];
    int best = 0;
    for (int c = 1; c < count; ++c)
      if (best == 0 || size[c] > size[best])
        best = c;
    std::vector<Pixel> pixels;
    for (int v = 0; best > 0 && v < cells_v * kCell; ++v) {
      for (int u = 0; u < cells_u * kCell; ++u) {
        if (components.at<int>(v / kCell, u / kCell) != best || !near.at<std::uint8_t>(v, u))
          continue;
        const double r = std::hypot(u - cx, v - cy) / r_norm;
        pixels.push_back({u, v, (u - cx) / fx, (v - cy) / fy, z.at<double>(v, u), r});
      }
    }
    if (static_cast<int>(pixels.size()) >= o.min_pixels)
      analysePlane(pixels, width, height, acc);
    // Remove this plane's RANSAC inliers and go on.
    pcl::PointCloud<pcl::PointXYZ>::Ptr rest(new pcl::PointCloud<pcl::PointXYZ>);
    std::vector<char> taken(cloud->size(), 0);
    for (int i : inliers.indices)
      taken[i] = 1;
    for (std::size_t i = 0; i < cloud->size(); ++i)
      if (!taken[i])
        rest->push_back((*cloud)[i]);
    cloud = rest;
  }
}

std::vector<std::string> depthFiles(const std::string& path) {
  std::vector<std::string> files;
  if (fs::is_regular_file(path))
    return {path};
  fs::path folder = path;
  if (fs::is_directory(folder / "depth"))
    folder /= "depth";
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".png" && name.find("rgb") == std::string::npos)
      files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

void printReport(const Accumulator& acc) {
  qs::KinectDepthModel::Params nguyen_params = qs::KinectDepthModel::nguyenParams();
  const qs::KinectDepthModel nguyen(nguyen_params), harsh;
  std::printf("frames %d, planes %d, plane pixels %ld, valid depth %.1f%%\n", acc.frames,
              acc.planes, acc.pixels, 100.0 * acc.valid / std::max(1L, acc.total));
  std::printf("\nDepth residual of the plane fits per band of depth (cm):\n");
  std::printf("  %-9s %9s %8s %8s %9s %8s %9s\n", "band (m)", "pixels", "std", "MAD-std", "nguyen",
              "harsh", "std/nguyen");
  for (int b = 0; b < kBands; ++b) {
    const std::vector<double>& r = acc.band_residuals[b];
    if (r.size() < 2000)
      continue;
    double sum = 0, sum2 = 0;
    for (double x : r)
      sum += x, sum2 += x * x;
    const double mean = sum / r.size();
    const double std = std::sqrt(std::max(0.0, sum2 / r.size() - mean * mean));
    std::vector<double> abs_dev;
    for (double x : r)
      abs_dev.push_back(std::abs(x - mean));
    const double mad = 1.4826 * median(abs_dev);
    const double zc = (b + 0.5) * kBandWidth;
    std::printf("  %.1f-%.1f   %9zu %8.2f %8.2f %9.2f %8.2f %9.2f\n", b * kBandWidth,
                (b + 1) * kBandWidth, r.size(), 100 * std, 100 * mad, 100 * nguyen.expectedStd(zc),
                100 * harsh.expectedStd(zc), std / nguyen.expectedStd(zc));
  }
  std::printf(
      "\nSystematic residual by image cell, scaled to 3 m (mm; + = deeper than the plane;"
      " %dx%d cells):\n",
      kGridCols, kGridRows);
  for (int row = 0; row < kGridRows; ++row) {
    std::printf("  ");
    for (int col = 0; col < kGridCols; ++col) {
      const int c = row * kGridCols + col;
      if (acc.cell_count[c] < 500)
        std::printf("%7s", "-");
      else
        std::printf("%7.1f", 1000 * acc.cell_sum[c] / acc.cell_count[c]);
    }
    std::printf("\n");
  }
  std::printf("\nRadial profile, scaled to 3 m (r = 1 at the corners):\n  r     ");
  for (int b = 0; b < kRadialBins; ++b)
    std::printf("%6.2f", (b + 0.5) / kRadialBins);
  std::printf("\n  mm    ");
  for (int b = 0; b < kRadialBins; ++b)
    std::printf("%6.1f",
                acc.radial_count[b] > 500 ? 1000 * acc.radial_sum[b] / acc.radial_count[b] : NAN);
  const Eigen::Vector2d k = acc.ata.ldlt().solve(acc.atb);
  // Disparity error D(r) = k2 r^2 + k4 r^4 (measured minus true disparity); the model's
  // distortion coefficients are of the depth excess, i.e. -D.
  std::printf(
      "\n\nRadial disparity distortion fitted over all planes (disparity px):"
      " k2 = %.4f, k4 = %.4f\n",
      k(0), k(1));
  const double corner = -(k(0) + k(1)) * 9.0 / kFocalBaseline;
  std::printf(
      "  depth excess at the corners relative to the centre: %.1f mm at 3 m"
      " (model: distortion_r2 = %.4f, distortion_r4 = %.4f)\n",
      1000 * corner, -k(0), -k(1));
  const double k2_only = acc.atb(0) / acc.ata(0, 0);
  std::printf(
      "  r^2 term alone: k2 = %.4f px, depth excess at the corners %.1f mm at 3 m"
      " (model: distortion_r2 = %.4f, distortion_r4 = 0)\n",
      k2_only, -1000 * k2_only * 9.0 / kFocalBaseline, -k2_only);
  double cell_sum2 = 0;
  int cells = 0;
  for (int c = 0; c < kGridCols * kGridRows; ++c) {
    if (acc.cell_count[c] >= 500) {
      const double m = acc.cell_sum[c] / acc.cell_count[c];
      cell_sum2 += m * m;
      ++cells;
    }
  }
  std::printf("  RMS of the cell means above: %.1f mm at 3 m over %d cells\n",
              1000 * std::sqrt(cell_sum2 / std::max(1, cells)), cells);
  std::printf("\nAutocorrelation of the residual (radial term removed), lag in pixels:\n");
  std::printf("  lag    ");
  for (int lag = 0; lag <= kMaxLag; ++lag)
    std::printf("%6d", lag);
  std::printf("\n  rows   ");
  for (int lag = 0; lag <= kMaxLag; ++lag)
    std::printf("%6.2f", acc.row_prod[lag] / acc.row_n[lag] / (acc.row_prod[0] / acc.row_n[0]));
  std::printf("\n  cols   ");
  for (int lag = 0; lag <= kMaxLag; ++lag)
    std::printf("%6.2f", acc.col_prod[lag] / acc.col_n[lag] / (acc.col_prod[0] / acc.col_n[0]));
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--units-per-metre")
      o.units_per_metre = std::atof(next().c_str());
    else if (a == "--intrinsics") {
      if (std::sscanf(next().c_str(), "%lf,%lf,%lf,%lf", &o.fx, &o.fy, &o.cx, &o.cy) != 4) {
        std::fprintf(stderr, "--intrinsics needs fx,fy,cx,cy\n");
        return 2;
      }
    } else if (a == "--stride")
      o.stride = std::max(1, std::atoi(next().c_str()));
    else if (a == "--max-frames")
      o.max_frames = std::atoi(next().c_str());
    else if (a == "--min-pixels")
      o.min_pixels = std::atoi(next().c_str());
    else if (a == "--help" || a == "-h" || a[0] == '-') {
      std::fprintf(stderr,
                   "usage: measure_depth_noise [--units-per-metre U] [--intrinsics fx,fy,cx,cy] "
                   "[--stride K] [--max-frames N] [--min-pixels P] PATH...\n");
      return a[0] == '-' && a != "--help" && a != "-h" ? 2 : 0;
    } else
      o.paths.push_back(a);
  }
  if (o.paths.empty() || !(o.units_per_metre > 0)) {
    std::fprintf(stderr, "give at least one depth PNG or folder (see --help)\n");
    return 2;
  }
  Accumulator acc;
  for (const std::string& path : o.paths) {
    const std::vector<std::string> files = depthFiles(path);
    int used = 0;
    for (std::size_t i = 0; i < files.size() && used < o.max_frames; i += o.stride, ++used) {
      const cv::Mat raw = cv::imread(files[i], cv::IMREAD_ANYDEPTH);
      if (raw.empty() || raw.type() != CV_16UC1) {
        std::fprintf(stderr, "skipping %s: not a 16-bit depth PNG\n", files[i].c_str());
        continue;
      }
      qs::CameraIntrinsics k = qs::tumIntrinsicsForSequence(files[i]);
      if (o.fx > 0)
        k.fx = o.fx, k.fy = o.fy, k.cx = o.cx, k.cy = o.cy;
      analyseFrame(raw, o, k.fx, k.fy, k.cx, k.cy, &acc);
    }
  }
  printReport(acc);
  return 0;
}
