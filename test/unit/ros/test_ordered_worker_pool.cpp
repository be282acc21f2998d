// OrderedWorkerPool: jobs on several workers at once, deliveries in arrival order, the oldest
// waiting job pushed out when the queue is full, a throwing job never stalls the others.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "quadric_slam/ros/ordered_worker_pool.h"

namespace qs = quadric_slam;

namespace {

// A gate the test opens; waits give up after a generous time so a bug fails instead of hanging.
class Gate {
 public:
  void open() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    changed_.notify_all();
  }
  bool wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, std::chrono::seconds(20), [&] { return open_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  bool open_ = false;
};

// Collects deliveries; waitFor(n) returns once n arrived (false after a generous time).
class Deliveries {
 public:
  void add(int value) {
    std::lock_guard<std::mutex> lock(mutex_);
    values_.push_back(value);
    changed_.notify_all();
  }
  bool waitFor(std::size_t n) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, std::chrono::seconds(20), [&] { return values_.size() >= n; });
  }
  std::vector<int> values() {
    std::lock_guard<std::mutex> lock(mutex_);
    return values_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<int> values_;
};

}  // namespace

TEST(OrderedWorkerPool, DeliversInArrivalOrderWhenLaterJobsFinishFirst) {
  qs::OrderedWorkerPool pool(3, 8);
  Deliveries deliveries;
  Gate first_may_finish;
  // Job 0 finishes only after jobs 1 and 2 have finished their work.
  std::atomic<int> finished_work{0};
  pool.submit([&](int) {
    EXPECT_TRUE(first_may_finish.wait());
    return qs::OrderedWorkerPool::Delivery([&] { deliveries.add(0); });
  });
  for (int k = 1; k <= 2; ++k)
    pool.submit([&, k](int) {
      if (++finished_work == 2)
        first_may_finish.open();
      return qs::OrderedWorkerPool::Delivery([&, k] { deliveries.add(k); });
    });
  ASSERT_TRUE(deliveries.waitFor(3));
  EXPECT_EQ(deliveries.values(), (std::vector<int>{0, 1, 2}));
}

TEST(OrderedWorkerPool, WorkersRunJobsAtOnceEachWithItsOwnIndex) {
  constexpr int kWorkers = 2;
  qs::OrderedWorkerPool pool(kWorkers, 4);
  EXPECT_EQ(pool.workers(), kWorkers);
  // Each job waits until the other has started: with one worker at a time this never happens.
  std::mutex mutex;
  std::condition_variable changed;
  int started = 0;
  std::vector<int> indices;
  Deliveries deliveries;
  for (int k = 0; k < kWorkers; ++k)
    pool.submit([&, k](int worker) {
      std::unique_lock<std::mutex> lock(mutex);
      indices.push_back(worker);
      ++started;
      changed.notify_all();
      const bool both = changed.wait_for(lock, std::chrono::seconds(20),
                                         [&] { return started == kWorkers; });
      return qs::OrderedWorkerPool::Delivery([&, k, both] { deliveries.add(both ? k : -1); });
    });
  ASSERT_TRUE(deliveries.waitFor(kWorkers));
  EXPECT_EQ(deliveries.values(), (std::vector<int>{0, 1}));
  ASSERT_EQ(indices.size(), 2u);
  EXPECT_NE(indices[0], indices[1]);
  for (int index : indices) {
    EXPECT_GE(index, 0);
    EXPECT_LT(index, kWorkers);
  }
}

TEST(OrderedWorkerPool, AFullQueuePushesOutTheOldestWaitingJob) {
  qs::OrderedWorkerPool pool(1, 2);
  Deliveries deliveries;
  Gate busy_may_finish, busy_started;
  pool.submit([&](int) {
    busy_started.open();
    EXPECT_TRUE(busy_may_finish.wait());
    return qs::OrderedWorkerPool::Delivery([&] { deliveries.add(0); });
  });
  ASSERT_TRUE(busy_started.wait());  // the worker holds job 0; the next ones wait
  auto job = [&](int value) {
    return [&, value](int) { return qs::OrderedWorkerPool::Delivery([&, value] { deliveries.add(value); }); };
  };
  EXPECT_EQ(pool.submit(job(1)), 0);
  EXPECT_EQ(pool.submit(job(2)), 0);
  EXPECT_EQ(pool.submit(job(3)), 1);  // job 1, the oldest waiting, is pushed out
  busy_may_finish.open();
  ASSERT_TRUE(deliveries.waitFor(3));
  EXPECT_EQ(deliveries.values(), (std::vector<int>{0, 2, 3}));
}

TEST(OrderedWorkerPool, AThrowingJobOrDeliveryDoesNotStallTheOthers) {
  qs::OrderedWorkerPool pool(2, 8);
  Deliveries deliveries;
  pool.submit([&](int) -> qs::OrderedWorkerPool::Delivery { throw std::runtime_error("job"); });
  pool.submit([&](int) {
    return qs::OrderedWorkerPool::Delivery([] { throw std::runtime_error("delivery"); });
  });
  pool.submit([&](int) { return qs::OrderedWorkerPool::Delivery(); });  // nothing to deliver
  pool.submit([&](int) { return qs::OrderedWorkerPool::Delivery([&] { deliveries.add(4); }); });
  ASSERT_TRUE(deliveries.waitFor(1));
  EXPECT_EQ(deliveries.values(), (std::vector<int>{4}));
}

TEST(OrderedWorkerPool, BadSizesAreRefused) {
  EXPECT_THROW(qs::OrderedWorkerPool(0, 1), std::invalid_argument);
  EXPECT_THROW(qs::OrderedWorkerPool(65, 1), std::invalid_argument);
  EXPECT_THROW(qs::OrderedWorkerPool(1, 0), std::invalid_argument);
}
