#pragma once

#include <exception>
#include <mutex>

namespace texlume {

/// The first exception thrown by work run on OpenMP threads or tasks. An
/// exception must not leave a parallel region (that would call terminate()):
/// each piece of work runs through Run(), which keeps the first exception, and
/// the thread that started the region rethrows it once the region is done.
class FirstException {
 public:
  /// Runs `work` unless an earlier piece failed; keeps its exception if it is the first.
  template <typename Work>
  void Run(const Work& work) {
    if (Failed()) return;
    try {
      work();
    } catch (...) {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
    }
  }
  bool Failed() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return static_cast<bool>(error_);
  }
  /// Throws the first exception kept, if any (call after the parallel region).
  void Rethrow() {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr error_;
};

}  // namespace texlume
