/// \file optical_chain_stage.hpp
/// \brief The optics stage: setpoint, measured joints and laser, joined sample by sample, become
/// the spot stream (setpoint spot, actual spot, beam direction, power).
#pragma once

#include "scanhead/common/chunk.hpp"
#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
class OpticalChainStage
{
public:
  explicit OpticalChainStage(const OpticalModel& optics)
    : optics_(optics)
  {
  }

  /// \pre the three chunks cover the same samples (same first_index, size and period)
  /// \throws std::invalid_argument if they do not
  SpotChunk process(const SetpointChunk& setpoint, const JointChunk& joints, const LaserChunk& laser) const;

private:
  const OpticalModel& optics_;
};
}  // namespace scanhead
