#include "core/thread_pool.h"

#include <algorithm>

namespace gi {

ThreadPool::ThreadPool(unsigned threads) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  for (unsigned i = 1; i < threads; ++i) workers_.emplace_back([this] { worker_loop(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void ThreadPool::run_chunks() {
  for (;;) {
    const std::size_t begin = next_.fetch_add(grain_);
    if (begin >= count_) return;
    const std::size_t end = std::min(count_, begin + grain_);
    for (std::size_t i = begin; i < end; ++i) (*job_)(i);
  }
}

void ThreadPool::worker_loop() {
  std::uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      ++busy_;
    }
    run_chunks();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      --busy_;
    }
    done_.notify_all();
  }
}

void ThreadPool::parallel_for(std::size_t count, const std::function<void(std::size_t)>& fn, std::size_t grain) {
  if (count == 0) return;
  {
    // Wait for stragglers of the previous call (workers still leaving run_chunks) before
    // publishing the new job, so no worker reads count_/grain_ while they change.
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return busy_ == 0; });
    job_ = &fn;
    count_ = count;
    grain_ = std::max<std::size_t>(1, grain);
    next_.store(0);
    ++generation_;
  }
  wake_.notify_all();
  run_chunks();
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [&] { return busy_ == 0; });
  job_ = nullptr;
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
