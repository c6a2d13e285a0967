// SPDX-License-Identifier: MIT
// LatestWorker: the worker processes the newest input, an input replaced while waiting comes back to the owner,
// results come back in order, stop() gives back the waiting input and finishes the running one, and a failure of
// the work reaches the owner. The work is gated by the test, so every interleaving checked here is forced, not
// timed; every wait is bounded.
#include "wingman/common/latest_worker.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using wingman::common::LatestWorker;
using namespace std::chrono_literals;

/// Work the test holds: each input waits until the test lets it through; records what started and what woke.
class Gate {
 public:
  /// The work: records `in` as started, then waits (at most 20 s) for a permit.
  int work(int& in) {
    std::unique_lock<std::mutex> lock(mutex_);
    started_.push_back(in);
    changed_.notify_all();
    const bool permitted = changed_.wait_for(lock, 20s, [this] { return permits_ > 0; });
    if (!permitted) throw std::runtime_error("the test never let input " + std::to_string(in) + " through");
    --permits_;
    if (in < 0) throw std::runtime_error("bad input " + std::to_string(in));
    return in * 10;
  }
  void wake() {
    std::lock_guard<std::mutex> lock(mutex_);
    ++wakes_;
    changed_.notify_all();
  }
  void permit() {
    std::lock_guard<std::mutex> lock(mutex_);
    ++permits_;
    changed_.notify_all();
  }
  /// Waits (at most 20 s) until `n` inputs have started; false on timeout.
  bool wait_started(size_t n) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, 20s, [&] { return started_.size() >= n; });
  }
  /// Waits (at most 20 s) until the worker has woken the owner `n` times; false on timeout.
  bool wait_wakes(int n) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, 20s, [&] { return wakes_ >= n; });
  }
  std::vector<int> started() {
    std::lock_guard<std::mutex> lock(mutex_);
    return started_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<int> started_;
  int permits_ = 0;
  int wakes_ = 0;
};

TEST(LatestWorker, ProcessesEachInputWhenTheWorkerKeepsUp) {
  Gate gate;
  LatestWorker<int, int> worker([&gate](int& in) { return gate.work(in); }, [&gate] { gate.wake(); });
  std::vector<int> results;
  for (int i = 1; i <= 5; ++i) {
    EXPECT_FALSE(worker.offer(i).has_value()) << "input " << i << " replaced one: the worker was idle";
    ASSERT_TRUE(gate.wait_started(static_cast<size_t>(i)));
    gate.permit();
    ASSERT_TRUE(gate.wait_wakes(i));
    const auto taken = worker.take();
    EXPECT_FALSE(taken.failure);
    results.insert(results.end(), taken.results.begin(), taken.results.end());
  }
  EXPECT_EQ(results, (std::vector<int>{10, 20, 30, 40, 50}));
  EXPECT_FALSE(worker.stop().has_value());
}

TEST(LatestWorker, AnInputReplacedWhileWaitingComesBackAndTheNewestIsProcessed) {
  Gate gate;
  LatestWorker<int, int> worker([&gate](int& in) { return gate.work(in); }, [&gate] { gate.wake(); });
  EXPECT_FALSE(worker.offer(1).has_value());
  ASSERT_TRUE(gate.wait_started(1));  // 1 is being processed: the next inputs wait
  EXPECT_FALSE(worker.offer(2).has_value());
  const auto replaced_2 = worker.offer(3);
  ASSERT_TRUE(replaced_2.has_value());
  EXPECT_EQ(*replaced_2, 2);
  const auto replaced_3 = worker.offer(4);
  ASSERT_TRUE(replaced_3.has_value());
  EXPECT_EQ(*replaced_3, 3);
  gate.permit();  // 1 finishes; the worker takes 4, the newest
  ASSERT_TRUE(gate.wait_started(2));
  gate.permit();
  ASSERT_TRUE(gate.wait_wakes(2));
  const auto taken = worker.take();
  EXPECT_EQ(taken.results, (std::vector<int>{10, 40}));
  EXPECT_EQ(gate.started(), (std::vector<int>{1, 4})) << "a replaced input was processed";
}

TEST(LatestWorker, StopGivesBackTheWaitingInputAndFinishesTheRunningOne) {
  Gate gate;
  LatestWorker<int, int> worker([&gate](int& in) { return gate.work(in); }, [&gate] { gate.wake(); });
  worker.offer(7);
  ASSERT_TRUE(gate.wait_started(1));
  worker.offer(8);
  // Two permits: 7 finishes, and so does 8 should the worker take it before stop() does (stop() joins the worker,
  // so it would otherwise wait for a permit no one gives).
  gate.permit();
  gate.permit();
  const auto waiting = worker.stop();
  const auto started = gate.started();
  if (waiting) {
    EXPECT_EQ(*waiting, 8);
    EXPECT_EQ(started, (std::vector<int>{7}));
  } else {
    EXPECT_EQ(started, (std::vector<int>{7, 8}));
  }
  const auto taken = worker.take();
  EXPECT_EQ(taken.results, (waiting ? std::vector<int>{70} : std::vector<int>{70, 80}))
      << "the input being processed at stop() was not finished";
  // After stop(), offer() gives every input back and nothing more is processed.
  const auto refused = worker.offer(9);
  ASSERT_TRUE(refused.has_value());
  EXPECT_EQ(*refused, 9);
  EXPECT_FALSE(worker.stop().has_value());
}

TEST(LatestWorker, AFailureOfTheWorkReachesTheOwnerAfterTheResultsBeforeIt) {
  Gate gate;
  LatestWorker<int, int> worker([&gate](int& in) { return gate.work(in); }, [&gate] { gate.wake(); });
  worker.offer(5);
  ASSERT_TRUE(gate.wait_started(1));
  gate.permit();
  ASSERT_TRUE(gate.wait_wakes(1));
  worker.offer(-1);  // the work throws on it
  ASSERT_TRUE(gate.wait_started(2));
  gate.permit();
  ASSERT_TRUE(gate.wait_wakes(2)) << "the worker did not wake the owner after its failure";
  const auto taken = worker.take();
  EXPECT_EQ(taken.results, (std::vector<int>{50}));
  ASSERT_TRUE(taken.failure);
  try {
    std::rethrow_exception(taken.failure);
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "bad input -1");
  }
  EXPECT_TRUE(worker.take().failure) << "a later take() forgot the failure";
  EXPECT_EQ(gate.started(), (std::vector<int>{5, -1}));
}

}  // namespace
