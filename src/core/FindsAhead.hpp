#pragma once

// Private to src/core: the sweep (SelfStressBasis.cpp) has the local stresses of its dependent rows found
// ahead, on a second thread, while it eliminates.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <system_error>
#include <thread>
#include <vector>

#include "LocalStressFinder.hpp"
#include "StressRule.hpp"

namespace mobility_analysis {
namespace core_detail {

/**
 * Local stress finds made ahead of the sweep's decisions, each recorded with the finder state it was made
 * from; the sweep takes one only when it is in that state, and finds for itself otherwise, so its stresses
 * are those of the sweep on one thread to the bit (LocalStressFinder::State says why).
 *
 * Why: where most dependent rows need a local find (a grid of continuous bars, a braced lattice) the finds
 * are most of the basis' time, and they read only J and the order. While the sweep eliminates, a worker
 * thread takes the published rows from the front, following the sweep's rule for which rows are found and
 * from which state (as well as it can know it: whether the sweep's trace succeeded comes with the row, the
 * trace limit it guesses); once the elimination is done, the sweep's own thread takes rows from the back,
 * from the worker's latest state (a regular structure stays in one state), until the two meet. A guess that
 * was wrong costs the find it wasted and one made again, never a different stress.
 */
class FindsAhead {
 public:
  /// A find made ahead: from which state, its stress, and the state it left.
  struct Find {
    bool made = false;
    LocalStressFinder::State from, after;
    std::optional<SelfStress> stress;
  };

  /// @param[in] maxRows most dependent rows the sweep can publish (J's rows).
  FindsAhead(const LocalStressFinder::Inputs& inputs, size_t maxRows)
      : inputs_(inputs), chunks_(std::make_unique<std::unique_ptr<Slot[]>[]>(maxRows / kChunk + 1)) {}

  FindsAhead(const FindsAhead&) = delete;
  FindsAhead& operator=(const FindsAhead&) = delete;

  /// Stops the worker (its unfinished find is finished first) and waits for it.
  ~FindsAhead() {
    stop_ = true;
    close();
  }

  /// The sweep's thread, while eliminating: dependent row @p row, and whether the trace the sweep made at
  /// once found its stress (false when it did not trace). Starts the worker at the first row.
  void publish(int row, bool traced) {
    const size_t k = published_.load(std::memory_order_relaxed);
    if (k % kChunk == 0)
      chunks_[k / kChunk] = std::make_unique<Slot[]>(kChunk);
    Slot& slot = at(k);
    slot.row = row;
    slot.traced = traced;
    published_.store(k + 1, std::memory_order_release);
    if (!started_) {
      started_ = true;
      try {
        worker_ = std::thread([this] { work(); });
      } catch (const std::system_error&) {
        // No thread to be had: the sweep finds every row itself, as on one thread.
      }
    }
    if (k % kWakeEvery == 0)
      wake_.notify_one();
  }

  /// The trace limit the sweep will have reached, as far as the worker's rule has followed it.
  size_t traceLimitHint() const { return limitHint_.load(std::memory_order_relaxed); }

  /// Whether the worker's rule, after its latest row, finds before it traces (StressRule::findsFirst): the
  /// sweep then need not trace at once.
  bool predictsFindsFirst() const { return findsFirst_.load(std::memory_order_relaxed); }

  /// The sweep's thread, once the elimination is done: finds rows from the back with @p helper until it meets
  /// the worker, then waits for the worker to finish.
  void finish(LocalStressFinder& helper) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    wake_.notify_one();
    if (!worker_.joinable())
      return;  // no worker: nothing to guess the state from, the sweep finds every row itself
    // The back is found from the worker's latest state: wait until it has one (its first finds), or a
    // regular structure's rows would all be found from the initial state and found again.
    const size_t count = published_.load(std::memory_order_relaxed);
    while (doneFront_.load(std::memory_order_acquire) < std::min(count, kWarmUp) &&
           !finished_.load(std::memory_order_acquire))
      std::this_thread::sleep_for(std::chrono::microseconds(20));
    for (size_t k = count; k-- > 0;) {
      Slot& slot = at(k);
      int expected = kFree;
      if (!slot.status.compare_exchange_strong(expected, kBack))
        break;  // the worker has it, and everything before it
      const LocalStressFinder::State guess = latest();
      if (guess.inSpaceFirst || !slot.traced || predictsFindsFirst())
        findInto(helper, slot, guess, 0);
      slot.status.store(kDone, std::memory_order_release);
    }
    close();
  }

  /// Finds made ahead for the @p k-th published row (valid after finish()): at most two, in the order made.
  Find* finds(size_t k) { return at(k).finds; }

 private:
  static constexpr size_t kChunk = 4096;
  static constexpr size_t kWakeEvery = 64;
  /// Rows the worker finds before the sweep's thread guesses its state.
  static constexpr size_t kWarmUp = 16;
  enum Status : int { kFree = 0, kFront = 1, kBack = 2, kDone = 3 };

  struct Slot {
    int row = -1;
    bool traced = false;
    std::atomic<int> status{kFree};
    Find finds[2];
  };

  Slot& at(size_t k) { return chunks_[k / kChunk][k % kChunk]; }

  LocalStressFinder::State latest() {
    std::lock_guard<std::mutex> lock(stateMutex_);
    return latest_;
  }

  void findInto(LocalStressFinder& finder, Slot& slot, const LocalStressFinder::State& from, int which) {
    finder.setState(from);
    Find& find = slot.finds[which];
    find.from = from;
    find.stress = finder.find(slot.row);
    find.after = finder.state();
    find.made = true;
  }

  void close() {
    if (worker_.joinable()) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        closed_ = true;
      }
      wake_.notify_one();
      worker_.join();
    }
  }

  /// The worker; an exception (no memory) ends it, and the sweep finds what it left.
  void work() {
    try {
      findFromTheFront();
    } catch (...) {
    }
    finished_.store(true, std::memory_order_release);
  }

  /// The published rows from the front, following the sweep's rule (StressRule) for which rows it finds and
  /// from which state, with what it knows of the sweep's traces: whether the trace made at once succeeded
  /// (a stand-in stress when it did; the rule's full trace, never used, an empty one).
  void findFromTheFront() {
    LocalStressFinder finder(inputs_);
    StressRule rule;
    int locallyResolved = 0;  // the sweep counts its own
    for (size_t k = 0;; ++k) {
      if (k >= published_.load(std::memory_order_acquire)) {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || closed_ || k < published_.load(std::memory_order_acquire); });
        if (stop_ || k >= published_.load(std::memory_order_acquire))
          return;
      }
      if (stop_)
        return;
      Slot& slot = at(k);
      int expected = kFree;
      if (!slot.status.compare_exchange_strong(expected, kFront))
        return;  // the sweep's thread has it, and everything after it
      int made = 0;
      auto find = [&] {
        findInto(finder, slot, finder.state(), made);
        return slot.finds[made++].stress;
      };
      auto cappedTrace = [&](size_t) {
        return slot.traced ? std::optional<SelfStress>(SelfStress{}) : std::nullopt;
      };
      rule.resolve(
          finder, find, cappedTrace, [] { return SelfStress{}; }, locallyResolved);
      limitHint_.store(rule.traceLimit(), std::memory_order_relaxed);
      {
        std::lock_guard<std::mutex> lock(stateMutex_);
        latest_ = finder.state();
      }
      findsFirst_.store(rule.findsFirst(finder), std::memory_order_relaxed);
      slot.status.store(kDone, std::memory_order_release);
      doneFront_.fetch_add(1, std::memory_order_release);
    }
  }

  const LocalStressFinder::Inputs inputs_;
  /// Slots in chunks of kChunk, the chunk table sized for every row at once: a published slot never moves.
  std::unique_ptr<std::unique_ptr<Slot[]>[]> chunks_;
  std::atomic<size_t> published_{0};
  std::atomic<bool> stop_{false};
  std::atomic<bool> findsFirst_{false};
  std::atomic<size_t> limitHint_{kTraceLimit};
  std::atomic<size_t> doneFront_{0};
  std::atomic<bool> finished_{false};
  bool started_ = false;  ///< the sweep's thread only
  bool closed_ = false;   ///< guarded by mutex_
  std::mutex mutex_;
  std::condition_variable wake_;
  std::mutex stateMutex_;
  LocalStressFinder::State latest_;  ///< guarded by stateMutex_
  std::thread worker_;
};

}  // namespace core_detail
}  // namespace mobility_analysis
