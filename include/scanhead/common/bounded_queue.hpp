/// \file bounded_queue.hpp
/// \brief A first-in first-out queue between two threads that holds at most a fixed number of items.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <utility>

namespace scanhead
{
/// \brief One producer, one consumer. push() waits while the queue is full, pop() while it is
/// empty, so memory is bounded by the capacity whatever the speeds of the two sides. close() ends
/// the stream (pop() drains what is left, then returns nothing); cancel() ends it at once (the
/// consumer gave up: push() returns false and the producer stops).
template <typename T>
class BoundedQueue
{
public:
  /// \throws std::invalid_argument if \p capacity is 0
  explicit BoundedQueue(std::size_t capacity)
    : capacity_(capacity)
  {
    if (capacity == 0)
      throw std::invalid_argument("BoundedQueue: capacity must be >= 1");
  }

  /// \brief Appends \p item, waiting for room. \return false if the queue was cancelled (item dropped)
  bool push(T item)
  {
    std::unique_lock<std::mutex> lock(mutex_);
    not_full_.wait(lock, [this] { return cancelled_ || items_.size() < capacity_; });
    if (cancelled_)
      return false;
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }

  /// \brief The oldest item, waiting for one; nothing once the queue is closed and empty, or cancelled.
  std::optional<T> pop()
  {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [this] { return cancelled_ || closed_ || !items_.empty(); });
    if (cancelled_ || items_.empty())
      return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    not_full_.notify_one();
    return item;
  }

  /// \brief The producer is done: pop() returns the items left, then nothing.
  void close()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    not_empty_.notify_all();
  }

  /// \brief The consumer gave up: both sides return at once; items still queued are dropped.
  void cancel()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cancelled_ = true;
    items_.clear();
    not_empty_.notify_all();
    not_full_.notify_all();
  }

private:
  const std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::deque<T> items_;
  bool closed_ = false;
  bool cancelled_ = false;
};
}  // namespace scanhead
