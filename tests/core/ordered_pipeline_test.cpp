#include "core/ordered_pipeline.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace texlume {
namespace {

// omp_set_num_threads for one test, restored after it.
class Threads {
 public:
  explicit Threads(int n) : before_(omp_get_max_threads()) { omp_set_num_threads(n); }
  ~Threads() { omp_set_num_threads(before_); }

 private:
  int before_;
};

// What a RunAhead saw: the order of consume, each item's prepared value read from
// its slot, and any broken promise of the window or the workers.
struct Record {
  Record(std::size_t count, std::size_t window, std::size_t workers)
      : slots(window), busy(workers), prepared(count) {}
  std::vector<long long> slots;
  std::vector<std::atomic<int>> busy;  // per worker: preparing now
  std::vector<std::atomic<int>> prepared;
  std::atomic<std::size_t> consumed{0};
  std::atomic<bool> window_broken{false}, worker_shared{false}, worker_out_of_range{false};
  std::vector<std::size_t> order;
  std::vector<long long> values;
};

void RunRecorded(Record& r, std::size_t count, std::size_t window,
                 std::size_t throw_at_prepare = static_cast<std::size_t>(-1),
                 std::size_t throw_at_consume = static_cast<std::size_t>(-1)) {
  RunAhead(
      count, window,
      [&](std::size_t i, std::size_t worker) {
        if (worker >= r.busy.size()) {
          r.worker_out_of_range = true;
          return;
        }
        if (r.busy[worker].exchange(1)) r.worker_shared = true;
        // prepare(i) may start only once consume(i - window) has returned.
        if (i >= window && r.consumed.load() < i - window + 1) r.window_broken = true;
        if (i % 3 == 0) std::this_thread::yield();  // uneven work
        if (i == throw_at_prepare) {
          r.busy[worker] = 0;
          throw std::runtime_error("prepare failed");
        }
        r.slots[i % window] = static_cast<long long>(i) * 7 + 1;
        ++r.prepared[i];
        r.busy[worker] = 0;
      },
      [&](std::size_t i) {
        if (i == throw_at_consume) throw std::invalid_argument("consume failed");
        r.order.push_back(i);
        r.values.push_back(r.prepared[i] == 1 ? r.slots[i % window] : -1);
        r.consumed = i + 1;
      });
}

TEST(RunAhead, ConsumesInOrderWhatWasPreparedWithinTheWindow) {
  for (const int threads : {1, 2, 4}) {
    const Threads scope(threads);
    for (const std::size_t window : {1u, 2u, 5u}) {
      const std::size_t count = 200;
      Record r(count, window, RunAheadWorkers());
      RunRecorded(r, count, window);
      ASSERT_EQ(r.order.size(), count) << threads << " threads, window " << window;
      for (std::size_t i = 0; i < count; ++i) {
        EXPECT_EQ(r.order[i], i);
        EXPECT_EQ(r.values[i], static_cast<long long>(i) * 7 + 1) << "item " << i;
        EXPECT_EQ(r.prepared[i], 1);
      }
      EXPECT_FALSE(r.window_broken);
      EXPECT_FALSE(r.worker_shared);
      EXPECT_FALSE(r.worker_out_of_range);
    }
  }
}

TEST(RunAhead, UsesEveryThreadItIsGiven) {
  const Threads scope(3);
  EXPECT_EQ(RunAheadWorkers(), 3u);
  std::vector<std::atomic<int>> used(3);
  RunAhead(
      60, 6,
      [&](std::size_t, std::size_t worker) {
        used[worker] = 1;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      },
      [](std::size_t) {});
  int workers = 0;
  for (auto& u : used) workers += u;
  EXPECT_GE(workers, 2);  // the consumer and at least one other thread prepared
}

TEST(RunAhead, TheFirstExceptionStopsTheRunAndReachesTheCaller) {
  for (const int threads : {1, 2}) {
    const Threads scope(threads);
    {
      Record r(100, 4, RunAheadWorkers());
      EXPECT_THROW(RunRecorded(r, 100, 4, 30), std::runtime_error);
      ASSERT_LE(r.order.size(), 30u);  // nothing from item 30 on is consumed
      for (std::size_t i = 0; i < r.order.size(); ++i) EXPECT_EQ(r.order[i], i);
      for (std::size_t i = 30 + 4; i < 100; ++i) EXPECT_EQ(r.prepared[i], 0) << i;
    }
    {
      Record r(100, 4, RunAheadWorkers());
      EXPECT_THROW(RunRecorded(r, 100, 4, static_cast<std::size_t>(-1), 50), std::invalid_argument);
      EXPECT_EQ(r.order.size(), 50u);
      for (std::size_t i = 50 + 4; i < 100; ++i) EXPECT_EQ(r.prepared[i], 0) << i;
    }
  }
}

// Of several failures, the one first in item order is reported, as running the
// items in turn would, whichever thread meets its failure first.
TEST(RunAhead, ReportsTheFailureFirstInItemOrder) {
  for (const int threads : {1, 2, 4}) {
    const Threads scope(threads);
    for (const bool consume_fails : {false, true}) {
      std::string message;
      try {
        RunAhead(
            60, 12,
            [&](std::size_t i, std::size_t) {
              if (i == 30 && !consume_fails) {
                std::this_thread::sleep_for(std::chrono::milliseconds(20));
                throw std::runtime_error("item 30");
              }
              if (i == 33 || i == 35) throw std::runtime_error("item " + std::to_string(i));
            },
            [&](std::size_t i) {
              if (i == 30 && consume_fails) {
                std::this_thread::sleep_for(std::chrono::milliseconds(20));
                throw std::runtime_error("consuming 30");
              }
            });
      } catch (const std::runtime_error& e) {
        message = e.what();
      }
      EXPECT_EQ(message, consume_fails ? "consuming 30" : "item 30") << threads << " threads";
    }
  }
}

TEST(RunAhead, WithinAParallelRegionRunsInTurnOnOneWorker) {
  const Threads scope(2);
  std::vector<std::size_t> order;
  std::atomic<bool> other_worker{false};
#pragma omp parallel num_threads(2)
  {
#pragma omp single
    {
      EXPECT_EQ(RunAheadWorkers(), 1u);
      RunAhead(
          5, 2,
          [&](std::size_t i, std::size_t worker) {
            if (worker != 0) other_worker = true;
            order.push_back(10 + i);
          },
          [&](std::size_t i) { order.push_back(i); });
    }
  }
  EXPECT_FALSE(other_worker);
  EXPECT_EQ(order, (std::vector<std::size_t>{10, 0, 11, 1, 12, 2, 13, 3, 14, 4}));
}

}  // namespace
}  // namespace texlume
