// TaskPool: every task runs once (those added by running tasks too), at most `threads` at a time,
// and the first exception comes back from run() after every task has finished.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "scanhead/report/task_pool.hpp"

using namespace scanhead;

TEST(TaskPool, RunsEveryTaskOnceIncludingTasksAddedByTasks)
{
  for (unsigned threads : {1u, 2u, 5u})
  {
    TaskPool pool(threads);
    std::atomic<int> parents{0}, children{0};
    for (int k = 0; k < 40; ++k)
      pool.add([&] {
        ++parents;
        pool.add([&] { ++children; });
      });
    pool.run();
    EXPECT_EQ(parents.load(), 40) << threads << " threads";
    EXPECT_EQ(children.load(), 40) << threads << " threads";
  }
}

TEST(TaskPool, RunsAtMostItsThreadsAtOnceAndUsesThem)
{
  TaskPool pool(3);
  std::atomic<int> now{0}, most{0};
  for (int k = 0; k < 12; ++k)
    pool.add([&] {
      const int n = ++now;
      int seen = most.load();
      while (n > seen && !most.compare_exchange_weak(seen, n))
      {
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      --now;
    });
  pool.run();
  EXPECT_LE(most.load(), 3);
  EXPECT_GE(most.load(), 2);  // 12 sleeping tasks on 3 threads overlap
}

TEST(TaskPool, FirstExceptionAfterEveryTaskFinished)
{
  TaskPool pool(2);
  std::atomic<int> finished{0};
  pool.add([] { throw std::runtime_error("disk full"); });
  for (int k = 0; k < 10; ++k)
    pool.add([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      ++finished;
    });
  try
  {
    pool.run();
    FAIL() << "no exception";
  }
  catch (const std::runtime_error& e)
  {
    EXPECT_STREQ(e.what(), "disk full");
  }
  EXPECT_EQ(finished.load(), 10);
  // The pool is usable again, without the old error.
  pool.add([&] { ++finished; });
  EXPECT_NO_THROW(pool.run());
  EXPECT_EQ(finished.load(), 11);
}
