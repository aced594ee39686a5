#include "dualgrid/outputs/output_worker.hpp"

#include <stdexcept>
#include <utility>

namespace dualgrid::outputs {

OutputWorker::OutputWorker(bool threaded, std::size_t capacity) : capacity_(capacity) {
  if (capacity_ == 0) throw std::invalid_argument("OutputWorker: capacity must be at least 1");
  if (threaded) thread_ = std::thread([this] { Loop(); });
}

OutputWorker::~OutputWorker() {
  if (!thread_.joinable()) return;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  work_.notify_one();
  thread_.join();  // Loop empties the queue before it returns
}

std::future<void> OutputWorker::Post(std::function<void()> job) {
  std::packaged_task<void()> task(std::move(job));
  std::future<void> done = task.get_future();
  if (!thread_.joinable()) {
    task();  // the exception, if any, lands in `done`
    return done;
  }
  {
    std::unique_lock<std::mutex> lock(mutex_);
    room_.wait(lock, [this] { return queue_.size() < capacity_; });
    queue_.push_back(std::move(task));
  }
  work_.notify_one();
  return done;
}

void OutputWorker::Drain() {
  if (!thread_.joinable()) return;
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && !running_; });
}

void OutputWorker::Loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    work_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stop_, and nothing left to run
    std::packaged_task<void()> task = std::move(queue_.front());
    queue_.pop_front();
    running_ = true;
    lock.unlock();
    room_.notify_one();
    task();  // never throws: a packaged_task keeps the job's exception
    lock.lock();
    running_ = false;
    if (queue_.empty()) idle_.notify_all();
  }
}

}  // namespace dualgrid::outputs
