#include "quadric_slam/sim/sequence_generator.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace quadric_slam {
namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

void SequenceGenerator::Params::validate() const {
  if (threads < 1 || threads > 64)
    throw std::invalid_argument("SequenceGenerator::Params::threads must be in [1, 64]");
  if (max_in_flight < threads)
    throw std::invalid_argument("SequenceGenerator::Params::max_in_flight must be >= threads");
}

SequenceGenerator::SequenceGenerator(const Renderer& renderer, const Params& params)
    : renderer_(renderer), params_(params) {
  params_.validate();
}

SequenceGenerator::Stats SequenceGenerator::run(const std::vector<StampedPose>& poses,
                                                const FrameCallback& per_frame,
                                                const FrameCallback& ordered) const {
  const auto start = std::chrono::steady_clock::now();
  int max_id = 0;
  for (const Surface& s : renderer_.surfaces())
    max_id = std::max(max_id, s.id());
  Stats stats;
  stats.observations.assign(max_id + 1, 0);
  stats.large_views.assign(max_id + 1, 0);
  stats.pixels.assign(max_id + 1, 0);

  std::mutex mutex;
  std::condition_variable changed;
  std::size_t next_to_render = 0, next_to_consume = 0;
  std::map<std::size_t, std::unique_ptr<RenderedFrame>> done;
  std::exception_ptr failure;

  auto worker = [&] {
    for (;;) {
      std::size_t index;
      {
        std::unique_lock<std::mutex> lock(mutex);
        changed.wait(lock, [&] {
          return failure || next_to_render >= poses.size() ||
                 next_to_render < next_to_consume + params_.max_in_flight;
        });
        if (failure || next_to_render >= poses.size())
          return;
        index = next_to_render++;
      }
      try {
        const auto t0 = std::chrono::steady_clock::now();
        auto frame = std::make_unique<RenderedFrame>(
            renderer_.render(poses[index].T_world_sensor, frameNoiseSeed(params_.seed, index)));
        const double render = secondsSince(t0);
        std::vector<int> counts(max_id + 1, 0);
        for (int v = 0; v < frame->labels.rows; ++v) {
          const std::uint16_t* l = frame->labels.ptr<std::uint16_t>(v);
          for (int u = 0; u < frame->labels.cols; ++u) {
            if (l[u] > 0 && l[u] <= max_id)
              ++counts[l[u]];
          }
        }
        const auto t1 = std::chrono::steady_clock::now();
        if (per_frame)
          per_frame(index, poses[index], *frame);
        const double callback = secondsSince(t1);
        std::lock_guard<std::mutex> lock(mutex);
        stats.render_seconds += render;
        stats.per_frame_seconds += callback;
        for (int id = 1; id <= max_id; ++id) {
          stats.pixels[id] += counts[id];
          stats.observations[id] += counts[id] > 0 ? 1 : 0;
          stats.large_views[id] += counts[id] >= kLargeViewPixels ? 1 : 0;
        }
        done[index] = std::move(frame);
        changed.notify_all();
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!failure)
          failure = std::current_exception();
        changed.notify_all();
        return;
      }
    }
  };

  std::vector<std::thread> workers;
  for (int k = 0; k < params_.threads; ++k)
    workers.emplace_back(worker);

  while (next_to_consume < poses.size()) {
    std::unique_ptr<RenderedFrame> frame;
    {
      std::unique_lock<std::mutex> lock(mutex);
      changed.wait(lock, [&] { return failure || done.count(next_to_consume) > 0; });
      if (failure)
        break;
      frame = std::move(done[next_to_consume]);
      done.erase(next_to_consume);
    }
    try {
      const auto t0 = std::chrono::steady_clock::now();
      if (ordered)
        ordered(next_to_consume, poses[next_to_consume], *frame);
      stats.ordered_seconds += secondsSince(t0);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      failure = std::current_exception();
      changed.notify_all();
      break;
    }
    std::lock_guard<std::mutex> lock(mutex);
    ++next_to_consume;
    changed.notify_all();
  }
  for (std::thread& w : workers)
    w.join();
  if (failure)
    std::rethrow_exception(failure);
  stats.wall_seconds = secondsSince(start);
  return stats;
}

}  // namespace quadric_slam
