// The run's output worker (outputs/output_worker.hpp): jobs run one at a time in the order posted,
// on its own thread or in line; a full queue makes Post wait; a job's exception reaches its future
// and not the worker; Drain and the destructor wait for every job posted.
#include <catch2/catch.hpp>
#include <chrono>
#include <future>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "dualgrid/outputs/output_worker.hpp"

using dualgrid::outputs::OutputWorker;

namespace {

// A job that waits until the test opens the gate: the worker is then busy for as long as needed.
struct Gate {
  std::promise<void> open;
  std::shared_future<void> opened = open.get_future().share();
};

}  // namespace

TEST_CASE("the output worker runs jobs in the order posted", "[output_worker]") {
  const bool threaded = GENERATE(true, false);
  std::mutex mutex;
  std::vector<int> order;
  std::vector<std::thread::id> where;
  {
    OutputWorker worker(threaded, 3);
    CHECK(worker.threaded() == threaded);
    for (int k = 0; k < 50; ++k)
      worker.Post([&, k] {
        const std::lock_guard<std::mutex> lock(mutex);
        order.push_back(k);
        where.push_back(std::this_thread::get_id());
      });
    worker.Drain();
    const std::lock_guard<std::mutex> lock(mutex);
    REQUIRE(order.size() == 50);
  }
  for (int k = 0; k < 50; ++k) CHECK(order[k] == k);
  // In line: on the posting thread; threaded: never on it.
  for (const auto& id : where) CHECK((id == std::this_thread::get_id()) == !threaded);
}

TEST_CASE("a full output queue makes Post wait until the worker takes a job", "[output_worker]") {
  Gate gate;
  std::vector<int> order;
  OutputWorker worker(true, 1);
  worker.Post([&] {
    gate.opened.wait();
    order.push_back(0);
  });
  // Returns once the worker took job 0 (which then waits at the gate): the queue is [1].
  auto first = std::async(std::launch::async, [&] { worker.Post([&] { order.push_back(1); }); });
  first.wait();
  auto third = std::async(std::launch::async, [&] { worker.Post([&] { order.push_back(2); }); });
  // Job 0 holds the worker and job 1 fills the queue: the third Post cannot return.
  CHECK(third.wait_for(std::chrono::milliseconds(100)) == std::future_status::timeout);
  gate.open.set_value();
  third.get();
  worker.Drain();
  CHECK(order == std::vector<int>{0, 1, 2});
}

TEST_CASE("a job's exception reaches its future, and later jobs still run", "[output_worker]") {
  const bool threaded = GENERATE(true, false);
  OutputWorker worker(threaded);
  bool later = false;
  auto failing = worker.Post([] { throw std::runtime_error("cannot write x: No space left"); });
  auto next = worker.Post([&] { later = true; });
  CHECK_THROWS_WITH(failing.get(), "cannot write x: No space left");
  next.get();
  CHECK(later);
}

TEST_CASE("the output worker's destructor runs every job already posted", "[output_worker]") {
  Gate gate;
  int done = 0;  // written by the worker only; read after its thread ended
  {
    OutputWorker worker(true, 8);
    worker.Post([&] { gate.opened.wait(); });
    for (int k = 0; k < 5; ++k) worker.Post([&] { ++done; });
    gate.open.set_value();
  }  // no Drain: the destructor must run the five
  CHECK(done == 5);
}

TEST_CASE("an output worker needs room for one job", "[output_worker]") {
  CHECK_THROWS_AS(OutputWorker(true, 0), std::invalid_argument);
}
