// TaskBoard (cosim/include/.../task_board.hpp): every task runs once, never before what it waits
// for, in priority order when one thread takes them all, and sleeping threads wake for work that
// becomes ready outside the board.
#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include "dualgrid/cosim/task_board.hpp"

using dualgrid::cosim::TaskBoard;

namespace {

// Runs `threads` workers on `board`, each calling Work with `ready` and `run`.
template <typename Ready, typename Run>
void RunWorkers(TaskBoard& board, int threads, Ready ready, Run run) {
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&, t] { board.Work(ready, [&](int i) { run(t, i); }); });
  for (auto& th : pool) th.join();
}

}  // namespace

TEST_CASE("TaskBoard: one thread takes the ready tasks in index order", "[cosim]") {
  TaskBoard board(6);
  std::vector<int> order;
  // Task 1 waits for task 4: the thread runs 0, 2, 3, 4, then 1, then 5.
  board.Work([&](int i) { return i != 1 || board.done(4); }, [&](int i) { order.push_back(i); });
  CHECK(order == std::vector<int>{0, 2, 3, 4, 1, 5});
  for (int i = 0; i < 6; ++i) CHECK(board.done(i));
  // Nothing left: a second call returns at once.
  board.Work([](int) { return true; }, [&](int i) { order.push_back(100 + i); });
  CHECK(order.size() == 6u);
}

TEST_CASE("TaskBoard: a thread's preferred tasks first, when ready, in the order given",
          "[cosim]") {
  TaskBoard board(6);
  std::vector<int> order;
  std::vector<int> unfinished;
  // Task 4 waits for task 2: preferred 4 then 3, the thread runs 3 (4 not ready), then 0, 1, 2 in
  // index order, then 4 (preferred, ready now), then 5.
  const std::vector<int> preferred{4, 3};
  board.Work([&](int i) { return i != 4 || board.done(2); },
             [&](int i) {
               order.push_back(i);
               unfinished.push_back(board.unfinished());
             },
             preferred);
  CHECK(order == std::vector<int>{3, 0, 1, 2, 4, 5});
  CHECK(unfinished == std::vector<int>{6, 5, 4, 3, 2, 1});  // each task itself counted
  CHECK(board.unfinished() == 0);
}

TEST_CASE("TaskBoard: every task runs once, after the tasks it waits for", "[cosim]") {
  std::mt19937 rng(37);
  for (int round = 0; round < 40; ++round) {
    const int n = 1 + static_cast<int>(rng() % 40), threads = 1 + static_cast<int>(rng() % 4);
    // Each task waits for up to three random tasks (any index, no cycle: only lower "levels").
    std::vector<int> level(n);
    for (int& l : level) l = static_cast<int>(rng() % 5);
    std::vector<std::vector<int>> deps(n);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        const int j = static_cast<int>(rng() % n);
        if (level[j] < level[i]) deps[i].push_back(j);
      }
    TaskBoard board(n);
    std::vector<std::atomic<int>> runs(n);
    std::atomic<int> early{0};
    RunWorkers(
        board, threads,
        [&](int i) {
          for (int j : deps[i])
            if (!board.done(j)) return false;
          return true;
        },
        [&](int, int i) {
          for (int j : deps[i]) early += runs[j].load() == 0 ? 1 : 0;  // a dependency not run
          std::this_thread::sleep_for(std::chrono::microseconds(20 * (i % 3)));
          ++runs[i];
        });
    for (int i = 0; i < n; ++i) CHECK(runs[i].load() == 1);
    CHECK(early.load() == 0);
    for (int i = 0; i < n; ++i) CHECK(board.done(i));
  }
}

TEST_CASE("TaskBoard: under contention every task is claimed by one thread only", "[cosim]") {
  // Many tiny tasks, all ready, four threads racing for each: a claim that is not atomic runs
  // some twice.
  const int n = 20000;
  for (int round = 0; round < 5; ++round) {
    TaskBoard board(n);
    std::vector<std::atomic<int>> runs(n);
    RunWorkers(
        board, 4, [](int) { return true; }, [&](int, int i) { ++runs[i]; });
    int wrong = 0;
    for (int i = 0; i < n; ++i) wrong += runs[i].load() != 1 ? 1 : 0;
    CHECK(wrong == 0);
  }
}

TEST_CASE("TaskBoard: a sleeping thread wakes for work made ready outside the board", "[cosim]") {
  // Task 0 is ready only once `outside` is set by a thread that is not working on the board (as
  // a filter finishing): Wake() must reach the thread sleeping in Work.
  for (int round = 0; round < 20; ++round) {
    TaskBoard board(2);
    std::atomic<int> outside{0}, ran{0};
    std::thread worker([&] {
      board.Work([&](int i) { return i == 1 || outside.load() != 0; }, [&](int) { ++ran; });
    });
    std::this_thread::sleep_for(std::chrono::microseconds(200 * (round % 4)));
    outside.store(1);
    board.Wake();
    worker.join();  // hangs (the test's timeout fails it) if the wake-up is lost
    CHECK(ran.load() == 2);
  }
}

TEST_CASE("TaskBoard: WaitUntil sleeps until other threads finish tasks", "[cosim]") {
  TaskBoard board(3);
  std::atomic<int> ready{0};
  std::thread worker([&] {
    board.Work([&](int) { return ready.load() != 0; },
               [&](int) { std::this_thread::sleep_for(std::chrono::milliseconds(2)); });
  });
  ready.store(1);
  board.Wake();
  board.WaitUntil([&] { return board.done(0) && board.done(1) && board.done(2); });
  CHECK(board.done(2));
  worker.join();
}

TEST_CASE("TaskBoard: a negative task count is misuse", "[cosim]") {
  CHECK_THROWS_AS(TaskBoard(-1), std::invalid_argument);
  TaskBoard empty(0);
  int runs = 0;
  empty.Work([](int) { return true; }, [&](int) { ++runs; });
  CHECK(runs == 0);
}
