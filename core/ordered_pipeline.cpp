#include "core/ordered_pipeline.h"

#include <omp.h>

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <vector>

#include "core/check.h"

namespace texlume {
namespace {

// The shared state of one RunAhead: which items are claimed, prepared and
// consumed, under one mutex; every change is announced on `changed`.
class AheadRun {
 public:
  AheadRun(std::size_t count, std::size_t window,
           const std::function<void(std::size_t, std::size_t)>& prepare,
           const std::function<void(std::size_t)>& consume)
      : count_(count), window_(window), prepare_(prepare), consume_(consume), prepared_(count, 0) {}

  // Any thread but the caller's: claims and prepares items until none is left.
  void Prepare() {
    std::unique_lock lock(mutex_);
    for (;;) {
      changed_.wait(lock, [&] { return failed_ || next_ >= count_ || Claimable(); });
      if (failed_ || next_ >= count_) return;
      PrepareNext(lock, static_cast<std::size_t>(omp_get_thread_num()));
    }
  }

  // The caller's thread: every item consumed in order, preparing while it waits.
  void Consume() {
    for (std::size_t i = 0; i < count_; ++i) {
      std::unique_lock lock(mutex_);
      while (!prepared_[i] && !failed_) {
        if (next_ < count_ && Claimable())
          PrepareNext(lock, 0);
        else
          changed_.wait(lock);
      }
      if (failed_) return;
      lock.unlock();
      if (!Run([&] { consume_(i); })) return;
      lock.lock();
      consumed_ = i + 1;
      changed_.notify_all();
    }
  }

  void Rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  // The next item may start: the slot it takes was consumed.
  bool Claimable() const { return next_ < consumed_ + window_; }

  // Claims the next item and prepares it with the lock released.
  void PrepareNext(std::unique_lock<std::mutex>& lock, std::size_t worker) {
    const std::size_t i = next_++;
    lock.unlock();
    const bool done = Run([&] { prepare_(i, worker); });
    lock.lock();
    prepared_[i] = done ? 1 : 0;
    changed_.notify_all();
  }

  // work(); on an exception, keeps the first and stops every thread.
  template <typename Work>
  bool Run(const Work& work) {
    try {
      work();
      return true;
    } catch (...) {
      const std::lock_guard lock(mutex_);
      if (!error_) error_ = std::current_exception();
      failed_ = true;
      changed_.notify_all();
      return false;
    }
  }

  const std::size_t count_, window_;
  const std::function<void(std::size_t, std::size_t)>& prepare_;
  const std::function<void(std::size_t)>& consume_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<char> prepared_;  // per item
  std::size_t next_ = 0;        // the first item not claimed
  std::size_t consumed_ = 0;    // items [0, consumed_) are consumed
  bool failed_ = false;
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
