#pragma once

// Private to src/core: the analysis driver (MobilityAnalysis.cpp) runs phases that read only finished results
// beside the phases that follow them.

#include <future>
#include <system_error>
#include <type_traits>
#include <utility>

namespace mobility_analysis {
namespace core_detail {

/// From this many equations on, the analysis may use a second thread (the side tasks of the driver, the
/// sweep's finds made ahead): about a millisecond of work, against tens of microseconds to start a thread,
/// and the reference mechanisms and the node in motion stay below it.
constexpr long kSecondThreadEquations = 20000;

/**
 * A phase of the analysis that runs on a second thread beside the caller's work, or, when it is not worth a
 * thread, in the caller's thread when its result is asked for.
 *
 * Why the answer cannot depend on it: a side task is handed only inputs that no one writes while it runs (the
 * Jacobian, the pose, the self-stress basis, all const), has no progress callback (the caller's is not
 * thread-safe and may throw to cancel), and shares no state with the caller's phases (the core has no mutable
 * globals), so it computes the same bits on either thread. Its exceptions reach the caller at get(); if the
 * caller leaves by an exception first, the destructor waits for the task to finish.
 *
 * Why a threshold: starting a thread costs tens of microseconds; the reference mechanisms analyse in less,
 * and an interactive caller (the node in motion) analyses them hundreds of times a second.
 */
template <class Result>
class SideTask {
 public:
  /// Starts @p work on its own thread when @p worthAThread, else keeps it for get().
  template <class Work>
  SideTask(bool worthAThread, Work&& work) {
    if (worthAThread) {
      try {
        future_ = std::async(std::launch::async, work);
        return;
      } catch (const std::system_error&) {
        // No thread to be had (a process at its limit): the caller's thread does it at get().
      }
    }
    future_ = std::async(std::launch::deferred, std::forward<Work>(work));
  }

  /// The result (computed now if it was kept for the caller's thread); may be called once.
  Result get() { return future_.get(); }

 private:
  std::future<Result> future_;
};

template <class Work>
SideTask(bool, Work&&) -> SideTask<std::invoke_result_t<std::decay_t<Work>>>;

}  // namespace core_detail
}  // namespace mobility_analysis
