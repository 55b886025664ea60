/// \file nc_interpolator.hpp
/// \brief The NC stage: exact-timeline sampling, inverse geometry, FIR T1, velocity
/// saturation, FIR T2, laser gating (SPEC §2). A source: pulled chunk by chunk.
///
/// Sample n is at t_n = n·Ts. X_inter(t_n) is the exact point of the job's PathTimeline (the
/// last point after the end); Q_inter = optics.inverse(X_inter); Q_filt1 = box_T1(Q_inter);
/// s = rate limit(Q_filt1); Q_filt2 = box_T2(s), with its exact derivatives (see
/// nc_interpolator.cpp). The machine is at rest at the first point before t = 0.
/// Laser: \f[ P_n = P(t_n - (T_1 + T_2)/2) \f] with P the mark power on MARK segments, 0 on
/// jumps and outside [0, path end) (laser delays: not yet modelled).
#pragma once

#include <cstdint>
#include <memory>

#include "scanhead/core/chunk.hpp"
#include "scanhead/core/nc_config.hpp"
#include "scanhead/core/optical_model.hpp"
#include "scanhead/core/scan_job.hpp"

namespace scanhead
{
struct NcOutput
{
  SetpointChunk setpoint;
  LaserChunk laser;
  NcDebugChunk debug;  ///< empty unless NcConfig::debug
};

class NcInterpolator
{
public:
  /// \param[in] optics used for the inverse geometric transform (kept by reference: must outlive this)
  NcInterpolator(const NcConfig& config, const OpticalModel& optics);
  ~NcInterpolator();

  /// \brief Resets all state and loads a validated job. \throws NumericalError if a point is unreachable
  void start(const Job& job);

  /// \brief Next at most \p max_samples samples (fewer at the end of the job); first_index and
  /// period_s set on every chunk. Chunk sizes do not change the streams (bit-identical).
  /// \throws NumericalError if a sampled point is unreachable; the job is then abandoned
  NcOutput process(std::size_t max_samples);

  bool done() const;
  /// \brief Samples the whole job produces, tail included:
  /// \f[ N = \lceil (D_{path} + T_1 + T_2 + t_{tail}) / T_s \rceil + 1 \f]
  /// (samples 0..N−1 cover [0, D_path + T1 + T2 + tail]; a ratio within 1e-9 of an integer
  /// counts as that integer). 0 before start().
  std::uint64_t totalSamples() const;
  double pathDuration() const;         ///< Σ length/speed over the path, implicit jumps included [s]
  const NcConfig& config() const { return config_; }

private:
  struct State;
  NcConfig config_;
  const OpticalModel& optics_;
  std::unique_ptr<State> state_;
};
}  // namespace scanhead
