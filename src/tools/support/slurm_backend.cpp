/// \file slurm_backend.cpp
/// \brief Submitting a study as a Slurm job array (slurm_backend.hpp).
#include "slurm_backend.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "scanhead/common/errors.hpp"
#include "scanhead/study/study_folder.hpp"

namespace scanhead
{
namespace
{
namespace fs = std::filesystem;

/// \brief Single-quoted for a POSIX shell.
std::string quoted(const std::string& word)
{
  std::string out = "'";
  for (const char c : word)
    out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// \brief Runs \p argv, its stdout and stderr captured into \p output. \return its exit status (-1: not started)
int capture(const std::vector<std::string>& argv, std::string& output)
{
  int pipe_fd[2];
  if (::pipe(pipe_fd) != 0)
    return -1;
  const pid_t pid = ::fork();
  if (pid < 0)
    return -1;
  if (pid == 0)
  {
    ::dup2(pipe_fd[1], STDOUT_FILENO);
    ::dup2(pipe_fd[1], STDERR_FILENO);
    ::close(pipe_fd[0]);
    ::close(pipe_fd[1]);
    std::vector<char*> args;
    for (const std::string& a : argv)
      args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    std::fprintf(stderr, "cannot start %s: %s (is slurm-client installed?)\n", args[0], std::strerror(errno));
    ::_exit(127);
  }
  ::close(pipe_fd[1]);
  char buffer[4096];
  for (ssize_t n; (n = ::read(pipe_fd[0], buffer, sizeof buffer)) != 0;)
  {
    if (n < 0 && errno == EINTR)
      continue;
    if (n < 0)
      break;
    output.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(pipe_fd[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR)
  {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/// \brief sbatch --parsable prints "jobid[;cluster]".
std::string jobIdOf(const std::string& output)
{
  std::string id;
  for (const char c : output)
  {
    if (c < '0' || c > '9')
      break;
    id += c;
  }
  return id;
}

std::string sbatch(const std::vector<std::string>& arguments, const std::string& what)
{
  std::vector<std::string> argv = {"sbatch", "--parsable"};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  std::string output;
  const int status = capture(argv, output);
  const std::string id = jobIdOf(output);
  if (status != 0 || id.empty())
  {
    while (!output.empty() && (output.back() == '\n' || output.back() == '\r'))
      output.pop_back();
    throw InputError("sbatch could not submit the " + what + " (exit " + std::to_string(status) + "): " + output);
  }
  return id;
}
}  // namespace

std::string slurmIndexList(const std::vector<std::size_t>& indices)
{
  std::string list;
  for (std::size_t i = 0; i < indices.size();)
  {
    std::size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1)
      ++j;
    list += (list.empty() ? "" : ",") + std::to_string(indices[i]);
    if (j > i)
      list += "-" + std::to_string(indices[j]);
    i = j + 1;
  }
  return list;
}

std::string slurmArrayScript(const std::string& dir, const std::vector<std::size_t>& indices,
                             const SlurmOptions& options)
{
  const std::string abs = fs::absolute(dir).lexically_normal().string();
  std::string s = "#!/bin/bash\n";
  s += "#SBATCH --job-name=scanhead_study\n";
  s += "#SBATCH --array=" + slurmIndexList(indices) +
       (options.max_running > 0 ? "%" + std::to_string(options.max_running) : std::string()) + "\n";
  s += "#SBATCH --cpus-per-task=" + std::to_string(options.cpus_per_task) + "\n";
  s += "#SBATCH --output=" + abs + "/logs/slurm_%A_%a.out\n";
  if (!options.partition.empty())
    s += "#SBATCH --partition=" + options.partition + "\n";
  if (!options.time_limit.empty())
    s += "#SBATCH --time=" + options.time_limit + "\n";
  s += "# One case of the study " + abs + " (its cases.tsv, line SLURM_ARRAY_TASK_ID + 2): the same results folder\n";
  s += "# as the local backend. Collected by `scanhead_study collect` when the array has ended.\n";
  s += "exec " + quoted(options.study_exe) + " run-case " + quoted(abs) + " \"$SLURM_ARRAY_TASK_ID\"\n";
  return s;
}

std::string submitSlurmStudy(const std::string& dir, const std::vector<std::size_t>& indices,
                             const SlurmOptions& options)
{
  const std::string abs = fs::absolute(dir).lexically_normal().string();
  const std::string script = (fs::path(abs) / "slurm_array.sh").string();
  writeFileWhole(script, slurmArrayScript(abs, indices, options));
  const std::string array = sbatch({script}, "case array");
  std::vector<std::string> collect = {"--job-name=scanhead_study_collect", "--dependency=afterany:" + array,
                                      "--output=" + abs + "/logs/slurm_collect_%j.out", "--cpus-per-task=1"};
  if (!options.partition.empty())
    collect.push_back("--partition=" + options.partition);
  if (options.wait)
    collect.push_back("--wait");
  collect.push_back("--wrap=exec " + quoted(options.study_exe) + " collect " + quoted(abs));
  const std::string collector = sbatch(collect, "collection job");
  std::fprintf(stderr, "scanhead_study: submitted job array %s (%zu cases) and collection job %s%s\n", array.c_str(),
               indices.size(), collector.c_str(), options.wait ? " (ended)" : "");
  return array;
}
}  // namespace scanhead
