#pragma once
// The tasks of one parallel region that any of its threads may run, each run exactly once, by
// whichever thread is free first: a thread claims the first unclaimed task (in index order, the
// priority) whose inputs are ready, runs it, and claims again; with nothing ready it sleeps (a
// futex wait, no spinning) until a task finishes or Wake() says that something else changed.
//
// Which thread runs a task may differ from run to run; what a task computes must not depend on
// it (each task reads inputs that are complete when it is ready and writes its own outputs).
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>

namespace dualgrid::cosim {

class TaskBoard {
 public:
  /// `tasks` >= 0 tasks, indices [0, tasks); none claimed. Throws std::invalid_argument if < 0.
  explicit TaskBoard(int tasks);

  /// Runs tasks on the calling thread until every task is claimed: claims the lowest unclaimed i
  /// with ready(i), runs run(i), marks it done (done(i) is then true for every thread, with what
  /// run(i) wrote visible to it), and repeats; sleeps while unclaimed tasks remain and none is
  /// ready. `ready(i)` must become true once the tasks and the outside work it waits for are done
  /// (outside work calls Wake() when it is; the tasks' dependencies must have no cycle), and
  /// stay true. run(i) must not throw. Returns once nothing
  /// is left to claim (tasks other threads claimed may still be running: see WaitUntil).
  /// `preferred`: tasks this thread claims before the others when they are ready (e.g. those
  /// that read what this thread wrote last, still in its core's cache), in the order given.
  template <typename Ready, typename Run>
  void Work(Ready&& ready, Run&& run, std::span<const int> preferred = {}) {
    for (;;) {
      const std::uint32_t seen = progress_.load(std::memory_order_acquire);
      std::optional<int> task;
      for (int i : preferred)
        if ((task = TryClaim(i, ready))) break;
      if (!task) task = Claim(ready);
      if (task) {
        run(*task);
        Finish(*task);
      } else if (claimed_count_.load(std::memory_order_acquire) == tasks_) {
        return;
      } else {
        progress_.wait(seen, std::memory_order_acquire);
      }
    }
  }

  /// Task i finished (acquire: its writes are visible after a true result).
  bool done(int i) const { return slots_[i].done.load(std::memory_order_acquire) != 0; }
  /// Sleeps until `condition()` holds; it must become true through tasks finishing or Wake().
  template <typename Condition>
  void WaitUntil(Condition&& condition) const {
    for (;;) {
      const std::uint32_t seen = progress_.load(std::memory_order_acquire);
      if (condition()) return;
      progress_.wait(seen, std::memory_order_acquire);
    }
  }
  /// Something a ready() reads changed outside the board (e.g. a filter finished): waiting
  /// threads look again.
  void Wake();
  int size() const { return tasks_; }
  /// Tasks not yet done, claimed or not (a snapshot: other threads may change it at once).
  int unfinished() const { return tasks_ - done_count_.load(std::memory_order_acquire); }

 private:
  struct Slot {
    std::atomic<int> claimed{0}, done{0};
  };
  template <typename Ready>
  std::optional<int> TryClaim(int i, Ready& ready) {
    Slot& s = slots_[i];
    if (s.claimed.load(std::memory_order_relaxed) != 0 || !ready(i)) return std::nullopt;
    if (s.claimed.exchange(1, std::memory_order_acq_rel) != 0) return std::nullopt;  // another
    claimed_count_.fetch_add(1, std::memory_order_acq_rel);
    return i;
  }
  template <typename Ready>
  std::optional<int> Claim(Ready& ready) {
    for (int i = 0; i < tasks_; ++i)
      if (const std::optional<int> task = TryClaim(i, ready)) return task;
    return std::nullopt;
  }
  void Finish(int i);

  int tasks_;
  std::unique_ptr<Slot[]> slots_;
  std::atomic<int> claimed_count_{0}, done_count_{0};
  std::atomic<std::uint32_t> progress_{0};  // bumped by Finish and Wake
};

}  // namespace dualgrid::cosim
