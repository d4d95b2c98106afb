#pragma once
/// \file parallel.h
/// Minimal fork-join helpers (std::thread): a loop over index ranges, for loops whose
/// iterations are independent (the results do not depend on the number of threads), and two
/// jobs side by side.
///
/// The helpers start a thread only on an idle core. The process counts its threads at work: the
/// main thread, every thread these helpers start, and every ThreadAtWork scope, less the threads
/// that wait on another (ThreadWaiting). Where two jobs already fill the cores (the remesher's two
/// domains side by side), a nested helper runs its parts one after the other instead of taking
/// turns with them on the same cores.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <future>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace mrsnake {

namespace detail {

/// The threads of the process at work now (see the file's comment).
inline std::atomic<int>& threads_at_work() {
  static std::atomic<int> count{1};
  return count;
}

/// The machine's cores, asked once: every claim compares against it.
inline int core_count() {
  static const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return cores;
}

}  // namespace detail

/// While alive, one more thread counts as at work: a thread started other than by these helpers.
class ThreadAtWork {
 public:
  ThreadAtWork() { ++detail::threads_at_work(); }
  ~ThreadAtWork() { --detail::threads_at_work(); }
  ThreadAtWork(const ThreadAtWork&) = delete;
  ThreadAtWork& operator=(const ThreadAtWork&) = delete;
};

/// While alive, the calling thread counts as not at work: it only waits for another to end.
class ThreadWaiting {
 public:
  ThreadWaiting() { --detail::threads_at_work(); }
  ~ThreadWaiting() { ++detail::threads_at_work(); }
  ThreadWaiting(const ThreadWaiting&) = delete;
  ThreadWaiting& operator=(const ThreadWaiting&) = delete;
};

/// Counts one more thread at work if fewer threads are at work than the machine has cores.
/// \return whether it did; the caller then starts a thread and calls release_core() at its end.
inline bool claim_idle_core() {
  int at_work = detail::threads_at_work().load();
  while (at_work < detail::core_count())
    if (detail::threads_at_work().compare_exchange_weak(at_work, at_work + 1)) return true;
  return false;
}

/// Ends a claim_idle_core() that returned true.
inline void release_core() { --detail::threads_at_work(); }

namespace detail {

/// Releases a claimed core at the end of the thread's job, however the job ends.
struct ReleaseCoreAtEnd {
  ReleaseCoreAtEnd() = default;
  ReleaseCoreAtEnd(const ReleaseCoreAtEnd&) = delete;
  ReleaseCoreAtEnd& operator=(const ReleaseCoreAtEnd&) = delete;
  ~ReleaseCoreAtEnd() { release_core(); }
};

/// A thread running job on an idle core, as std::thread; std::system_error when no core is idle,
/// as std::thread without resources.
template <class Job>
std::thread start_on_idle_core(Job&& job) {
  if (!claim_idle_core()) throw std::system_error(std::make_error_code(std::errc::resource_unavailable_try_again));
  try {
    return std::thread([job = std::forward<Job>(job)]() mutable {
      const ReleaseCoreAtEnd release;
      job();
    });
  } catch (...) {
    release_core();
    throw;
  }
}

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
  const ThreadWaiting waiting;
  for (auto& th : pool) th.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace detail

/// Runs f(begin, end) on contiguous ranges of [0, n), one per hardware thread (at most
/// max_threads), each at least min_per_thread long; rethrows the first exception. The range
/// starting at 0 runs on the calling thread, and so do the ranges no idle core takes.
/// \throw whatever f throws (the first range's exception, in range order), after every range ends.
/// \pre f may run concurrently on disjoint ranges.
template <class F>
void parallel_ranges(std::size_t n, F&& f, std::size_t min_per_thread = 1024, std::size_t max_threads = 8) {
  const auto hardware = static_cast<std::size_t>(detail::core_count());
  const std::size_t parts =
      std::max<std::size_t>(1, std::min({hardware, max_threads, n / std::max<std::size_t>(1, min_per_thread)}));
  detail::parallel_ranges_with(n, parts, f, [](auto&& job) { return detail::start_on_idle_core(std::move(job)); });
}

/// Runs a() on the calling thread and b() on another one (one after the other when no core is
/// idle or no thread can be started), and returns after both.
/// \throw a()'s exception if it threw, else b()'s, after both ended.
template <class A, class B>
void run_both_in_parallel(A&& a, B&& b) {
  std::future<void> other;
  if (claim_idle_core()) {
    try {
      other = std::async(std::launch::async, [&b] {
        const detail::ReleaseCoreAtEnd release;
        b();
      });
    } catch (...) {  // std::system_error (no thread) or std::bad_alloc: run b() here after a()
      release_core();
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
  {
    const ThreadWaiting waiting;
    other.wait();
  }
  if (error) std::rethrow_exception(error);
  other.get();
}

}  // namespace mrsnake
