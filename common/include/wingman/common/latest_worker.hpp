// SPDX-License-Identifier: MIT
// A worker thread that processes the newest input handed to it, for a process that must keep reading its bus
// while slow work (a detection) runs.
#pragma once

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

namespace wingman::common {

/// One worker thread and a one-input mailbox. The owning thread hands inputs over with offer() and collects the
/// results with take(); the worker runs `work` on the newest input it finds. An input handed over while the previous
/// one still waits replaces it and is given back to the owner (who counts it as dropped): the mailbox never holds
/// more than one input, so a slow worker costs frames, never memory or latency. `wake` is called on the worker
/// thread after each result, and after a failure, so an owner blocked in poll() (e.g. Runtime::spin_once with
/// Runtime::wake) returns and collects.
///
/// Results come back in the order their inputs were taken. An exception that `work` lets out ends the worker; take()
/// hands it to the owner. In, Out: movable. offer(), take() and stop() are for one owning thread.
template <class In, class Out>
class LatestWorker {
 public:
  /// Starts the worker thread. `work` runs on it, one input at a time; `wake` is called on it and must not block.
  LatestWorker(std::function<Out(In&)> work, std::function<void()> wake)
      : work_(std::move(work)), wake_(std::move(wake)), thread_([this] { loop(); }) {}
  LatestWorker(const LatestWorker&) = delete;
  LatestWorker& operator=(const LatestWorker&) = delete;
  /// Stops the worker (as stop()) and discards what was not taken.
  ~LatestWorker() { stop(); }

  /// Hands `in` to the worker. Returns the input it replaced: one handed over before and not yet taken by the
  /// worker (it will never be processed), or nothing. After stop(), `in` itself comes back.
  std::optional<In> offer(In in) {
    std::optional<In> replaced;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_) return std::optional<In>(std::move(in));
      replaced = std::move(pending_);
      pending_ = std::move(in);
    }
    wanted_.notify_one();
    return replaced;  // destroyed, if the caller drops it, outside the lock
  }

  /// What take() collects.
  struct Taken {
    std::vector<Out> results;    ///< finished since the last take(), oldest first
    std::exception_ptr failure;  ///< set: `work` threw this and the worker has ended (the owner rethrows or
                                 ///< reports it after handling `results`; every later take() returns it again)
  };
  /// The results finished since the last call, and the worker's failure, if any (then the worker thread is joined).
  Taken take() {
    Taken out;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      out.results.swap(done_);
      out.failure = failure_;
    }
    if (out.failure) stop();
    return out;
  }

  /// Stops the worker: the input still waiting, if any, is not processed and is returned; the one being processed
  /// finishes, and its result stays for take(). Joins the thread. Later calls return nothing; offer() then gives
  /// every input back.
  std::optional<In> stop() {
    std::optional<In> waiting;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
      waiting = std::move(pending_);
      pending_.reset();
    }
    wanted_.notify_one();
    if (thread_.joinable() && thread_.get_id() != std::this_thread::get_id()) thread_.join();
    return waiting;
  }

 private:
  void loop() {
    for (;;) {
      std::optional<In> in;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wanted_.wait(lock, [this] { return stopping_ || pending_.has_value(); });
        if (stopping_) return;
        in = std::move(pending_);
        pending_.reset();
      }
      try {
        Out out = work_(*in);
        std::lock_guard<std::mutex> lock(mutex_);
        done_.push_back(std::move(out));
      } catch (...) {
        {
          std::lock_guard<std::mutex> lock(mutex_);
          failure_ = std::current_exception();
        }
        wake_();
        return;
      }
      wake_();
    }
  }

  std::function<Out(In&)> work_;
  std::function<void()> wake_;
  std::mutex mutex_;
  std::condition_variable wanted_;
  std::optional<In> pending_;  ///< the newest input, not yet taken by the worker
  bool stopping_ = false;
  std::vector<Out> done_;
  std::exception_ptr failure_;  ///< what `work` threw; ends the worker
  std::thread thread_;          ///< last: starts after every other member exists
};

}  // namespace wingman::common
