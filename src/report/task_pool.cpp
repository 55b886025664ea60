/// \file task_pool.cpp
#include "scanhead/report/task_pool.hpp"

#include <algorithm>
#include <system_error>
#include <thread>
#include <vector>

namespace scanhead
{
TaskPool::TaskPool(unsigned threads)
  : threads_(threads > 0 ? threads : std::clamp(std::thread::hardware_concurrency(), 1u, 4u))
{
}

void TaskPool::add(Task task)
{
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(task));
  }
  changed_.notify_one();
}

void TaskPool::work()
{
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;)
  {
    changed_.wait(lock, [this] { return !queue_.empty() || running_ == 0; });
    if (queue_.empty())
      break;  // nothing queued and nothing running that could queue more
    Task task = std::move(queue_.front());
    queue_.pop_front();
    ++running_;
    lock.unlock();
    try
    {
      task();
    }
    catch (...)
    {
      const std::lock_guard<std::mutex> error_lock(mutex_);
      if (!error_)
        error_ = std::current_exception();
    }
    lock.lock();
    --running_;
    changed_.notify_all();
  }
}

void TaskPool::run()
{
  std::vector<std::thread> helpers;
  for (unsigned k = 1; k < threads_; ++k)
  {
    try
    {
      helpers.emplace_back([this] { work(); });
    }
    catch (const std::system_error&)
    {
      break;  // no more threads to be had: the ones started (and this one) do the work
    }
  }
  work();
  for (std::thread& t : helpers)
    t.join();
  if (error_)
  {
    std::exception_ptr error = error_;
    error_ = nullptr;
    std::rethrow_exception(error);
  }
}
}  // namespace scanhead
