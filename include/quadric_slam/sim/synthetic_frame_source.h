// A generated sequence as a frame source: each frame is rendered from the scene when it is asked
// for, so a sequence of any length (an hour of frames) runs through the pipeline without writing a
// bag or a folder first. The frames are those `synth` writes for the same scene, trajectory and
// seed (same renderer, same per-frame noise stream).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/io/trajectory_io.h"
#include "quadric_slam/sim/renderer.h"
#include "quadric_slam/sim/scene.h"

namespace quadric_slam {

class SyntheticFrameSource : public FrameSource {
 public:
  struct Params {
    double seconds = 60.0;  // length of the sequence (s), > 0
    // Frame rate (Hz), > 0; 0 takes the scene's rate.
    double rate = 0.0;
    // Seed of the depth noise and of the hand-held motion.
    std::uint64_t seed = 1;
    // A TUM ground-truth file whose motion drives the camera (resampled at the rate from its
    // first stamp); empty: the scene's seeded hand-held motion.
    std::string driving_trajectory;
    bool noise = true;       // the scene's depth model; false: true depth
    bool rgb = true;         // fill RgbdFrame::rgb with the rendered colour image
    int render_threads = 1;  // threads over image rows within one frame, >= 1

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  // Throws std::invalid_argument on bad parameters and std::runtime_error when the trajectory
  // gives no frame.
  SyntheticFrameSource(const Scene& scene, const Params& params);

  bool next(RgbdFrame& frame) override;
  std::size_t size() const override { return poses_.size(); }
  void rewind() override { position_ = 0; }

  // The camera poses of the frames (T_world_camera of the optical frame), the ground truth.
  const Trajectory& groundTruth() const { return poses_; }
  const Renderer& renderer() const { return *renderer_; }

 private:
  Params params_;
  Trajectory poses_;
  std::unique_ptr<Renderer> renderer_;
  std::size_t position_ = 0;
};

}  // namespace quadric_slam
