#include "scanhead/chain/results_writer.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/text_file.hpp"

#include <atomic>
#include <filesystem>
#include <functional>
#include <system_error>

#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/common/staged_folder.hpp"
#include "scanhead/common/stop_request.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/job_stats.hpp"
#include "scanhead/metrics/metrics_report.hpp"
#include "scanhead/report/energy_exports.hpp"
#include "scanhead/report/job_picture.hpp"
#include "scanhead/report/results_report.hpp"
#include "scanhead/report/task_pool.hpp"
#include "scanhead/report/thermal_images.hpp"

namespace scanhead
{
namespace fs = std::filesystem;

namespace
{
/// A folder the writer may replace: empty, or written by an earlier run.
void checkReplaceable(const fs::path& dir)
{
  std::error_code ec;
  if (!fs::exists(dir, ec))
    return;
  if (!fs::is_directory(dir, ec) || !(fs::is_empty(dir, ec) || fs::exists(dir / kResultsMarker, ec)))
    throw InputError(dir.string() + ": exists and is not a scanhead results folder; choose another --out");
}
}  // namespace

FolderLock lockResultsFolder(const std::string& dir, std::vector<std::string>* removed)
{
  FolderLock lock(dir);
  checkReplaceable(lock.folder());
  const std::vector<std::string> stale = StagedFolder::removeStale(lock);
  if (removed != nullptr)
    *removed = stale;
  return lock;
}

void writeResultsFolder(const std::string& dir, const RunMetrics& metrics, const EnergyStage& energy,
                        const ChainConfig& config, const Job& job, const ResultsFinisher& finish,
                        const PlotHook& data_written, const std::function<void()>& on_failure)
{
  writeResultsFolder(lockResultsFolder(dir), metrics, energy, config, job, finish, data_written, on_failure);
}

void writeResultsFolder(const FolderLock& lock, const RunMetrics& metrics, const EnergyStage& energy,
                        const ChainConfig& config, const Job& job, const ResultsFinisher& finish,
                        const PlotHook& data_written, const std::function<void()>& on_failure)
{
  checkReplaceable(lock.folder());
  throwIfStopRequested();
  StagedFolder staging(lock);  // removed on every way out but publish()
  const fs::path tmp = staging.path();
  try
  {
    writeTextFile(tmp / kResultsMarker, "written by scanhead\n");
    // Every file is independent of the others: written side by side, the energy images first (the
    // longest: their grids were read from the map by EnergyStage::mapViews); each file's bytes are
    // those of a serial write.
    TaskPool pool;
    addEnergyViewTasks(pool, tmp.string(), *energy.mapViews());
    // The plots' data next, so data_written comes early; the last of the three calls it.
    std::atomic<int> data_left{3};
    auto data_file = [&](const char* name, const std::function<std::string()>& text) {
      return [&, name, text] {
        writeTextFile(tmp / name, text());
        if (--data_left == 0 && data_written)
          data_written(tmp.string());
      };
    };
    pool.add(data_file("metrics.yaml", [&] { return metricsToYaml(metrics); }));
    pool.add(data_file("job.yaml", [&] { return scanJobToYaml(job); }));
    pool.add(data_file("trace.csv", [&] { return energy.trace().csv(config.nc.period_s); }));
    pool.add([&] { writeJobPicture((tmp / "job.png").string(), job, 1600); });
    pool.add([&] {
      writeTextFile(tmp / "config.yaml", chainConfigToYaml(config));
      writeTextFile(tmp / "job_stats.yaml", jobStatsYaml(computeJobStats(job, config.nc.implicit_jump_speed_mps)));
    });
    if (energy.thermal() != nullptr)
      pool.add([&] { writeThermalImages(tmp.string(), *energy.thermal()); });
    pool.run();
    throwIfStopRequested();
    if (finish)
      finish(tmp.string());
    // Last: the page embeds every image, the plots included.
    writeTextFile(tmp / "report.html", resultsReportHtml(tmp.string(), metrics, job));
    throwIfStopRequested();  // the last moment a stop still leaves the previous folder in place
    checkReplaceable(lock.folder());
    staging.publish();
  }
  catch (const StopRequested&)
  {
    if (on_failure)
      on_failure();
    throw;  // the staging folder goes with `staging`
  }
  catch (const std::exception& e)
  {
    if (on_failure)
      on_failure();
    // Name the target's files, not the staging folder's, and a full disk as such (measured now,
    // before the staging folder is removed).
    const std::string message = staging.explain(e.what());
    if (message == e.what())
      throw;
    throw InputError(message);
  }
  catch (...)
  {
    if (on_failure)
      on_failure();
    throw;
  }
}
}  // namespace scanhead
