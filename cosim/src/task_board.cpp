#include "dualgrid/cosim/task_board.hpp"

#include <stdexcept>
#include <string>

namespace dualgrid::cosim {

TaskBoard::TaskBoard(int tasks) : tasks_(tasks) {
  if (tasks < 0)
    throw std::invalid_argument("TaskBoard: need 0 or more tasks, got " + std::to_string(tasks));
  slots_ = std::make_unique<Slot[]>(static_cast<std::size_t>(tasks));
}

void TaskBoard::Finish(int i) {
  slots_[i].done.store(1, std::memory_order_release);
  done_count_.fetch_add(1, std::memory_order_acq_rel);
  Wake();
}

void TaskBoard::Wake() {
  progress_.fetch_add(1, std::memory_order_acq_rel);
  progress_.notify_all();
}

}  // namespace dualgrid::cosim
