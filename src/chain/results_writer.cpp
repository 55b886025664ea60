#include "scanhead/chain/results_writer.hpp"
#include "scanhead/common/number_text.hpp"
#include "scanhead/common/text_file.hpp"

#include <atomic>
#include <filesystem>
#include <functional>
#include <system_error>

#include "scanhead/chain/config_io.hpp"
#include "scanhead/common/errors.hpp"
#include "scanhead/job/formats/job_io.hpp"
#include "scanhead/job/job_stats.hpp"
#include "scanhead/metrics/metrics_report.hpp"
#include "scanhead/report/energy_exports.hpp"
#include "scanhead/report/job_picture.hpp"
#include "scanhead/report/task_pool.hpp"
#include "scanhead/report/thermal_images.hpp"

namespace scanhead
{
namespace fs = std::filesystem;

namespace
{

/// A folder the writer may replace: empty, or written by an earlier run.
bool replaceable(const fs::path& dir)
{
  return fs::is_empty(dir) || fs::exists(dir / kResultsMarker);
}
}  // namespace

void writeResultsFolder(const std::string& dir_text, const RunMetrics& metrics, const EnergyStage& energy,
                        const ChainConfig& config, const Job& job, const ResultsFinisher& finish,
                        const PlotHook& data_written, const std::function<void()>& on_failure)
{
  const fs::path dir = fs::absolute(dir_text).lexically_normal();
  if (fs::exists(dir) && (!fs::is_directory(dir) || !replaceable(dir)))
    throw InputError(dir.string() + ": exists and is not a scanhead results folder; choose another --out");
  const fs::path parent = dir.parent_path();
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec)
    throw InputError(parent.string() + ": cannot create (" + ec.message() + ")");
  const fs::path tmp = parent / ("." + dir.filename().string() + ".partial");
  fs::remove_all(tmp);
  try
  {
    fs::create_directory(tmp);
    writeTextFile(tmp / kResultsMarker, "written by scanhead\n");
    // Every file is independent of the others: written side by side, the longest first (on the
    // THESIS layer: the energy overview, which reads the whole tiled map); each file's bytes are
    // those of a serial write.
    TaskPool pool;
    addEnergyExportTasks(pool, tmp.string(), energy.map(), job, config.energy);
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
    if (finish)
      finish(tmp.string());
    if (fs::exists(dir))
      fs::remove_all(dir);
    fs::rename(tmp, dir);
  }
  catch (...)
  {
    if (on_failure)
      on_failure();
    fs::remove_all(tmp, ec);
    throw;
  }
}
}  // namespace scanhead
