/// \file stop_request.hpp
/// \brief The process-wide "stop now" request: set by a signal handler (SIGINT, SIGTERM) of a tool,
/// polled by long work (the chain's progress callback, the results writer, the plot wait), which then
/// unwinds through its ordinary error path so that every temporary file is removed.
///
/// The core never installs a handler (a ROS node keeps roscpp's own); requestStop() is the only
/// function here a handler may call: it stores into a lock-free atomic, which is async-signal-safe
/// ([support.signal] of C++17). Nothing in a library sets the request, so code that never installs
/// a handler sees no change.
#pragma once

#include <stdexcept>
#include <string>

namespace scanhead
{
/// \brief Thrown by throwIfStopRequested(): the work was abandoned on a signal; its cleanup has run
/// (or runs during the unwinding). A tool exits with 128 + signal() (130 for SIGINT, 143 for SIGTERM).
class StopRequested : public std::runtime_error
{
public:
  explicit StopRequested(int signal);
  int signal() const { return signal_; }

private:
  int signal_;
};

/// \brief Records a stop request for signal \p signal (the first one wins). Async-signal-safe.
void requestStop(int signal) noexcept;

/// \brief The signal of the stop request, 0 if there is none.
int stopRequest() noexcept;

/// \brief Forgets the request (tests; a tool that handled it and goes on).
void clearStopRequest() noexcept;

/// \throws StopRequested if a stop was requested
void throwIfStopRequested();

/// \brief "SIGINT", "SIGTERM", ... (or "signal N"); not for signal handlers.
std::string signalName(int signal);
}  // namespace scanhead
