/// \file task_pool.hpp
/// \brief Runs independent file-writing tasks on a few threads: the results folder's files
/// (metrics, job, trace, the energy images) are written side by side, each by one task, so their
/// bytes do not depend on the number of threads.
#pragma once

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>

namespace scanhead
{
class TaskPool
{
public:
  using Task = std::function<void()>;

  /// \param[in] threads  tasks run at the same time at most (the calling thread of run() is one of
  /// them); 0: std::thread::hardware_concurrency(), at most 4 (memory: each task holds its file)
  explicit TaskPool(unsigned threads = 0);

  /// \brief Queues \p task; a running task may add more (the energy overview adds its images).
  /// Tasks start in the order they were added: add the longest first.
  void add(Task task);

  /// \brief Runs every task, those added meanwhile included, and returns when all have finished.
  /// \throws the first exception a task threw (the other tasks still run to the end, so no
  /// task outlives the call)
  void run();

  unsigned threads() const { return threads_; }

private:
  void work();

  unsigned threads_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Task> queue_;
  unsigned running_ = 0;
  std::exception_ptr error_;
};
}  // namespace scanhead
