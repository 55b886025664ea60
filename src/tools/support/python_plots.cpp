/// \file python_plots.cpp
#include "python_plots.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/package_path.hpp"
#include "scanhead/common/stop_request.hpp"

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

/// Whether process group \p group has a member that is not a zombie (a zombie writes nothing; an
/// orphan's zombie waits for whatever reaps orphans here, which may be slow or nothing).
bool groupAlive(pid_t group)
{
  if (kill(-group, 0) != 0)
    return false;
  DIR* proc = opendir("/proc");
  if (proc == nullptr)
    return true;
  bool alive = false;
  while (const dirent* entry = readdir(proc))
  {
    if (entry->d_name[0] < '1' || entry->d_name[0] > '9')
      continue;
    std::ifstream file(std::string("/proc/") + entry->d_name + "/stat");
    std::string stat;
    std::getline(file, stat);
    // "pid (comm) state ppid pgrp ...": comm may hold spaces and parentheses; the last ')' ends it.
    const std::size_t close = stat.rfind(')');
    if (close == std::string::npos)
      continue;
    char state = 0;
    long ppid = 0, pgrp = 0;
    if (std::sscanf(stat.c_str() + close + 1, " %c %ld %ld", &state, &ppid, &pgrp) == 3 && pgrp == group &&
        state != 'Z' && state != 'X')
    {
      alive = true;
      break;
    }
  }
  closedir(proc);
  return alive;
}

void sleepMs(int ms)
{
  poll(nullptr, 0, ms);
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
  return [](const std::string& dir) {
    PlotProcess plots("scripts/plot_results.py", {"--plots", "all"});
    if (!plots.plot(dir))
      throw PlotError(plots.failure());
  };
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
  // Signals are blocked across the fork: between fork and exec the child still has our handlers
  // (scanhead_run's only record a stop request), so a SIGTERM from cancel() landing there would be
  // swallowed and the script would start anyway, with nobody left to stop it. The child resets
  // its caught signals to their defaults before unblocking them, so such a signal ends it.
  sigset_t all;
  sigset_t old;
  sigfillset(&all);
  pthread_sigmask(SIG_SETMASK, &all, &old);
  const pid_t pid = fork();
  if (pid == 0)
  {
    // Only async-signal-safe calls until exec: its own process group (so that cancel() stops the
    // drawing processes it forks too), stdin from the socket, stderr to our stdout.
    for (const int sig : {SIGINT, SIGTERM, SIGHUP})
    {
      struct sigaction action;
      if (sigaction(sig, nullptr, &action) == 0 && action.sa_handler != SIG_IGN)
        signal(sig, SIG_DFL);  // an ignored signal (nohup) stays ignored, as exec would keep it
    }
    sigprocmask(SIG_SETMASK, &old, nullptr);
    if (setpgid(0, 0) != 0 || dup2(ends[1], STDIN_FILENO) < 0 || dup2(STDOUT_FILENO, STDERR_FILENO) < 0)
      _exit(127);
    execv(kPython, argv.data());
    _exit(127);
  }
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  close(ends[1]);
  if (pid < 0)
  {
    close(ends[0]);
    return;
  }
  setpgid(pid, pid);  // also here: the group exists before cancel() can use it, whoever runs first
  pid_ = pid;
  group_ = pid;
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
    if (socket_ >= 0)
    {
      close(socket_);  // end of its input too, should it be reading it
      socket_ = -1;
    }
    // Bounded wait: whatever the script does with SIGTERM, it is gone within 2 s.
    int status = 0;
    for (int waited = 0; waitpid(pid_, &status, WNOHANG) == 0; waited += 10)
    {
      if (waited == 2000)
        kill(-pid_, SIGKILL);
      sleepMs(10);
    }
    pid_ = -1;
  }
  if (group_ > 0)
  {
    // The drawing processes outlive the script by a moment: wait until none is left (2 s, then
    // SIGKILL), since the caller removes the folder they write into next. (Signalled only while
    // a member is left: the group's id cannot be reused before it is empty.)
    for (int waited = 0; groupAlive(group_); waited += 10)
    {
      if (waited == 2000)
        kill(-group_, SIGKILL);
      if (waited > 4000)
        break;
      sleepMs(10);
    }
    group_ = -1;
  }
  if (socket_ >= 0)
  {
    close(socket_);
    socket_ = -1;
  }
}

bool PlotProcess::judge(int status)
{
  std::string how;
  if (status < 0)
    how = "could not be waited for";
  else if (WIFSIGNALED(status))
    how = "was killed by " + signalName(WTERMSIG(status));
  else if (WIFEXITED(status) && WEXITSTATUS(status) == ENOSPC)  // plot_results.py's "disk full"
    how = std::string("found the disk full (") + std::strerror(ENOSPC) + ")";
  else if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
    how = std::string("could not be started (") + kPython + " missing?)";
  else if (WIFEXITED(status) && WEXITSTATUS(status) != 0)
    how = "exited with status " + std::to_string(WEXITSTATUS(status)) +
          " (its message is above; is python3-matplotlib installed?)";
  else if (!sent_)
    how = "stopped reading the folder to plot";
  else if (!used_)
    how = "ended before the data was written";
  if (how.empty())
    return true;
  failure_ = what_ + " failed: " + path_ + " " + how;
  return false;
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

bool PlotProcess::ended()
{
  if (ended_)
    return true;
  if (pid_ <= 0 || used_)
    return false;
  int status = 0;
  const pid_t got = waitpid(pid_, &status, WNOHANG);
  if (got == 0 || (got < 0 && errno == EINTR))
    return false;
  pid_ = -1;
  ended_ = true;
  judge(got > 0 ? status : -1);
  return true;
}

bool PlotProcess::plot(const std::string& dir)
{
  if (used_)
    return false;
  if (ended())
  {
    used_ = true;
    return false;  // failure_ says how it ended
  }
  used_ = true;
  if (pid_ < 0)
  {
    failure_ = what_ + " failed: " + path_ + " could not be started (no socket pair or fork)";
    return false;
  }
  begin(dir);
  sent_ = sendAll(socket_, "images\n") && sent_;
  close(socket_);
  socket_ = -1;
  // Polled rather than a blocking waitpid: a signal may be delivered to any of this process'
  // threads, so the wait would not see EINTR; the stop request is seen within 10 ms.
  int status = -1;
  for (;;)
  {
    const pid_t got = waitpid(pid_, &status, WNOHANG);
    if (got == pid_)
      break;
    if (got < 0 && errno != EINTR)
    {
      status = -1;
      break;
    }
    if (stopRequest() != 0)
    {
      cancel();
      throwIfStopRequested();
    }
    sleepMs(10);
  }
  pid_ = -1;
  if (!judge(status))
  {
    cancel();  // drawing processes it left
    return false;
  }
  group_ = -1;  // ended cleanly: it waited for its drawing processes
  return true;
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
