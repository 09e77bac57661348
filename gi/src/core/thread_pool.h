#pragma once
// A fixed pool of worker threads for bakers and the reference renderer. Work is split into
// items identified by index; results must be written per item (never accumulated across
// items in completion order), so output is bit-identical for any thread count.
//   gi::ThreadPool pool(4);
//   pool.parallel_for(n, [&](std::size_t i) { out[i] = shade(i); });

#include <gi/progress.h>

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace gi {

class ThreadPool {
 public:
  /// `threads` = 0 uses std::thread::hardware_concurrency(). The calling thread also works,
  /// so a pool of 1 runs everything on the caller.
  explicit ThreadPool(unsigned threads = 0);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned size() const { return static_cast<unsigned>(workers_.size()) + 1; }

  /// Calls fn(i) for every i in [0, count), items handed out in chunks of `grain`. Blocks
  /// until all are done. Not re-entrant (fn must not call parallel_for on the same pool).
  void parallel_for(std::size_t count, const std::function<void(std::size_t)>& fn, std::size_t grain = 1);

  /// parallel_for in batches (at most 200), calling `progress` (if set) with the fraction
  /// done after each batch, from the calling thread. Returns false, having stopped after
  /// the batch, when the callback returns false (cancelled).
  bool parallel_for_with_progress(std::size_t count, const ProgressCallback& progress,
                                  const std::function<void(std::size_t)>& fn, std::size_t grain = 4);

 private:
  void worker_loop();
  void run_chunks();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  const std::function<void(std::size_t)>* job_ = nullptr;
  std::size_t count_ = 0;
  std::size_t grain_ = 1;
  std::atomic<std::size_t> next_{0};
  std::size_t busy_ = 0;
  std::uint64_t generation_ = 0;
  bool stop_ = false;
};

}  // namespace gi
