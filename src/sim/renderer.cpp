#include "quadric_slam/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

namespace quadric_slam {

void Renderer::Params::validate() const {
  if (!(ambient >= 0.0 && ambient <= 1.0))
    throw std::invalid_argument("Renderer::Params::ambient must be in [0, 1]");
  if (!(near_clip > 0.0))
    throw std::invalid_argument("Renderer::Params::near_clip must be > 0 m");
  if (threads < 1 || threads > 256)
    throw std::invalid_argument("Renderer::Params::threads must be in [1, 256]");
}

Renderer::Renderer(std::vector<Surface> surfaces, const CameraIntrinsics& camera,
                   const KinectDepthModel::Params& depth_model, const Params& params,
                   const Eigen::Vector3d& background)
    : surfaces_(std::move(surfaces)),
      camera_(camera),
      depth_model_(depth_model),
      params_(params),
      background_(background) {
  params_.validate();
  if (!camera_.valid())
    throw std::invalid_argument("Renderer: camera intrinsics: " + camera_.problem());
}

bool Renderer::pixelBox(const Eigen::Vector3d& c, double r, PixelBox* box) const {
  const int w = camera_.width, h = camera_.height;
  if (c.z() + r <= params_.near_clip)
    return false;
  if (c.z() - r <= params_.near_clip) {
    *box = {0, w - 1, 0, h - 1};
    return true;
  }
  // The sphere's shadow on the x-z (y-z) plane is a disc in front of the camera; its tangent
  // lines through the centre of projection bound x/z (y/z) exactly.
  auto range = [r](double a, double z, double* lo, double* hi) {
    const double d = std::hypot(a, z);
    const double centre = std::atan2(a, z), half = std::asin(std::min(1.0, r / d));
    *lo = std::tan(centre - half);
    *hi = std::tan(centre + half);
  };
  double x_lo, x_hi, y_lo, y_hi;
  range(c.x(), c.z(), &x_lo, &x_hi);
  range(c.y(), c.z(), &y_lo, &y_hi);
  const double u0 = std::floor(camera_.fx * x_lo + camera_.cx) - 1;
  const double u1 = std::ceil(camera_.fx * x_hi + camera_.cx) + 1;
  const double v0 = std::floor(camera_.fy * y_lo + camera_.cy) - 1;
  const double v1 = std::ceil(camera_.fy * y_hi + camera_.cy) + 1;
  if (u1 < 0 || v1 < 0 || u0 > w - 1 || v0 > h - 1)
    return false;
  box->u0 = static_cast<int>(std::max(0.0, u0));
  box->u1 = static_cast<int>(std::min<double>(w - 1, u1));
  box->v0 = static_cast<int>(std::max(0.0, v0));
  box->v1 = static_cast<int>(std::min<double>(h - 1, v1));
  return true;
}

void Renderer::castRows(const Eigen::Isometry3d& T_world_camera, const std::vector<int>& candidates,
                        const std::vector<PixelBox>& boxes, int row_begin, int row_step,
                        RenderedFrame* frame) const {
  // Per candidate surface, the camera centre and the pixel rays in the surface frame: the ray of
  // pixel (u, v) is base(v) + u * step, with unit optical z so that the ray parameter is the depth.
  struct Candidate {
    int index;
    PixelBox box;
    Eigen::Vector3d origin, step, base_u0, base_v;
  };
  std::vector<Candidate> all;
  for (int i : candidates) {
    const Eigen::Isometry3d T_surface_camera = surfaces_[i].inversePose() * T_world_camera;
    const Eigen::Matrix3d M = T_surface_camera.linear();
    Candidate c;
    c.index = i;
    c.box = boxes[i];
    c.origin = T_surface_camera.translation();
    c.step = M.col(0) / camera_.fx;
    c.base_u0 = M.col(2) - camera_.cx / camera_.fx * M.col(0);
    c.base_v = M.col(1) / camera_.fy;
    all.push_back(c);
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Eigen::Vector3d background = 255.0 * background_;
  const cv::Vec3b background_pixel(cv::saturate_cast<uchar>(background.x()),
                                   cv::saturate_cast<uchar>(background.y()),
                                   cv::saturate_cast<uchar>(background.z()));
  std::vector<Candidate> row;
  for (int v = row_begin; v < camera_.height; v += row_step) {
    row.clear();
    for (const Candidate& c : all) {
      if (v >= c.box.v0 && v <= c.box.v1) {
        row.push_back(c);
        row.back().base_u0 += (v - camera_.cy) * c.base_v;
      }
    }
    float* depth = frame->depth_true.ptr<float>(v);
    float* cosine = frame->cos_incidence.ptr<float>(v);
    cv::Vec3b* rgb = frame->rgb.ptr<cv::Vec3b>(v);
    std::uint16_t* label = frame->labels.ptr<std::uint16_t>(v);
    for (int u = 0; u < camera_.width; ++u) {
      double best = std::numeric_limits<double>::infinity();
      const Candidate* hit = nullptr;
      for (const Candidate& c : row) {
        if (u < c.box.u0 || u > c.box.u1)
          continue;
        double t;
        if (surfaces_[c.index].intersectLocal(c.origin, c.base_u0 + u * c.step, params_.near_clip,
                                              best, &t)) {
          best = t;
          hit = &c;
        }
      }
      if (!hit) {
        depth[u] = nan;
        cosine[u] = 0.0f;
        rgb[u] = background_pixel;
        label[u] = 0;
        continue;
      }
      const Surface& surface = surfaces_[hit->index];
      const Eigen::Vector3d direction = hit->base_u0 + u * hit->step;
      const Eigen::Vector3d point = hit->origin + best * direction;
      const Eigen::Vector3d normal = surface.normalLocal(point);
      const double c = std::abs(normal.dot(direction)) / (normal.norm() * direction.norm());
      depth[u] = static_cast<float>(best);
      cosine[u] = static_cast<float>(c);
      const Eigen::Vector3d colour =
          255.0 * (params_.ambient + (1.0 - params_.ambient) * c) * surface.albedo(point);
      rgb[u] = cv::Vec3b(cv::saturate_cast<uchar>(colour.x()), cv::saturate_cast<uchar>(colour.y()),
                         cv::saturate_cast<uchar>(colour.z()));
      label[u] = static_cast<std::uint16_t>(surface.id());
    }
  }
}

RenderedFrame Renderer::render(const Eigen::Isometry3d& T_world_camera, std::uint64_t seed) const {
  RenderedFrame frame;
  const cv::Size size(camera_.width, camera_.height);
  frame.depth_true.create(size, CV_32FC1);
  frame.cos_incidence.create(size, CV_32FC1);
  frame.rgb.create(size, CV_8UC3);
  frame.labels.create(size, CV_16UC1);

  // Bounding-volume early-out: only surfaces whose bounding sphere projects into the image are
  // tested, and only inside their pixel box.
  const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
  std::vector<PixelBox> boxes(surfaces_.size());
  std::vector<int> candidates;
  for (std::size_t i = 0; i < surfaces_.size(); ++i) {
    // Closed solids' faces turned away from the camera are hidden by their front faces.
    if (!surfaces_[i].mayBeVisibleFrom(T_world_camera.translation()))
      continue;
    if (pixelBox(T_camera_world * surfaces_[i].boundCentre(), surfaces_[i].boundRadius(),
                 &boxes[i]))
      candidates.push_back(static_cast<int>(i));
  }
  const int threads = std::min(params_.threads, camera_.height);
  if (threads == 1) {
    castRows(T_world_camera, candidates, boxes, 0, 1, &frame);
  } else {
    std::vector<std::thread> workers;
    for (int k = 0; k < threads; ++k)
      workers.emplace_back(
          [&, k] { castRows(T_world_camera, candidates, boxes, k, threads, &frame); });
    for (std::thread& worker : workers)
      worker.join();
  }

  if (params_.noise) {
    frame.depth = depth_model_.apply(frame.depth_true, frame.cos_incidence, seed);
  } else {
    frame.depth = frame.depth_true.clone();
  }
  for (int v = 0; v < frame.depth.rows; ++v) {
    const float* d = frame.depth.ptr<float>(v);
    std::uint16_t* l = frame.labels.ptr<std::uint16_t>(v);
    for (int u = 0; u < frame.depth.cols; ++u) {
      if (std::isnan(d[u]))
        l[u] = 0;
    }
  }
  return frame;
}

}  // namespace quadric_slam
