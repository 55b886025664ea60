// The queue between the batch chain's two threads: order, the capacity bound, close and cancel.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "scanhead/common/bounded_queue.hpp"

using scanhead::BoundedQueue;

TEST(BoundedQueue, KeepsOrderAndDrainsAfterClose)
{
  BoundedQueue<int> queue(3);
  std::thread producer([&] {
    for (int i = 0; i < 1000; ++i)
      ASSERT_TRUE(queue.push(i));
    queue.close();
  });
  std::vector<int> got;
  while (std::optional<int> item = queue.pop())
    got.push_back(*item);
  producer.join();
  ASSERT_EQ(got.size(), 1000u);
  for (int i = 0; i < 1000; ++i)
    EXPECT_EQ(got[static_cast<std::size_t>(i)], i);
}

TEST(BoundedQueue, ProducerWaitsWhenFull)
{
  BoundedQueue<int> queue(2);
  std::atomic<int> pushed{0};
  std::thread producer([&] {
    for (int i = 0; i < 5; ++i)
    {
      queue.push(i);
      ++pushed;
    }
    queue.close();
  });
  // Nothing is taken: the producer must stop at the capacity.
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(pushed.load(), 2);
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(queue.pop().value(), i);
  EXPECT_FALSE(queue.pop().has_value());
  producer.join();
  EXPECT_EQ(pushed.load(), 5);
}

TEST(BoundedQueue, CancelReleasesAWaitingProducer)
{
  BoundedQueue<int> queue(1);
  bool last_push = true;
  std::thread producer([&] {
    queue.push(0);
    last_push = queue.push(1);  // waits: the queue is full
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  queue.cancel();
  producer.join();
  EXPECT_FALSE(last_push);
  EXPECT_FALSE(queue.pop().has_value());
  EXPECT_THROW(BoundedQueue<int>(0), std::invalid_argument);
}
