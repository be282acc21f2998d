#include "quadric_slam/sim/synthetic_frame_source.h"

#include <cmath>
#include <stdexcept>

#include "quadric_slam/sim/sequence_generator.h"
#include "quadric_slam/sim/surfaces.h"
#include "quadric_slam/sim/trajectory.h"

namespace quadric_slam {

void SyntheticFrameSource::Params::validate() const {
  if (!(seconds > 0.0 && std::isfinite(seconds)))
    throw std::invalid_argument("SyntheticFrameSource: seconds must be in (0, inf) s");
  if (!(rate >= 0.0 && std::isfinite(rate)))
    throw std::invalid_argument("SyntheticFrameSource: rate must be 0 (the scene's) or > 0 Hz");
  if (render_threads < 1)
    throw std::invalid_argument("SyntheticFrameSource: render_threads must be >= 1");
}

SyntheticFrameSource::SyntheticFrameSource(const Scene& scene, const Params& params)
    : params_((params.validate(), params)) {
  const double rate = params_.rate > 0.0 ? params_.rate : scene.rate;
  if (params_.driving_trajectory.empty()) {
    poses_ = HandheldTrajectory(scene.handheld)
                 .generate(scene.centre_of_interest, rate, params_.seconds, params_.seed);
  } else {
    poses_ = resampleTrajectory(readDrivingTrajectory(params_.driving_trajectory), rate,
                                params_.seconds);
  }
  if (poses_.empty())
    throw std::runtime_error("SyntheticFrameSource: the trajectory gives no frames");
  Renderer::Params render;
  render.noise = params_.noise;
  render.threads = params_.render_threads;
  renderer_ = std::make_unique<Renderer>(buildSurfaces(scene), scene.camera, scene.depth, render,
                                         scene.background);
}

bool SyntheticFrameSource::next(RgbdFrame& frame) {
  if (position_ >= poses_.size())
    return false;
  const StampedPose& pose = poses_[position_];
  // The per-frame noise stream of SequenceGenerator (what `synth` writes for the same seed).
  RenderedFrame rendered =
      renderer_->render(pose.T_world_sensor, frameNoiseSeed(params_.seed, position_));
  ++position_;
  frame.stamp = pose.stamp;
  frame.depth_m = rendered.depth;
  frame.rgb = params_.rgb ? rendered.rgb : cv::Mat();
  frame.rgb_stamp = pose.stamp;
  frame.intrinsics = renderer_->camera();
  frame.frame_id = "openni_rgb_optical_frame";
  return true;
}

}  // namespace quadric_slam
