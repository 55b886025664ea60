/// \file study_runner.cpp
/// \brief Cases of a study as scanhead_run processes (study_runner.hpp).
#include "study_runner.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>

#include "scanhead/common/errors.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/stop_request.hpp"
#include "scanhead/common/text_file.hpp"
#include "scanhead/study/study_estimate.hpp"

namespace scanhead
{
namespace
{
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// \brief Starts scanhead_run for \p c, its stdout and stderr into the case's log; \p one_thread: with
/// stream.threads=1 instead of the case's own. \return its pid
pid_t startCase(const std::string& dir, const CaseRecord& c, const StudyRunOptions& options, bool one_thread = false)
{
  const std::string log = caseLogPath(dir, c.id);
  std::vector<std::string> words = {
      options.scanhead_run,      "--job",   c.job,         "--config", caseConfigPath(dir, c.id), "--out",
      caseResultsDir(dir, c.id), "--plots", options.plots, "--quiet"};
  if (one_thread)
    words.insert(words.end(), {"--set", "stream.threads=1"});
  std::vector<char*> argv;
  for (std::string& w : words)
    argv.push_back(w.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0)
    throw InputError(std::string("cannot start a case (fork: ") + std::strerror(errno) + ")");
  if (pid == 0)
  {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0)
    {
      ::dup2(fd, STDOUT_FILENO);
      ::dup2(fd, STDERR_FILENO);
      ::close(fd);
    }
    ::execv(argv[0], argv.data());
    std::fprintf(stderr, "scanhead_study: cannot start %s: %s\n", argv[0], std::strerror(errno));
    ::_exit(127);
  }
  return pid;
}

/// \brief Records how the process of \p c ended (\p status of waitpid). \return true if the case is done
bool finishCase(const std::string& dir, const CaseRecord& c, int status, double wall_s)
{
  const bool published = fs::exists(fs::path(caseResultsDir(dir, c.id)) / "metrics.yaml");
  if (stopRequest() != 0 && !published)
  {
    // The study was stopped (Ctrl-C, SIGTERM): the case did not fail, it stays pending for the next run.
    fs::remove(fs::path(dir) / "status" / (c.id + ".yaml"));
    return false;
  }
  int exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::string error;
  if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0 && published))
  {
    const std::string log = readFileOrEmpty(caseLogPath(dir, c.id));
    error = WIFSIGNALED(status) ? std::string("killed by signal ") + std::to_string(WTERMSIG(status)) + " (" +
                                      strsignal(WTERMSIG(status)) + ")"
                                : errorLineOf(log);
    if (error.empty())
      error = "exited with status " + std::to_string(exit_code) + (published ? "" : ", no results");
  }
  writeCaseStatus(dir, c.id, error.empty(), exit_code, wall_s, error);
  return error.empty();
}

}  // namespace

std::string siblingExecutable(const std::string& name)
{
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  const fs::path sibling = self.parent_path() / name;
  if (ec || !fs::exists(sibling))
    throw InputError("cannot find " + name + " beside this program (" + self.string() + ")");
  return sibling.string();
}

bool runStudyCase(const std::string& dir, const CaseRecord& c, const StudyRunOptions& options)
{
  const Clock::time_point start = Clock::now();
  const pid_t pid = startCase(dir, c, options);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR)
  {
  }
  return finishCase(dir, c, status, std::chrono::duration<double>(Clock::now() - start).count());
}

std::size_t runStudyLocally(const std::string& dir, const std::vector<CaseRecord>& records,
                            const std::vector<std::size_t>& cases, const StudyRunOptions& options)
{
  const Clock::time_point start = Clock::now();
  std::map<pid_t, std::pair<std::size_t, Clock::time_point>> running;
  std::size_t next = 0, finished = 0, failed = 0, last_tenth = 0;
  double case_seconds = 0.0;  // summed wall time of the finished cases
  auto report = [&] {
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    const double left = finished == 0 ? 0.0
                                      : (case_seconds / static_cast<double>(finished)) *
                                            static_cast<double>(cases.size() - finished) /
                                            static_cast<double>(std::max<unsigned>(1, options.workers));
    const std::size_t tenth = cases.empty() ? 10 : 10 * finished / cases.size();
    if (!options.progress_tty && tenth == last_tenth && finished != cases.size())
      return;
    last_tenth = tenth;
    const int width = 30;
    const int filled = cases.empty() ? width : static_cast<int>(width * finished / cases.size());
    std::fprintf(stderr, "%s[%s%s] %zu/%zu cases, %zu failed, %s elapsed%s%s", options.progress_tty ? "\r" : "",
                 std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(width - filled), '.').c_str(), finished, cases.size(), failed,
                 durationText(elapsed).c_str(),
                 finished > 0 && finished < cases.size() ? (", ~" + durationText(left) + " left").c_str() : "",
                 options.progress_tty && finished != cases.size() ? "   " : "\n");
    std::fflush(stderr);
  };
  report();
  while (next < cases.size() || !running.empty())
  {
    if (stopRequest() != 0 && next < cases.size())
    {
      next = cases.size();  // start nothing more; the running cases get the signal and end
      for (const auto& [pid, what] : running)
        ::kill(pid, SIGTERM);
    }
    while (next < cases.size() && running.size() < std::max<unsigned>(1, options.workers))
    {
      const std::size_t k = cases[next++];
      // While cases wait, each worker's case on one core; the last ones on their own threads, so that the cores
      // the finished workers leave speed them up (5 equal cases on 2 cores: 1.6× instead of at most 5/3 × 0.8).
      const bool one_thread = options.one_thread_while_waiting && options.workers > 1 && next < cases.size();
      running[startCase(dir, records[k], options, one_thread)] = {k, Clock::now()};
    }
    // Each case's own pid, polled: waiting for any child would also reap the study's plot process.
    int status = 0;
    auto it = running.begin();
    for (; it != running.end(); ++it)
      if (::waitpid(it->first, &status, WNOHANG) == it->first)
        break;
    if (it == running.end())
    {
      ::usleep(10000);  // cases last ≥ 0.1 s: 10 ms costs nothing (a signal ends the sleep early)
      continue;
    }
    const double wall = std::chrono::duration<double>(Clock::now() - it->second.second).count();
    if (!finishCase(dir, records[it->second.first], status, wall) && stopRequest() == 0)
      ++failed;
    case_seconds += wall;
    ++finished;
    running.erase(it);
    report();
  }
  return failed;
}
}  // namespace scanhead
