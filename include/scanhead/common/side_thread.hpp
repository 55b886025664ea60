/// \file side_thread.hpp
/// \brief One long-lived thread that runs one task at a time beside the caller (a fork–join pair
/// without creating a thread per task).
#pragma once

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace scanhead
{
/// \brief start(task) hands \p task to the thread; wait() returns when it is done and rethrows
/// what it threw. Creating a std::thread (std::async) per chunk costs ~20–50 µs: on a 30 M-sample
/// layer in chunks of 1000 that is ~1 s, which this thread, started once, saves.
///
/// \pre one task at a time: start() after wait() (checked: std::logic_error)
class SideThread
{
public:
  SideThread()
    : thread_([this] { loop(); })
  {
  }
  ~SideThread()
  {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  SideThread(const SideThread&) = delete;
  SideThread& operator=(const SideThread&) = delete;

  void start(std::function<void()> task)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (task_ || busy_)
      throw std::logic_error("SideThread::start() while a task is running (wait() first)");
    task_ = std::move(task);
    busy_ = true;
    wake_.notify_all();
  }

  /// \brief Waits for the task of the last start() (no-op without one); rethrows its exception.
  void wait()
  {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return !busy_; });
    if (error_)
    {
      std::exception_ptr error = error_;
      error_ = nullptr;
      std::rethrow_exception(error);
    }
  }

private:
  void loop()
  {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;)
    {
      wake_.wait(lock, [this] { return stopping_ || task_; });
      if (!task_)
        return;  // stopping, nothing left to run
      std::function<void()> task = std::move(task_);
      task_ = nullptr;
      lock.unlock();
      std::exception_ptr error;
      try
      {
        task();
      }
      catch (...)
      {
        error = std::current_exception();
      }
      lock.lock();
      error_ = error;
      busy_ = false;
      done_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::function<void()> task_;
  bool busy_ = false;
  bool stopping_ = false;
  std::exception_ptr error_;
  std::thread thread_;  ///< last: started once the members above exist
};
}  // namespace scanhead
