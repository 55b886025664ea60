/// \file test_study_cases.cpp
/// \brief Issue 16: a study file becomes cases: every layer of a layered file × every grid combination, identities
/// that change exactly when the job or its settings change, and clear errors for bad study files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "scanhead/chain/config_io.hpp"
#include "scanhead/chain/run_plan.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/job_files.hpp"
#include "scanhead/optics/optics_loading.hpp"
#include "scanhead/study/study_cases.hpp"
#include "scanhead/study/study_estimate.hpp"
#include "scanhead/study/study_folder.hpp"
#include "scanhead/study/study_spec.hpp"

using scanhead::InputError;
using scanhead::planStudyCases;
using scanhead::readStudyFile;
using scanhead::StudyCase;

namespace
{
namespace fs = std::filesystem;
const std::string kConfig = std::string(SCANHEAD_SOURCE_DIR) + "/config/scanhead.yaml";

fs::path folder()
{
  const fs::path dir = fs::path(::testing::TempDir()) / "study_cases";
  fs::create_directories(dir);
  return dir;
}

std::string write(const std::string& name, const std::string& text)
{
  const fs::path path = folder() / name;
  std::ofstream(path) << text;
  return path.string();
}

/// \brief Two layers (z 0 then 1e-4 m), one mark each.
const char* kTwoLayers =
    "Mode x y z pmod param\n1 0 0 0 0 0\n0 0.002 0 0 1 1\n1 0 0.001 1e-4 0 0\n0 0.002 0.001 1e-4 1 1\n";

std::vector<StudyCase> plan(const std::string& study, const std::vector<std::string>& extra = {})
{
  return planStudyCases(readStudyFile(write("study.yaml", study)), kConfig, extra);
}

std::string errorOf(const std::string& study)
{
  try
  {
    plan(study);
  }
  catch (const InputError& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

// 2 layers × (2 × 2 grid) + a built-in job × 4 = 12 cases, in order: jobs, layers, grid (last key fastest).
TEST(StudyCases, LayersTimesGrid)
{
  write("two_layers.txt", kTwoLayers);
  const auto cases = plan(
      "jobs: [two_layers.txt, corner]\nset: {nc.fir_t2_s: 1.0e-4}\n"
      "grid:\n  servo.position_controller: [pd, hinf]\n  energy.pixel_m: [5.0e-6, 1.0e-5]\n");
  ASSERT_EQ(cases.size(), 12u);
  EXPECT_EQ(cases[0].layer, 0);
  EXPECT_EQ(cases[4].layer, 1);
  EXPECT_EQ(cases[8].layer, -1);  // a built-in job is not split
  EXPECT_EQ(cases[1].grid[1].second, "1.0e-5");
  EXPECT_EQ(cases[2].grid[0].second, "hinf");
  EXPECT_NE(cases[5].config_yaml.find("layer: 1\n"), std::string::npos);
  EXPECT_NE(cases[5].config_yaml.find("fir_t2_s: 0.0001"), std::string::npos);
  EXPECT_EQ(cases[0].id.rfind("two_layers_layer0000_position_controller-pd_pixel_m-5.0e-6_", 0), 0u) << cases[0].id;
  EXPECT_EQ(cases[8].label, "corner");
  std::set<std::string> ids;
  for (const StudyCase& c : cases)
    ids.insert(c.id);
  EXPECT_EQ(ids.size(), cases.size());
}

// A multi-layer CLI file (test/data/cli/cli_full.cli: 2 layers) is one case per layer too.
TEST(StudyCases, CliLayers)
{
  const auto cases = plan("jobs: [" + std::string(SCANHEAD_SOURCE_DIR) + "/test/data/cli/cli_full.cli]\n");
  ASSERT_EQ(cases.size(), 2u);
  EXPECT_EQ(cases[1].layer, 1);
  EXPECT_EQ(cases[1].id.rfind("cli_full_layer0001_", 0), 0u) << cases[1].id;
}

// The estimate before a study plans a layered file's first layer only and scales the others by their path time (the
// reader's survey): three layers of 4, 8 and 16 hatch lines, each estimated within 5 % of its own run plan.
TEST(StudyCases, EstimateScalesLayersByPathTime)
{
  std::string text = "Mode x y z pmod param\n";
  int layer = 0;
  for (const int lines : {4, 8, 16})
  {
    const std::string z = std::to_string(1e-4 * layer++);
    text += "1 0 0 " + z + " 0 0\n";
    for (int k = 0; k < lines; ++k)
    {
      const std::string y = std::to_string(1e-4 * k), x0 = k % 2 ? "0.004" : "0", x1 = k % 2 ? "0" : "0.004";
      text += "0 " + x0 + " " + y + " " + z + " 0 4.5\n0 " + x1 + " " + y + " " + z + " 1 1\n";
    }
  }
  write("three_layers.txt", text);
  const auto cases = plan("jobs: [three_layers.txt]\n");
  ASSERT_EQ(cases.size(), 3u);
  double total_s = 0.0;
  for (std::size_t k = 0; k < cases.size(); ++k)
  {
    const scanhead::StudyEstimate one = scanhead::estimateStudy(cases, {k});
    scanhead::ChainConfig config = scanhead::loadChainConfig(kConfig, {});
    config.cam.layer = static_cast<int>(k);
    const scanhead::Job job = scanhead::loadJob(cases[k].job, config.cam);
    const scanhead::RunPlan own = scanhead::planRun(config, job, scanhead::loadOpticalModel(config.optics));
    EXPECT_NEAR(one.machine_time_s, own.machine_time_s, 0.05 * own.machine_time_s) << "layer " << k;
    EXPECT_NEAR(one.wall_time_s, own.wall_time_s, 0.05 * own.wall_time_s) << "layer " << k;
    total_s += one.machine_time_s;
  }
  EXPECT_NEAR(scanhead::estimateStudy(cases, {0, 1, 2}).machine_time_s, total_s, 1e-12);
}

// The identity: the same study plans the same ids; a setting, the job file's content or an extra --set changes them.
TEST(StudyCases, IdentityFollowsJobAndSettings)
{
  write("two_layers.txt", kTwoLayers);
  const std::string study = "jobs: [two_layers.txt]\n";
  const auto a = plan(study), b = plan(study);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0].id, b[0].id);
  EXPECT_NE(plan(study, {"nc.fir_t1_s=3e-4"})[0].id, a[0].id);
  EXPECT_NE(plan("jobs: [two_layers.txt]\nset: {cam.mark_power_w: 150}\n")[0].id, a[0].id);
  // The thread count changes no result: the same case (the local backend chooses it per case).
  EXPECT_EQ(plan(study, {"stream.threads=1"})[0].id, a[0].id);
  write("two_layers.txt", std::string(kTwoLayers) + "0 0.003 0.001 1e-4 1 1\n");
  EXPECT_NE(plan(study)[1].id, a[1].id);
  // cam.layer set by the study: no split, the layer it names.
  EXPECT_EQ(plan("jobs: [two_layers.txt]\nset: {cam.layer: -1}\n").size(), 1u);
}

// Bad study files name the file, the line and the key; nothing is planned.
TEST(StudyCases, BadStudyFiles)
{
  EXPECT_NE(errorOf("jobs: [corner]\nsweep: 1\n").find("study.yaml:2: unknown key 'sweep'"), std::string::npos);
  EXPECT_NE(errorOf("jobs: []\n").find("jobs: expected a non-empty list"), std::string::npos);
  EXPECT_NE(errorOf("set: {nc.fir_t1_s: 1e-4}\n").find("jobs: missing"), std::string::npos);
  EXPECT_NE(errorOf("jobs: [none_*.cli]\n").find("study.yaml:1: jobs[0]: 'none_*.cli' matches no file"),
            std::string::npos);
  EXPECT_NE(errorOf("jobs: [missing.txt]\n").find("'missing.txt' is neither a file"), std::string::npos);
  EXPECT_NE(errorOf("jobs: [corner]\ngrid:\n  nc.nope: [1]\n").find("study.yaml:3: grid.nc.nope: not a setting"),
            std::string::npos);
  EXPECT_NE(errorOf("jobs: [corner]\ngrid:\n  nc.fir_t1_s: []\n").find("grid.nc.fir_t1_s: expected a non-empty list"),
            std::string::npos);
  EXPECT_NE(errorOf("jobs: [corner]\nset: {nc.nope: 1}\n").find("set.nc.nope: not a setting"), std::string::npos);
  EXPECT_NE(errorOf("jobs: [corner]\ngrid:\n  nc.fir_t1_s: [-1]\n").find("(grid: nc.fir_t1_s=-1): nc.fir_t1_s"),
            std::string::npos);
  EXPECT_NE(errorOf("jobs: [corner]\nplots: some\n").find("plots: 'some' is not none, summary or all"),
            std::string::npos);
}

// The folder's plan and case states round-trip; a status file says failed, a published folder says done.
TEST(StudyCases, FolderStates)
{
  const auto cases = plan("jobs: [corner]\ngrid:\n  nc.fir_t1_s: [2.0e-4, 3.0e-4, 4.0e-4]\n");
  const std::string dir = (folder() / "study_folder").string();
  fs::remove_all(dir);
  scanhead::writeStudyPlan(dir, "jobs: [corner]\n", cases);
  scanhead::writeCaseStatus(dir, cases[1].id, false, 1, 0.5, "scanhead_run: error: \"bad\" thing");
  fs::create_directories(scanhead::caseResultsDir(dir, cases[2].id));
  std::ofstream(fs::path(scanhead::caseResultsDir(dir, cases[2].id)) / "metrics.yaml") << "job: x\n";
  const auto records = scanhead::readStudyCases(dir);
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[0].state, scanhead::CaseState::Pending);
  EXPECT_EQ(records[1].state, scanhead::CaseState::Failed);
  EXPECT_EQ(records[1].error, "scanhead_run: error: 'bad' thing");
  EXPECT_EQ(records[1].wall_s, 0.5);
  EXPECT_EQ(records[2].state, scanhead::CaseState::Done);
  EXPECT_EQ(records[2].grid_text, "nc.fir_t1_s=4.0e-4");
  EXPECT_EQ(scanhead::errorLineOf("a\nscanhead_run: error: x: y\n\n"), "scanhead_run: error: x: y");
}
