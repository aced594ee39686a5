// One background thread for a run's output work (the replay recording's compression and appends,
// the pictures' drawing and encoding), so that the co-simulation's step loop does not wait for it.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <future>
#include <mutex>
#include <thread>

namespace dualgrid::outputs {

/// Runs posted jobs one at a time in the order posted: on one thread of its own when `threaded`,
/// else at once on the posting thread (a run on one thread stays on one core). Either way the
/// jobs run in the same order, so what they write is the same bytes.
///
/// Bounded: at most `capacity` jobs wait; Post then blocks (a condition variable, no spinning)
/// until the worker takes one. A job's exception is kept in the future Post returns; the worker
/// itself never throws. The destructor runs every job already posted, then ends the thread, so
/// work already handed over is not lost when a later stage of the run fails.
class OutputWorker {
 public:
  /// Throws std::invalid_argument for `capacity` 0.
  explicit OutputWorker(bool threaded, std::size_t capacity = 16);
  ~OutputWorker();
  OutputWorker(const OutputWorker&) = delete;
  OutputWorker& operator=(const OutputWorker&) = delete;

  /// Queues `job` (blocking while `capacity` jobs wait). The future becomes ready when the job
  /// ran, holding its exception if it threw. A job must not Post to its own worker.
  std::future<void> Post(std::function<void()> job);
  /// Blocks until every job posted so far ran.
  void Drain();
  bool threaded() const { return thread_.joinable(); }

 private:
  void Loop();

  std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable work_;  // a job was queued, or stop_
  std::condition_variable room_;  // the worker took a job from the queue
  std::condition_variable idle_;  // the queue is empty and no job runs
  std::deque<std::packaged_task<void()>> queue_;
  bool running_ = false;  // the worker is inside a job
  bool stop_ = false;
  std::thread thread_;  // last: started once the members above exist
};

}  // namespace dualgrid::outputs
