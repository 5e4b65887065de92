#pragma once
// A fixed pool of workers for data-parallel loops. parallel_for splits [0, n) into one
// contiguous block per thread (the caller works the first block), so which thread steps
// which environment never changes a result.
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace segue {

class ThreadPool {
 public:
  explicit ThreadPool(int threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;
  int size() const { return static_cast<int>(workers_.size()) + 1; }
  // Calls fn(begin, end) on disjoint blocks covering [0, n) and waits for all of them.
  void parallel_for(int n, const std::function<void(int, int)>& fn);

 private:
  void work(int index);
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_, finished_;
  const std::function<void(int, int)>* job_ = nullptr;
  int n_ = 0;
  long generation_ = 0;
  int pending_ = 0;
  bool stop_ = false;
};

// Threads to use for a "threads" setting: 0 means every core.
int resolve_threads(int requested);

}  // namespace segue
