// Frames processed on several threads at once, their results delivered in arrival order.
//
// A nodelet's callbacks run one at a time, so a stage whose frame takes longer than the sensor's
// frame period drops frames even while another core is idle. The pool takes a frame's job on the
// next free worker; what a job returns (its delivery: publishing, counting) runs after the
// deliveries of every job that arrived before it, one delivery at a time, so consumers still see
// strictly increasing stamps. A job that arrives while `capacity` jobs already wait for a worker
// pushes out the oldest waiting one (a live stage keeps the newest frames), which submit()
// reports. ROS-free; used by the quadric_segmentation nodelet (~workers).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace quadric_slam {

class OrderedWorkerPool {
 public:
  // The delivery of a job's result (may be empty: nothing to deliver).
  using Delivery = std::function<void()>;
  // A job: runs on worker `worker` (0 .. workers-1; each worker runs one job at a time, so a
  // job may use storage of its own per worker index) and returns its delivery. What a job or a
  // delivery throws is swallowed (the job's order slot is released); catch inside them to report.
  using Job = std::function<Delivery(int worker)>;

  // workers in [1, 64], capacity (jobs waiting for a worker) >= 1; throws std::invalid_argument.
  OrderedWorkerPool(int workers, int capacity);
  // Waiting jobs are discarded; running jobs finish and deliver; then the workers are joined.
  ~OrderedWorkerPool();
  OrderedWorkerPool(const OrderedWorkerPool&) = delete;
  OrderedWorkerPool& operator=(const OrderedWorkerPool&) = delete;

  // Queues job; returns the number of waiting jobs pushed out to make room (0 or 1).
  int submit(Job job);
  int workers() const { return static_cast<int>(threads_.size()); }

 private:
  void run(int worker);

  const std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable work_ready_, turn_changed_;
  std::deque<Job> waiting_;
  std::uint64_t next_ticket_ = 0;     // handed to the next job a worker takes (arrival order)
  std::uint64_t next_delivery_ = 0;   // the ticket whose delivery runs next
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace quadric_slam
