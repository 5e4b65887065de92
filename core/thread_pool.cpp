#include "core/thread_pool.h"

#include <cstdlib>

#include <ATen/Parallel.h>
#include <omp.h>

#include <algorithm>

namespace segue {

int resolve_threads(int requested) {
  if (requested > 0) return requested;
  // Ranks sharing a host (LOCAL_WORLD_SIZE, set by --nproc as torchrun does) share its cores.
  const char* local = std::getenv("LOCAL_WORLD_SIZE");
  const int ranks = local ? std::max(1, std::atoi(local)) : 1;
  return std::max(1, int(std::thread::hardware_concurrency()) / ranks);
}

ThreadPool::ThreadPool(int threads) {
  // Workers start from generation 0: a job posted before a thread first runs is still seen.
  // A worker's items are its share of the parallelism: the BLAS calls they make (an
  // update's two networks, OnPolicyLearner::run_both) run on it alone. OpenMP's thread
  // count, which OpenBLAS follows, is each thread's own and a new thread's is every core.
  for (int i = 1; i < std::max(1, threads); ++i)
    workers_.emplace_back([this] {
      omp_set_num_threads(1);
      work(0);
    });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    generation_.fetch_add(1);
  }
  start_.notify_all();
  for (auto& w : workers_) w.join();
}

void ThreadPool::drain() {
  for (int i = next_.fetch_add(1); i < n_; i = next_.fetch_add(1)) {
    try {
      (*job_)(i, i + 1);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
    }
  }
}

void ThreadPool::parallel_for(int n, const std::function<void(int, int)>& fn) {
  if (workers_.empty() || n <= 1) {
    for (int i = 0; i < n; ++i) fn(i, i + 1);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &fn;
    n_ = n;
    next_.store(0);
    busy_.store(static_cast<int>(workers_.size()));
    generation_.fetch_add(1);
  }
  start_.notify_all();
  drain();
  while (busy_.load(std::memory_order_acquire) > 0) std::this_thread::yield();
  std::exception_ptr error;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::swap(error, error_);
  }
  if (error) std::rethrow_exception(error);
}

void ThreadPool::work(long seen) {
  for (;;) {
    // Spin a little for the next job, then sleep.
    for (int spin = 0; spin < 20000 && generation_.load(std::memory_order_acquire) == seen; ++spin)
      std::this_thread::yield();
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, [&] { return generation_.load() != seen; });
      if (stop_) return;
      seen = generation_.load();
    }
    drain();
    busy_.fetch_sub(1, std::memory_order_release);
  }
}

void set_torch_threads(int threads) {
  at::set_num_threads(resolve_threads(threads));
  static bool interop_set = false;  // may only be set once per process
  if (!interop_set) {
    at::set_num_interop_threads(1);
    interop_set = true;
  }
}

}  // namespace segue
