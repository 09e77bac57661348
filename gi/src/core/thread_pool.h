#pragma once
// The bakers' and the reference renderer's parallel loop: a oneTBB task arena of a fixed
// size (Debian's libtbb). Work is split into items identified by index; results must be
// written per item (never accumulated across items in completion order), so output is
// bit-identical for any thread count and any scheduling.
//   gi::ThreadPool pool(4);
//   pool.parallel_for(n, [&](std::size_t i) { out[i] = shade(i); });
// An exception thrown by fn reaches the caller of parallel_for (the other items stop).

#include <oneapi/tbb/task_arena.h>
#include <gi/progress.h>

#include <cstddef>
#include <functional>
#include <memory>

namespace gi {

class ThreadPool {
 public:
  /// At most this many threads, whatever is asked (a request is a setting, not a promise).
  static constexpr unsigned kMaxThreads = 256;

  /// `threads` = 0 uses the hardware's threads; more than kMaxThreads is clamped. The
  /// calling thread works too, so a pool of 1 runs everything on the caller.
  explicit ThreadPool(unsigned threads = 0);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned size() const { return size_; }

  /// Calls fn(i) for every i in [0, count), in chunks of at least `grain` items. Blocks
  /// until all are done.
  void parallel_for(std::size_t count, const std::function<void(std::size_t)>& fn, std::size_t grain = 1);

  /// parallel_for in batches (at most 200), calling `progress` (if set) with the fraction
  /// done after each batch, from the calling thread. Returns false, having stopped after
  /// the batch, when the callback returns false (cancelled).
  bool parallel_for_with_progress(std::size_t count, const ProgressCallback& progress,
                                  const std::function<void(std::size_t)>& fn, std::size_t grain = 4);

 private:
  unsigned size_ = 1;
  std::unique_ptr<tbb::task_arena> arena_;
};

}  // namespace gi
