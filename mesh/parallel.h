#pragma once
/// \file parallel.h
/// A minimal fork-join loop over index ranges (std::thread), for loops whose iterations are
/// independent: the results do not depend on the number of threads.
#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace mrsnake {

/// Runs f(begin, end) on contiguous ranges of [0, n), one per hardware thread (at most
/// max_threads), each at least min_per_thread long; rethrows the first exception.
/// \pre f may run concurrently on disjoint ranges.
template <class F>
void parallel_ranges(std::size_t n, F&& f, std::size_t min_per_thread = 1024, std::size_t max_threads = 8) {
  const std::size_t hardware = std::max<std::size_t>(1, std::thread::hardware_concurrency());
  const std::size_t parts =
      std::max<std::size_t>(1, std::min({hardware, max_threads, n / std::max<std::size_t>(1, min_per_thread)}));
  if (parts == 1) {
    if (n > 0) f(std::size_t{0}, n);
    return;
  }
  std::vector<std::exception_ptr> errors(parts);
  std::vector<std::thread> pool;
  pool.reserve(parts - 1);
  for (std::size_t t = 1; t < parts; ++t)
    pool.emplace_back([&, t] {
      try {
        f(n * t / parts, n * (t + 1) / parts);
      } catch (...) {
        errors[t] = std::current_exception();
      }
    });
  try {
    f(std::size_t{0}, n / parts);
  } catch (...) {
    errors[0] = std::current_exception();
  }
  for (auto& th : pool) th.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace mrsnake
