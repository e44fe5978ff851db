#include "core/ordered_pipeline.h"

#include <omp.h>

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <map>
#include <mutex>
#include <vector>

#include "core/check.h"

namespace texlume {
namespace {

// The shared state of one RunAhead: which items are claimed, prepared and
// consumed, under one mutex; every change is announced on `changed`. A failed
// item stops the claims beyond it, and the run ends at the first failure in item
// order (prepare(i) then consume(i) for each i), whichever thread met it first.
class AheadRun {
 public:
  AheadRun(std::size_t count, std::size_t window,
           const std::function<void(std::size_t, std::size_t)>& prepare,
           const std::function<void(std::size_t)>& consume)
      : count_(count),
        window_(window),
        prepare_(prepare),
        consume_(consume),
        state_(count, kWaiting),
        first_failed_(count) {}

  // Any thread but the caller's: claims and prepares items until none is left.
  void Prepare() {
    std::unique_lock lock(mutex_);
    for (;;) {
      changed_.wait(lock, [&] { return stopped_ || !Left() || Claimable(); });
      if (stopped_ || !Left()) return;
      PrepareNext(lock, static_cast<std::size_t>(omp_get_thread_num()));
    }
  }

  // The caller's thread: every item consumed in order, preparing while it waits.
  void Consume() {
    for (std::size_t i = 0; i < count_; ++i) {
      std::unique_lock lock(mutex_);
      while (state_[i] == kWaiting) {
        if (Left() && Claimable())
          PrepareNext(lock, 0);
        else
          changed_.wait(lock);
      }
      if (state_[i] == kFailed) return Stop(errors_.at(i));
      lock.unlock();
      try {
        consume_(i);
      } catch (...) {
        lock.lock();
        return Stop(std::current_exception());
      }
      lock.lock();
      consumed_ = i + 1;
      changed_.notify_all();
    }
  }

  void Rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  static constexpr char kWaiting = 0, kPrepared = 1, kFailed = 2;

  // Items may still be claimed: not all are, and none before them failed.
  bool Left() const { return next_ < std::min(count_, first_failed_); }
  // The next item may start: the slot it takes was consumed.
  bool Claimable() const { return next_ < consumed_ + window_; }

  // Claims the next item and prepares it with the lock released.
  void PrepareNext(std::unique_lock<std::mutex>& lock, std::size_t worker) {
    const std::size_t i = next_++;
    lock.unlock();
    std::exception_ptr error;
    try {
      prepare_(i, worker);
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    state_[i] = error ? kFailed : kPrepared;
    if (error) errors_[i] = error, first_failed_ = std::min(first_failed_, i);
    changed_.notify_all();
  }

  // Ends the run with `error` (the lock held): no thread claims anything more.
  void Stop(std::exception_ptr error) {
    error_ = std::move(error);
    stopped_ = true;
    changed_.notify_all();
  }

  const std::size_t count_, window_;
  const std::function<void(std::size_t, std::size_t)>& prepare_;
  const std::function<void(std::size_t)>& consume_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<char> state_;                           // per item: kWaiting, kPrepared or kFailed
  std::map<std::size_t, std::exception_ptr> errors_;  // the failed items'
  std::size_t next_ = 0;                              // the first item not claimed
  std::size_t consumed_ = 0;                          // items [0, consumed_) are consumed
  std::size_t first_failed_;  // the first item whose prepare failed (count_: none)
  bool stopped_ = false;
  std::exception_ptr error_;
};

}  // namespace

std::size_t RunAheadWorkers() {
  return omp_in_parallel() ? 1 : static_cast<std::size_t>(std::max(1, omp_get_max_threads()));
}

void RunAhead(std::size_t count, std::size_t window,
              const std::function<void(std::size_t, std::size_t)>& prepare,
              const std::function<void(std::size_t)>& consume) {
  TEXLUME_CHECK(window >= 1, "RunAhead needs a window of at least one item");
  if (count <= 1 || RunAheadWorkers() <= 1) {
    for (std::size_t i = 0; i < count; ++i) {
      prepare(i, 0);
      consume(i);
    }
    return;
  }
  AheadRun run(count, window, prepare, consume);
#pragma omp parallel
  {
    // Thread 0 of the team is the calling thread: it consumes.
    if (omp_get_thread_num() == 0)
      run.Consume();
    else
      run.Prepare();
  }
  run.Rethrow();
}

}  // namespace texlume
