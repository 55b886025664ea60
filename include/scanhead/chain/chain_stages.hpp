/// \file chain_stages.hpp
/// \brief The five stages of the chain behind the one Stage interface (common/stage.hpp):
///
/// | stage           | reset with        | process                    | finish       |
/// |-----------------|-------------------|----------------------------|--------------|
/// | CamStage        | job argument      | (nothing) → the Job        | the Job      |
/// | NcStage         | Job               | sample budget → NcOutput   | empty output |
/// | ServoStage      | ServoJob (period) | SetpointChunk → JointChunk | empty chunk  |
/// | OpticsStage     | (nothing)         | OpticsInput → SpotChunk    | empty chunk  |
/// | EnergySinkStage | PlannedJob        | SpotChunk → samples taken  | RunMetrics   |
///
/// (EnergySinkStage is in energy_sink_stage.hpp, so that the stages before it do not depend on the
/// energy stage.) The NC is the source: its plan of the job (NcStage::plan(), nc_plan.hpp) gives the
/// later stages what they need of the job (the servo its period, the energy stage the program and
/// the delays), so none of them plans the job again.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "scanhead/chain/chain_config.hpp"
#include "scanhead/common/stage.hpp"
#include "scanhead/job/scan_job.hpp"
#include "scanhead/nc/nc_interpolator.hpp"
#include "scanhead/nc/nc_plan.hpp"
#include "scanhead/optics/optical_chain_stage.hpp"
#include "scanhead/optics/optical_model.hpp"
#include "scanhead/servo/galvo_servo.hpp"

namespace scanhead
{
/// \brief What the stages after the NC are reset with: the job and the NC's plan of it (read during
/// reset(): the stages copy what they keep).
struct PlannedJob
{
  const Job& job;
  const NcPlan& plan;
};

/// \brief What the servo needs of a job: the sample period of its setpoint stream [s].
struct ServoJob
{
  double period_s = 0.0;
};

/// \brief A stage input that carries nothing (the CAM stage's process()).
struct NoInput
{
};

/// \brief The CAM stage: a job argument (built-in spec or file) becomes a validated Job.
class CamStage final : public Stage<std::string, NoInput, Job>
{
public:
  CamStage(const CamConfig& cam, double field_half_width_m)
    : cam_(cam)
    , field_half_width_m_(field_half_width_m)
  {
  }
  /// \throws InputError naming the file and what is wrong (loadJob, validateScanJob)
  void reset(const std::string& argument) override;
  Job process(const NoInput&) override { return job_; }
  Job finish() override { return job_; }

private:
  CamConfig cam_;
  double field_half_width_m_;
  Job job_;
};

/// \brief The NC stage: reset plans the job; each process() samples up to the given number of samples.
class NcStage final : public Stage<Job, std::size_t, NcOutput>
{
public:
  /// \param[in] optics must outlive this object
  NcStage(const ChainConfig& config, const OpticalModel& optics);
  void reset(const Job& job) override { nc_.start(job); }
  NcOutput process(const std::size_t& max_samples) override { return nc_.process(max_samples); }
  NcOutput finish() override { return NcOutput(); }

  bool done() const { return nc_.done(); }
  const NcPlan& plan() const { return nc_.plan(); }
  const NcInterpolator& interpolator() const { return nc_; }

private:
  NcInterpolator nc_;
};

/// \brief The servo stage: both axes, at rest where the job starts (its first setpoint sample).
class ServoStage final : public Stage<ServoJob, SetpointChunk, JointChunk>
{
public:
  explicit ServoStage(const ServoConfig& config)
    : config_(config)
  {
  }
  /// \brief A new job: a servo at \p job.period_s, put at rest by the first chunk's first setpoint.
  void reset(const ServoJob& job) override;
  JointChunk process(const SetpointChunk& setpoint) override;
  JointChunk finish() override { return JointChunk(); }

private:
  ServoConfig config_;
  std::unique_ptr<GalvoServo> servo_;
  bool at_rest_pending_ = false;
};

/// \brief The three streams the optics joins, sample-aligned (same first_index, size and period).
struct OpticsInput
{
  const SetpointChunk& setpoint;
  const JointChunk& joints;
  const LaserChunk& laser;
};

/// \brief The optics stage: setpoint, measured joints and laser become the spot stream.
class OpticsStage final : public Stage<NoInput, OpticsInput, SpotChunk>
{
public:
  /// \param[in] optics must outlive this object
  explicit OpticsStage(const OpticalModel& optics)
    : optics_(optics)
  {
  }
  void reset(const NoInput&) override {}  // stateless: each sample is traced on its own
  SpotChunk process(const OpticsInput& in) override { return optics_.process(in.setpoint, in.joints, in.laser); }
  SpotChunk finish() override { return SpotChunk(); }

private:
  OpticalChainStage optics_;
};

}  // namespace scanhead
