#include "core/thread_pool.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <thread>

namespace gi {

ThreadPool::ThreadPool(unsigned threads) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  size_ = std::min(threads, kMaxThreads);
  // One slot reserved for the calling thread (the default), the rest for TBB's workers.
  arena_ = std::make_unique<tbb::task_arena>(static_cast<int>(size_));
}

ThreadPool::~ThreadPool() = default;

void ThreadPool::parallel_for(std::size_t count, const std::function<void(std::size_t)>& fn, std::size_t grain) {
  if (count == 0) return;
  if (size_ == 1) {  // the caller alone: no task overhead
    for (std::size_t i = 0; i < count; ++i) fn(i);
    return;
  }
  arena_->execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, std::max<std::size_t>(1, grain)),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i < r.end(); ++i) fn(i);
                      });
  });
}

bool ThreadPool::parallel_for_with_progress(std::size_t count, const ProgressCallback& progress,
                                            const std::function<void(std::size_t)>& fn, std::size_t grain) {
  const std::size_t batches = std::clamp<std::size_t>(count / 256, 1, 200);
  const std::size_t per_batch = (count + batches - 1) / batches;
  for (std::size_t begin = 0; begin < count; begin += per_batch) {
    const std::size_t n = std::min(per_batch, count - begin);
    parallel_for(
        n, [&](std::size_t i) { fn(begin + i); }, grain);
    if (progress && !progress(static_cast<double>(begin + n) / static_cast<double>(count))) return false;
  }
  return true;
}

}  // namespace gi
