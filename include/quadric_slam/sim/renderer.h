// Ray casts a scene's surfaces from a pinhole camera: true depth, Kinect-model depth, shaded RGB
// and per-pixel surface ids. Depth is the z coordinate in the optical frame (as a depth image
// stores it), registered to the RGB camera.
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

#include "quadric_slam/types/camera_intrinsics.h"
#include "quadric_slam/sim/kinect_depth_model.h"
#include "quadric_slam/sim/surfaces.h"

namespace quadric_slam {

struct RenderedFrame {
  cv::Mat depth_true;     // CV_32FC1, metres, NaN where no surface
  cv::Mat cos_incidence;  // CV_32FC1, |cos| of the angle between viewing ray and normal (0: none)
  cv::Mat depth;          // CV_32FC1, metres, NaN = no data (the Kinect model applied)
  cv::Mat rgb;            // CV_8UC3, R G B order
  cv::Mat labels;         // CV_16UC1, surface id where `depth` is valid, 0 elsewhere
};

class Renderer {
 public:
  struct Params {
    bool noise = true;        // apply the Kinect model; false: depth = true depth (all ranges)
    double ambient = 0.35;    // share of the colour that does not depend on the incidence, [0, 1]
    double near_clip = 0.01;  // nearest ray distance considered (m)
    int threads = 1;          // threads over image rows within one frame, >= 1

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  Renderer(std::vector<Surface> surfaces, const CameraIntrinsics& camera,
           const KinectDepthModel::Params& depth_model, const Params& params,
           const Eigen::Vector3d& background = Eigen::Vector3d(0.55, 0.6, 0.65));

  // Renders the view of the optical frame at T_world_camera; `seed` drives the depth noise.
  RenderedFrame render(const Eigen::Isometry3d& T_world_camera, std::uint64_t seed) const;

  const std::vector<Surface>& surfaces() const { return surfaces_; }
  const CameraIntrinsics& camera() const { return camera_; }
  const KinectDepthModel& depthModel() const { return depth_model_; }

 private:
  // Image rectangle (inclusive) that a surface's bounding sphere can cover; false when it
  // cannot be seen at all.
  struct PixelBox {
    int u0, u1, v0, v1;
  };
  bool pixelBox(const Eigen::Vector3d& centre_camera, double radius, PixelBox* box) const;
  void castRows(const Eigen::Isometry3d& T_world_camera, const std::vector<int>& candidates,
                const std::vector<PixelBox>& boxes, int row_begin, int row_step,
                RenderedFrame* frame) const;

  std::vector<Surface> surfaces_;
  CameraIntrinsics camera_;
  KinectDepthModel depth_model_;
  Params params_;
  Eigen::Vector3d background_;
};

}  // namespace quadric_slam
