// Results folder: complete and atomic, replaces only its own kind, leaves nothing on failure.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include <unistd.h>

#include "scanhead/chain/batch_chain.hpp"
#include "scanhead/chain/config_io.hpp"
#include "scanhead/chain/results_writer.hpp"
#include "scanhead/common/errors.hpp"
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
