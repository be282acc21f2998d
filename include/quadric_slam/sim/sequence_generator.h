// Renders a sequence of poses on several threads: each frame is rendered (and handed to a
// per-frame callback, e.g. PNG writing) on a worker thread, then handed in frame order to a
// second callback on the calling thread (e.g. bag writing), with a bounded number of frames in
// flight. Counts per surface the frames in which it covers at least one labelled pixel.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "quadric_slam/sim/renderer.h"
#include "quadric_slam/sim/trajectory.h"

namespace quadric_slam {

// Seed of frame `index`'s depth noise in a sequence seeded with `seed` (one stream per frame, so
// the frames do not depend on the order or thread they are rendered in).
inline std::uint64_t frameNoiseSeed(std::uint64_t seed, std::size_t index) {
  return seed * 1000003ULL + index;
}

// Pixels a surface covers in a frame for the frame to count as a large view of it: what
// eval_segmentation needs by default to score a surface in a frame (a strip seen at a grazing angle, or a
// corner of a surface at the image's edge, is seen but not a surface a segmenter can find).
constexpr int kLargeViewPixels = 2000;

class SequenceGenerator {
 public:
  struct Params {
    int threads = 2;         // worker threads rendering frames, >= 1
    int max_in_flight = 8;   // rendered frames waiting for the ordered callback, >= threads
    std::uint64_t seed = 1;  // seed of the depth noise (frame k uses a stream of (seed, k))

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  struct Stats {
    std::vector<int> observations;   // index = surface id (0 unused): frames with >= 1 pixel
    std::vector<int> large_views;    // index = surface id: frames with >= kLargeViewPixels pixels
    std::vector<long> pixels;        // index = surface id: labelled pixels over all frames
    double wall_seconds = 0.0;       // whole run
    double render_seconds = 0.0;     // summed over workers
    double per_frame_seconds = 0.0;  // summed over workers (the per-frame callback)
    double ordered_seconds = 0.0;    // the ordered callback, on the calling thread
  };

  using FrameCallback =
      std::function<void(std::size_t index, const StampedPose& pose, const RenderedFrame& frame)>;

  SequenceGenerator(const Renderer& renderer, const Params& params);

  // Either callback may be empty. An exception in a callback stops the run and is rethrown.
  Stats run(const std::vector<StampedPose>& poses, const FrameCallback& per_frame,
            const FrameCallback& ordered) const;

 private:
  const Renderer& renderer_;
  Params params_;
};

}  // namespace quadric_slam
