// Results folder: complete and atomic, replaces only its own kind, leaves nothing on failure; one
// writer per folder (the lock names the holder), a failure or a stop leaves the previous folder as it
// was, what a killed run left is removed by the next one.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include <sys/wait.h>
#include <unistd.h>

#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/chain/results_writer.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/staged_folder.hpp"
#include "scanhead/common/stop_request.hpp"
#include "scanhead/job/generators/builtin_jobs.hpp"
#include "scanhead/report/energy_exports.hpp"
#include "scanhead/report/task_pool.hpp"

using namespace scanhead;
namespace fs = std::filesystem;

namespace
{
struct Fixture
{
  ChainConfig config = loadChainConfig(std::string(SCANHEAD_SOURCE_DIR) + "/config/scanhead.yaml", {});
  OpticalModel optics = loadOpticalModel(config.optics);
  Job job = builtinJob("corner:speed=2,angle=90,leg=0.001");
  BatchChain chain{config, optics};
  RunMetrics metrics = chain.run(job);
};

fs::path freshDir(const std::string& name)
{
  const fs::path dir = fs::temp_directory_path() / ("scanhead_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}
}  // namespace

TEST(ResultsWriter, WritesEveryFileAndReplacesItsOwnFolder)
{
  Fixture f;
  const fs::path dir = freshDir("ok");
  writeResultsFolder(dir.string(), f.metrics, f.chain.energy(), f.config, f.job);
  for (const char* name : {"metrics.yaml", "config.yaml", "job.yaml", "job_stats.yaml", "job.png", "trace.csv",
                           "energy_map.png", "energy_map_16bit.png", "energy_map.yaml", kResultsMarker})
    EXPECT_TRUE(fs::exists(dir / name)) << name;
  // PNG signature on the images.
  std::ifstream png(dir / "energy_map.png", std::ios::binary);
  char magic[8] = {};
  png.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  // A second run replaces the folder (it is a results folder).
  EXPECT_NO_THROW(writeResultsFolder(dir.string(), f.metrics, f.chain.energy(), f.config, f.job));
  fs::remove_all(dir);
}

TEST(ResultsWriter, RefusesForeignFolderAndLeavesNoPartialOutput)
{
  Fixture f;
  const fs::path dir = freshDir("foreign");
  fs::create_directories(dir);
  std::ofstream(dir / "precious.txt") << "user data";
  EXPECT_THROW(writeResultsFolder(dir.string(), f.metrics, f.chain.energy(), f.config, f.job), InputError);
  EXPECT_TRUE(fs::exists(dir / "precious.txt"));
  EXPECT_FALSE(fs::exists(dir / "metrics.yaml"));

  // A failure while writing (here: the finisher throws) leaves neither the folder nor the temporary.
  const fs::path failing = freshDir("failing");
  EXPECT_THROW(writeResultsFolder(failing.string(), f.metrics, f.chain.energy(), f.config, f.job,
                                  [](const std::string&) { throw InputError("disk full"); }),
               InputError);
  EXPECT_FALSE(fs::exists(failing));
  EXPECT_FALSE(fs::exists(failing.parent_path() / ("." + failing.filename().string() + ".partial")));
  EXPECT_FALSE(fs::exists(FolderLock::lockFileOf(failing)));
  fs::remove_all(dir);
}

namespace
{
/// Every regular file under \p dir, by relative path, with its bytes.
std::map<std::string, std::string> filesUnder(const fs::path& dir)
{
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.is_regular_file())
    {
      std::ifstream in(entry.path(), std::ios::binary);
      files[fs::relative(entry.path(), dir).string()] = std::string(std::istreambuf_iterator<char>(in), {});
    }
  return files;
}
}  // namespace

TEST(ResultsWriter, EnergyExportsOnSeveralThreadsAreTheSerialBytes)
{
  Fixture f;
  EnergyConfig energy = f.config.energy;
  energy.crop_parts = 1;
  energy.crop_regions = "-0.0005,-0.0005,0.0005,0.0005,centre";
  const fs::path serial = freshDir("serial"), parallel = freshDir("parallel");
  fs::create_directories(serial);
  fs::create_directories(parallel);
  writeEnergyExports(serial.string(), f.chain.energy().map(), f.job, energy);
  TaskPool pool(3);
  addEnergyExportTasks(pool, parallel.string(), f.chain.energy().map(), f.job, energy);
  pool.run();
  const auto expected = filesUnder(serial), got = filesUnder(parallel);
  EXPECT_EQ(expected.size(), 8u);  // overview and the centre crop: .png, _16bit.png, .tiff, .yaml each
  ASSERT_EQ(got.size(), expected.size());
  for (const auto& [name, bytes] : expected)
  {
    ASSERT_TRUE(got.count(name)) << name;
    EXPECT_TRUE(got.at(name) == bytes) << name << " differs";
  }
  fs::remove_all(serial);
  fs::remove_all(parallel);
}

namespace
{
/// The hidden entries beside \p target that belong to it (staging folders, aside folders, the lock).
std::vector<std::string> litterOf(const fs::path& target)
{
  std::vector<std::string> found;
  const std::string prefix = "." + target.filename().string() + ".";
  for (const auto& entry : fs::directory_iterator(target.parent_path()))
    if (entry.path().filename().string().rfind(prefix, 0) == 0)
      found.push_back(entry.path().filename().string());
  return found;
}

/// A results folder at \p target written by writeResultsFolder, and its bytes.
std::map<std::string, std::string> previousResults(Fixture& f, const fs::path& target)
{
  writeResultsFolder(target.string(), f.metrics, f.chain.energy(), f.config, f.job,
                     [](const std::string& dir) { std::ofstream(fs::path(dir) / "plot.png") << "first run's plot"; });
  return filesUnder(target);
}
}  // namespace

TEST(ResultsWriter, SecondWriterFailsAtOnceNamingTheHolder)
{
  Fixture f;
  const fs::path parent = freshDir("busy");
  const fs::path target = parent / "out";
  const FolderLock lock = lockResultsFolder(target.string());
  EXPECT_TRUE(fs::exists(FolderLock::lockFileOf(target)));
  const std::string pid = "pid " + std::to_string(::getpid());
  EXPECT_NE(FolderLock::holderOf(target).find(pid), std::string::npos) << FolderLock::holderOf(target);
  // Another lock on the same folder (another open file description: as another process) fails now.
  try
  {
    writeResultsFolder(target.string(), f.metrics, f.chain.energy(), f.config, f.job);
    ADD_FAILURE() << "a second writer was let in";
  }
  catch (const FolderBusyError& e)
  {
    const std::string message = e.what();
    EXPECT_NE(message.find(target.string() + ": being written by "), std::string::npos) << message;
    EXPECT_NE(message.find(pid), std::string::npos) << message;
    EXPECT_NE(message.find(" since 20"), std::string::npos) << message;
    EXPECT_NE(message.find("choose another output folder"), std::string::npos) << message;
  }
  EXPECT_FALSE(fs::exists(target));
  // The holder writes through its lock.
  writeResultsFolder(lock, f.metrics, f.chain.energy(), f.config, f.job);
  EXPECT_TRUE(fs::exists(target / "metrics.yaml"));
  EXPECT_EQ(litterOf(target), std::vector<std::string>{".out.lock"});
  fs::remove_all(parent);
}

TEST(ResultsWriter, FolderNamedThroughASymbolicLinkIsTheRealOne)
{
  Fixture f;
  const fs::path parent = freshDir("link");
  const fs::path real = parent / "real";
  writeResultsFolder(real.string(), f.metrics, f.chain.energy(), f.config, f.job);
  fs::create_directory_symlink("real", parent / "link");
  {
    // A run through the link locks the real folder: a run naming the real folder is excluded.
    const FolderLock lock = lockResultsFolder((parent / "link").string());
    EXPECT_EQ(lock.folder(), real);
    EXPECT_THROW(lockResultsFolder(real.string()), FolderBusyError);
    writeResultsFolder(lock, f.metrics, f.chain.energy(), f.config, f.job);
  }
  // The real folder was replaced, the link still names it.
  EXPECT_TRUE(fs::is_symlink(parent / "link"));
  EXPECT_TRUE(fs::exists(parent / "link" / "metrics.yaml"));
  EXPECT_EQ(litterOf(real), std::vector<std::string>{});
  fs::remove_all(parent);
}

TEST(ResultsWriter, LockIsReleasedWhenItsHolderDies)
{
  const fs::path parent = freshDir("dies");
  const fs::path target = parent / "a" / "b" / "out";
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0)
  {
    // Takes the lock, says so, then waits to be killed (no cleanup: as under SIGKILL).
    try
    {
      FolderLock lock(target.string());
      (void)!::write(ready[1], "x", 1);
      for (;;)
        ::pause();
    }
    catch (...)
    {
      ::_exit(1);
    }
  }
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  try
  {
    FolderLock second(target.string());
    ADD_FAILURE() << "the lock of a live process was taken";
  }
  catch (const FolderBusyError& e)
  {
    EXPECT_NE(std::string(e.what()).find("pid " + std::to_string(child)), std::string::npos) << e.what();
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ::close(ready[0]);
  ::close(ready[1]);
  // Its lock file is still there (nobody removed it) but no longer held: taken over.
  EXPECT_TRUE(fs::exists(FolderLock::lockFileOf(target)));
  {
    FolderLock taken(target.string());
    EXPECT_NE(FolderLock::holderOf(target).find("pid " + std::to_string(::getpid())), std::string::npos);
  }
  // Released: the lock file goes, and so do the parents a lock created for a folder never written.
  EXPECT_FALSE(fs::exists(FolderLock::lockFileOf(target)));
  const fs::path deep = parent / "c" / "d" / "out";
  {
    FolderLock lock(deep.string());
    EXPECT_TRUE(fs::is_directory(deep.parent_path()));
  }
  EXPECT_FALSE(fs::exists(parent / "c"));
  EXPECT_TRUE(fs::exists(parent / "a" / "b"));  // created by the other process
  fs::remove_all(parent);
}

TEST(ResultsWriter, FailingFinisherLeavesThePreviousFolderAsItWas)
{
  Fixture f;
  const fs::path parent = freshDir("previous");
  const fs::path target = parent / "out";
  const auto before = previousResults(f, target);
  ASSERT_GT(before.size(), 8u);
  bool cancelled = false;
  std::string staging;
  EXPECT_THROW(writeResultsFolder(
                   target.string(), f.metrics, f.chain.energy(), f.config, f.job,
                   [&](const std::string& dir) {
                     staging = dir;
                     std::ofstream(fs::path(dir) / "plot.png") << "half a plot";
                     throw InputError("plots failed: killed");
                   },
                   {}, [&] { cancelled = true; }),
               InputError);
  EXPECT_TRUE(cancelled);
  // The staging folder was this run's own, beside the target, and is gone.
  EXPECT_EQ(fs::path(staging).parent_path(), target.parent_path());
  EXPECT_TRUE(StagedFolder::isStagingName(fs::path(staging).filename().string(), "out")) << staging;
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_TRUE(filesUnder(target) == before);
  EXPECT_TRUE(litterOf(target).empty());
  // A successful run replaces it whole: nothing of the previous folder stays.
  std::ofstream(target / "stray.txt") << "in the previous folder only";
  writeResultsFolder(target.string(), f.metrics, f.chain.energy(), f.config, f.job);
  EXPECT_FALSE(fs::exists(target / "stray.txt"));
  EXPECT_FALSE(fs::exists(target / "plot.png"));
  EXPECT_TRUE(fs::exists(target / "metrics.yaml"));
  EXPECT_TRUE(litterOf(target).empty());
  fs::remove_all(parent);
}

TEST(ResultsWriter, StopRequestLeavesThePreviousFolderAsItWas)
{
  Fixture f;
  const fs::path parent = freshDir("stop");
  const fs::path target = parent / "out";
  const auto before = previousResults(f, target);
  // The signal arrives while the plots are drawn: the writer stops before publishing.
  bool cancelled = false;
  try
  {
    writeResultsFolder(
        target.string(), f.metrics, f.chain.energy(), f.config, f.job, [](const std::string&) { requestStop(SIGTERM); },
        {}, [&] { cancelled = true; });
    ADD_FAILURE() << "published despite the stop request";
  }
  catch (const StopRequested& e)
  {
    EXPECT_EQ(e.signal(), SIGTERM);
    EXPECT_STREQ(e.what(), "interrupted by SIGTERM");
  }
  // A request standing before the write: nothing is started.
  EXPECT_THROW(writeResultsFolder(target.string(), f.metrics, f.chain.energy(), f.config, f.job), StopRequested);
  clearStopRequest();
  EXPECT_TRUE(cancelled);
  EXPECT_TRUE(filesUnder(target) == before);
  EXPECT_TRUE(litterOf(target).empty());
  fs::remove_all(parent);
}

TEST(ResultsWriter, WhatAKilledRunLeftIsRemovedByTheNext)
{
  Fixture f;
  const fs::path parent = freshDir("stale");
  const fs::path target = parent / "out";
  const auto before = previousResults(f, target);
  // A run killed while writing: its staging folder and its lock file (no longer held).
  const fs::path stale = parent / ".out.staging.99999.0123456789abcdef";
  fs::create_directories(stale / "sub");
  std::ofstream(stale / "sub" / "trace.csv") << "partial";
  std::ofstream(FolderLock::lockFileOf(target)) << "pid: 99999\nhost: elsewhere\nprogram: scanhead_run\nsince: then\n";
  std::ofstream(parent / ".out.partial") << "left by an older version";
  // Not ours: another target's staging folder, and a name that only looks like one.
  const fs::path other = parent / ".out.staging.5.staging.123.0123456789abcdef";
  const fs::path lookalike = parent / ".out.staging.mine";
  fs::create_directories(other);
  fs::create_directories(lookalike);
  std::vector<std::string> removed;
  {
    const FolderLock lock = lockResultsFolder(target.string(), &removed);
    EXPECT_EQ(removed.size(), 2u);
    EXPECT_FALSE(fs::exists(stale));
    EXPECT_FALSE(fs::exists(parent / ".out.partial"));
    EXPECT_TRUE(fs::exists(other));
    EXPECT_TRUE(fs::exists(lookalike));
    EXPECT_TRUE(filesUnder(target) == before);
    writeResultsFolder(lock, f.metrics, f.chain.energy(), f.config, f.job);
  }
  EXPECT_TRUE(fs::exists(target / "metrics.yaml"));
  EXPECT_FALSE(fs::exists(target / "plot.png"));

  // A run killed between moving the previous folder aside and moving its own in (file systems
  // without RENAME_EXCHANGE): the previous folder is put back.
  const auto second = filesUnder(target);
  const fs::path aside = parent / ".out.previous.99999.00000000000000ff";
  fs::rename(target, aside);
  {
    const FolderLock lock = lockResultsFolder(target.string(), &removed);
    ASSERT_EQ(removed.size(), 1u);
    EXPECT_NE(removed[0].find("restored"), std::string::npos) << removed[0];
  }
  EXPECT_FALSE(fs::exists(aside));
  EXPECT_TRUE(filesUnder(target) == second);
  fs::remove_all(parent);
}

TEST(ResultsWriter, StagingNamesAreUniqueAndRecognised)
{
  EXPECT_TRUE(StagedFolder::isStagingName(".out.staging.1234.0123456789abcdef", "out"));
  EXPECT_TRUE(StagedFolder::isStagingName(".out.previous.1.ffffffffffffffff", "out"));
  EXPECT_FALSE(StagedFolder::isStagingName(".out.staging.1234.0123456789abcde", "out"));   // 15 digits
  EXPECT_FALSE(StagedFolder::isStagingName(".out.staging.12a4.0123456789abcdef", "out"));  // pid not a number
  EXPECT_FALSE(StagedFolder::isStagingName(".out.staging..0123456789abcdef", "out"));
  EXPECT_FALSE(StagedFolder::isStagingName(".out2.staging.1234.0123456789abcdef", "out"));
  EXPECT_FALSE(StagedFolder::isStagingName(".out.lock", "out"));
  const fs::path parent = freshDir("unique");
  const FolderLock lock((parent / "out").string());
  StagedFolder a(lock), b(lock);
  EXPECT_NE(a.path(), b.path());
  EXPECT_EQ(a.path().parent_path(), parent);
  EXPECT_TRUE(fs::is_directory(a.path()));
  const std::string pid = std::to_string(::getpid());
  EXPECT_EQ(a.path().filename().string().rfind(".out.staging." + pid + ".", 0), 0u) << a.path();
  // Messages name the target's files; a write error of a full disk is named as such.
  EXPECT_EQ(a.explain(a.path().string() + "/metrics.yaml: cannot write (Permission denied)"),
            (parent / "out").string() + "/metrics.yaml: cannot write (Permission denied)");
  EXPECT_EQ(a.explain(a.path().string() + "/trace.csv: cannot write (No space left on device)"),
            "no space left on device writing " + (parent / "out").string() + "/trace.csv (" +
                (parent / "out").string() + "/trace.csv: cannot write (No space left on device))");
  fs::remove_all(parent);
}
