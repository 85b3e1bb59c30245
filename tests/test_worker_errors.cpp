// worker_errors (core/worker_errors.hpp): an exception thrown on a worker
// thread reaches the thread that waits for the workers, the others stop at
// their next unit of work, and nothing ends the program.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

#include "mcrt/core/worker_errors.hpp"

using namespace mcrt;

TEST(WorkerErrors, TheFirstExceptionReachesTheCallerAndStopsTheOthers) {
  worker_errors errors;
  std::atomic<int> next{0}, done_after_failure{0};
  constexpr int units = 100000;
  const auto work = [&] {
    for (int u; !errors.failed() && (u = next.fetch_add(1)) < units;) {
      if (u == 500) throw std::runtime_error("unit 500 failed");
      if (errors.failed()) done_after_failure.fetch_add(1);
    }
  };
  {
    std::vector<std::jthread> pool;
    for (int t = 0; t < 3; ++t) pool.emplace_back([&] { errors.run(work); });
    errors.run(work);
  }
  EXPECT_TRUE(errors.failed());
  try {
    errors.rethrow_if_failed();
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "unit 500 failed");
  }
  // The others stopped long before the end (each finishes at most the unit
  // it was on).
  EXPECT_LT(next.load(), units);
  EXPECT_LE(done_after_failure.load(), 4);
}

TEST(WorkerErrors, NothingToRethrowWithoutAFailure) {
  worker_errors errors;
  int sum = 0;
  errors.run([&] { sum += 1; });
  EXPECT_FALSE(errors.failed());
  EXPECT_NO_THROW(errors.rethrow_if_failed());
  EXPECT_EQ(sum, 1);
}
