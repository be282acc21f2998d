#include "quadric_slam/ros/ordered_worker_pool.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace quadric_slam {

OrderedWorkerPool::OrderedWorkerPool(int workers, int capacity)
    : capacity_(static_cast<std::size_t>(capacity > 0 ? capacity : 0)) {
  if (workers < 1 || workers > 64)
    throw std::invalid_argument("workers must be in [1, 64], got " + std::to_string(workers));
  if (capacity < 1)
    throw std::invalid_argument("capacity must be >= 1, got " + std::to_string(capacity));
  threads_.reserve(workers);
  for (int w = 0; w < workers; ++w)
    threads_.emplace_back([this, w] { run(w); });
}

OrderedWorkerPool::~OrderedWorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    waiting_.clear();
  }
  work_ready_.notify_all();
  for (std::thread& thread : threads_)
    thread.join();
}

int OrderedWorkerPool::submit(Job job) {
  int pushed_out = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_)
      return 0;
    if (waiting_.size() >= capacity_) {
      waiting_.pop_front();
      pushed_out = 1;
    }
    waiting_.push_back(std::move(job));
  }
  work_ready_.notify_one();
  return pushed_out;
}

void OrderedWorkerPool::run(int worker) {
  for (;;) {
    Job job;
    std::uint64_t ticket = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      work_ready_.wait(lock, [&] { return stopping_ || !waiting_.empty(); });
      if (waiting_.empty())
        return;  // stopping, nothing left to take
      job = std::move(waiting_.front());
      waiting_.pop_front();
      // Taken in arrival order under the lock: tickets follow the arrival of the jobs.
      ticket = next_ticket_++;
    }
    Delivery delivery;
    try {
      delivery = job(worker);
    } catch (...) {
      delivery = nullptr;  // the job reports its own errors; its slot must still be released
    }
    std::unique_lock<std::mutex> lock(mutex_);
    turn_changed_.wait(lock, [&] { return next_delivery_ == ticket; });
    if (delivery) {
      // Deliveries run one at a time (no other ticket can be current), outside the lock so that
      // workers keep taking jobs meanwhile.
      lock.unlock();
      try {
        delivery();
      } catch (...) {
      }
      lock.lock();
    }
    ++next_delivery_;
    turn_changed_.notify_all();
  }
}

}  // namespace quadric_slam
