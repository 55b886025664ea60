/// \file python_plots.cpp
#include "python_plots.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/package_path.hpp"

namespace scanhead
{
namespace
{
constexpr const char* kPython = "/usr/bin/python3";

void warnSkipped(const std::string& what, const std::string& path)
{
  std::fprintf(stderr, "scanhead: %s skipped (%s failed; is python3-matplotlib installed?)\n", what.c_str(),
               path.c_str());
}

/// waitpid that retries on EINTR; \return the status, or -1
int reap(pid_t pid)
{
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR)
      return -1;
  return status;
}
}  // namespace

bool runPythonScript(const std::string& script, const std::vector<std::string>& arguments, const std::string& what)
{
  // Each word single-quoted, its own quotes as '\'' (labels and paths come from users).
  auto quoted = [](const std::string& word) {
    std::string out = "'";
    for (char c : word)
      out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
  };
  const std::string path = resolvePackagePath(script);
  std::string command = std::string(kPython) + " " + quoted(path);
  for (const std::string& argument : arguments)
    command += " " + quoted(argument);
  if (std::system((command + " 2>&1").c_str()) == 0)
    return true;
  warnSkipped(what, path);
  return false;
}

PlotHook pythonPlotHook(const std::string& script, const std::string& what)
{
  return [script, what](const std::string& dir) { runPythonScript(script, {dir}, what); };
}

PlotHook plotFinisher()
{
  return pythonPlotHook("scripts/plot_results.py");
}

PlotProcess::PlotProcess(const std::string& script, const std::vector<std::string>& arguments, const std::string& what)
  : path_(resolvePackagePath(script))
  , what_(what)
{
  std::vector<std::string> words = {kPython, path_};
  words.insert(words.end(), arguments.begin(), arguments.end());
  words.emplace_back("--serve");
  std::vector<char*> argv;
  for (std::string& word : words)
    argv.push_back(&word[0]);
  argv.push_back(nullptr);
  int ends[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ends) != 0)
    return;
  std::fflush(nullptr);  // the child must not repeat our buffered output
  const pid_t pid = fork();
  if (pid == 0)
  {
    // Only async-signal-safe calls until exec: its own process group (so that cancel() stops the
    // drawing processes it forks too), stdin from the socket, stderr to our stdout.
    if (setpgid(0, 0) != 0 || dup2(ends[1], STDIN_FILENO) < 0 || dup2(STDOUT_FILENO, STDERR_FILENO) < 0)
      _exit(127);
    execv(kPython, argv.data());
    _exit(127);
  }
  close(ends[1]);
  if (pid < 0)
  {
    close(ends[0]);
    return;
  }
  setpgid(pid, pid);  // also here: the group exists before cancel() can use it, whoever runs first
  pid_ = pid;
  socket_ = ends[0];
}

PlotProcess::~PlotProcess()
{
  cancel();
}

void PlotProcess::cancel()
{
  if (pid_ > 0)
  {
    kill(-pid_, SIGTERM);  // the script and the drawing processes it forked: the plots are not wanted
    reap(pid_);
    pid_ = -1;
  }
  if (socket_ >= 0)
  {
    close(socket_);
    socket_ = -1;
  }
}

namespace
{
/// Sends all of \p text on \p socket; false if the reader is gone.
bool sendAll(int socket, const std::string& text)
{
  for (std::size_t at = 0; at < text.size();)
  {
    const ssize_t n = send(socket, text.data() + at, text.size() - at, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR)
      continue;
    if (n <= 0)
      return false;
    at += static_cast<std::size_t>(n);
  }
  return true;
}
}  // namespace

void PlotProcess::begin(const std::string& dir)
{
  if (begun_ || pid_ < 0)
    return;
  begun_ = true;
  sent_ = sendAll(socket_, dir + "\n");
}

bool PlotProcess::plot(const std::string& dir)
{
  if (used_)
    return false;
  used_ = true;
  if (pid_ < 0)
  {
    warnSkipped(what_, path_);  // could not start (no socket pair or fork)
    return false;
  }
  begin(dir);
  sent_ = sendAll(socket_, "images\n") && sent_;
  close(socket_);
  socket_ = -1;
  const int status = reap(pid_);
  pid_ = -1;
  if (sent_ && status >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0)
    return true;
  warnSkipped(what_, path_);
  return false;
}

PlotHook PlotProcess::hook()
{
  return [this](const std::string& dir) { plot(dir); };
}

PlotHook PlotProcess::beginHook()
{
  return [this](const std::string& dir) { begin(dir); };
}

std::unique_ptr<PlotProcess> startResultsPlots(const std::string& plots)
{
  if (plots == "none")
    return nullptr;
  if (plots != "summary" && plots != "all")
    throw ConfigError("--plots must be none, summary or all (got '" + plots + "')");
  return std::make_unique<PlotProcess>("scripts/plot_results.py", std::vector<std::string>{"--plots", plots});
}
}  // namespace scanhead
