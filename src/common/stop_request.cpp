/// \file stop_request.cpp
#include "scanhead/common/stop_request.hpp"

#include <atomic>
#include <csignal>
#include <cstring>

namespace scanhead
{
namespace
{
std::atomic<int> stop_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "a signal handler may only touch lock-free atomics");
}  // namespace

StopRequested::StopRequested(int signal)
  : std::runtime_error("interrupted by " + signalName(signal))
  , signal_(signal)
{
}

void requestStop(int signal) noexcept
{
  int none = 0;
  stop_signal.compare_exchange_strong(none, signal);
}

int stopRequest() noexcept
{
  return stop_signal.load();
}

void clearStopRequest() noexcept
{
  stop_signal.store(0);
}

void throwIfStopRequested()
{
  if (const int signal = stop_signal.load())
    throw StopRequested(signal);
}

std::string signalName(int signal)
{
  switch (signal)
  {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    case SIGKILL:
      return "SIGKILL";
    case SIGSEGV:
      return "SIGSEGV";
    case SIGABRT:
      return "SIGABRT";
    case SIGPIPE:
      return "SIGPIPE";
    default:
      return "signal " + std::to_string(signal);
  }
}
}  // namespace scanhead
