// The energy stage's tracker thread: tasks run on another thread, wait() joins and rethrows.
#include <gtest/gtest.h>

#include <stdexcept>
#include <thread>

#include "scanhead/common/side_thread.hpp"

using scanhead::SideThread;

TEST(SideThread, RunsEachTaskOnItsThreadAndWaits)
{
  SideThread side;
  std::thread::id task_thread;
  long sum = 0;
  for (int i = 1; i <= 1000; ++i)
  {
    side.start([&, i] {
      task_thread = std::this_thread::get_id();
      sum += i;
    });
    side.wait();
    EXPECT_EQ(sum, static_cast<long>(i) * (i + 1) / 2);
  }
  EXPECT_NE(task_thread, std::this_thread::get_id());
  side.wait();  // nothing running: returns at once
}

TEST(SideThread, RethrowsTheTaskErrorOnceAndKeepsWorking)
{
  SideThread side;
  side.start([] { throw std::runtime_error("tracker failed"); });
  EXPECT_THROW(side.wait(), std::runtime_error);
  side.wait();  // the error was reported once
  bool ran = false;
  side.start([&] { ran = true; });
  side.wait();
  EXPECT_TRUE(ran);
}

TEST(SideThread, RefusesASecondTaskBeforeWait)
{
  SideThread side;
  side.start([] { std::this_thread::sleep_for(std::chrono::milliseconds(20)); });
  EXPECT_THROW(side.start([] {}), std::logic_error);
  side.wait();
}
