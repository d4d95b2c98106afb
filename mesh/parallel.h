#pragma once
/// \file parallel.h
/// Minimal fork-join helpers (std::thread): a loop over index ranges, for loops whose
/// iterations are independent (the results do not depend on the number of threads), and two
/// jobs side by side.
#include <algorithm>
#include <cstddef>
#include <exception>
#include <future>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace mrsnake {

namespace detail {

/// The loop of parallel_ranges with the thread start passed in, so that a test can make it fail.
/// A range whose thread cannot be started (std::system_error: no resources) runs on the calling
/// thread instead, so the loop degrades to fewer threads rather than terminating the program.
/// \pre parts >= 1 when n > 0; start_thread returns a joinable std::thread running its argument.
template <class F, class StartThread>
void parallel_ranges_with(std::size_t n, std::size_t parts, F& f, StartThread&& start_thread) {
  if (parts <= 1) {
    if (n > 0) f(std::size_t{0}, n);
    return;
  }
  std::vector<std::exception_ptr> errors(parts);
  auto run = [&](std::size_t t) {
    try {
      f(n * t / parts, n * (t + 1) / parts);
    } catch (...) {
      errors[t] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(parts - 1);
  std::size_t started = 1;  // range 0 is the calling thread's
  for (; started < parts; ++started) {
    try {
      pool.push_back(start_thread([&run, started] { run(started); }));
    } catch (...) {  // std::system_error (no resources) or std::bad_alloc
      break;
    }
  }
  run(0);
  for (std::size_t t = started; t < parts; ++t) run(t);
  for (auto& th : pool) th.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace detail

/// Runs f(begin, end) on contiguous ranges of [0, n), one per hardware thread (at most
/// max_threads), each at least min_per_thread long; rethrows the first exception. The range
/// starting at 0 runs on the calling thread.
/// \throw whatever f throws (the first range's exception, in range order), after every range ends.
/// \pre f may run concurrently on disjoint ranges.
template <class F>
void parallel_ranges(std::size_t n, F&& f, std::size_t min_per_thread = 1024, std::size_t max_threads = 8) {
  const std::size_t hardware = std::max<std::size_t>(1, std::thread::hardware_concurrency());
  const std::size_t parts =
      std::max<std::size_t>(1, std::min({hardware, max_threads, n / std::max<std::size_t>(1, min_per_thread)}));
  detail::parallel_ranges_with(n, parts, f, [](auto&& job) { return std::thread(std::move(job)); });
}

/// Runs a() on the calling thread and b() on another one (one after the other without a second
/// core or when no thread can be started), and returns after both.
/// \throw a()'s exception if it threw, else b()'s, after both ended.
template <class A, class B>
void run_both_in_parallel(A&& a, B&& b) {
  std::future<void> other;
  if (std::thread::hardware_concurrency() > 1) {
    try {
      other = std::async(std::launch::async, [&b] { b(); });
    } catch (...) {  // std::system_error (no thread) or std::bad_alloc: run b() here after a()
    }
  }
  std::exception_ptr error;
  try {
    a();
  } catch (...) {
    error = std::current_exception();
  }
  if (!other.valid()) {  // b() here, even when a() threw
    try {
      b();
    } catch (...) {
      if (!error) error = std::current_exception();
    }
    if (error) std::rethrow_exception(error);
    return;
  }
  other.wait();
  if (error) std::rethrow_exception(error);
  other.get();
}

}  // namespace mrsnake
