#pragma once
// A fixed pool of workers for data-parallel loops over independent items (environments).
// Items are handed out one at a time from an atomic counter, so a slow item (an episode
// reset, a contact-heavy step) does not leave the other threads idle; which thread runs
// which item never changes a result. Between jobs, workers spin briefly before sleeping:
// a vector step is a few hundred microseconds, comparable to a futex wake-up.
#include <atomic>
#include <condition_variable>
#include <exception>
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
  // Calls fn(i, i + 1) for every i in [0, n) and waits for all of them. An exception
  // reaches the caller: with workers, the first one thrown, once every other item has run
  // (uncaught on a worker it would end the process).
  void parallel_for(int n, const std::function<void(int, int)>& fn);

 private:
  void work(long seen);
  void drain();
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_;
  const std::function<void(int, int)>* job_ = nullptr;
  int n_ = 0;
  std::atomic<int> next_{0};
  std::atomic<int> busy_{0};        // workers still inside the current job
  std::atomic<long> generation_{0};
  bool stop_ = false;
  std::exception_ptr error_;        // the current job's first exception (under mutex_)
};

// Threads to use for a "threads" setting: 0 means every core. A setting above
// kMaxThreads is refused where it is read (a typo must not start a million threads).
constexpr int kMaxThreads = 1024;
int resolve_threads(int requested);
// Sets LibTorch's intra-op threads (0: every core) and its inter-op threads to one.
void set_torch_threads(int threads);

}  // namespace segue
