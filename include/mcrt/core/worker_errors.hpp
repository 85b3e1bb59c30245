#pragma once
// Exceptions of worker threads, carried to the thread that waits for them.
// An exception that leaves a std::thread's function ends the program
// (std::terminate: an abort, no message of the program's own); a worker
// runs its work through run() instead, the first exception any worker
// throws is kept, the others are told to stop (failed()), and the waiting
// thread rethrows it once every worker has ended (rethrow_if_failed()).
#include <atomic>
#include <exception>
#include <mutex>

namespace mcrt {

class worker_errors {
 public:
  // work(), with any exception it throws kept instead of leaving the thread.
  template <class Work>
  void run(Work&& work) noexcept {
    try {
      work();
    } catch (...) {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!first_) first_ = std::current_exception();
      failed_.store(true, std::memory_order_release);
    }
  }
  // Whether a worker has failed: the others stop at their next unit of work.
  bool failed() const { return failed_.load(std::memory_order_acquire); }
  // After every worker has ended: the first exception, rethrown.
  void rethrow_if_failed() {
    if (first_) std::rethrow_exception(first_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr first_;
  std::atomic<bool> failed_{false};
};

}  // namespace mcrt
