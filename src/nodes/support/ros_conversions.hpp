/// \file ros_conversions.hpp
/// \brief Messages ⇄ core chunks and jobs. Every conversion is exact (doubles copied as doubles).
#pragma once

#include <scanhead/JointStreamChunk.h>
#include <scanhead/NcDebug.h>
#include <scanhead/NcJobPlan.h>
#include <scanhead/NcLaser.h>
#include <scanhead/NcSetpoint.h>
#include <scanhead/ScanJob.h>
#include <scanhead/SpotStream.h>

#include "scanhead/common/chunk.hpp"
#include "scanhead/job/scan_job.hpp"
#include "scanhead/nc/nc_plan.hpp"

namespace scanhead
{
/// \brief Joint names of the setpoint and measured streams (the URDF's revolute joints).
extern const char* const kJointNames[2];

ChunkHeader makeChunkHeader(std::uint32_t job_id, std::uint64_t first_index, double period_s,
                            std::uint64_t total_samples);

Job fromMsg(const ScanJob& msg);
ScanJob toMsg(const Job& job, std::uint32_t job_id);

SetpointChunk fromMsg(const NcSetpoint& msg);
NcSetpoint toMsg(const SetpointChunk& chunk, const ChunkHeader& header);

LaserChunk fromMsg(const NcLaser& msg);
NcLaser toMsg(const LaserChunk& chunk, const ChunkHeader& header);

NcDebug toMsg(const NcDebugChunk& chunk, const ChunkHeader& header);

JointChunk fromMsg(const JointStreamChunk& msg);
JointStreamChunk toMsg(const JointChunk& chunk, const ChunkHeader& header);

SpotChunk fromMsg(const SpotStream& msg);
SpotStream toMsg(const SpotChunk& chunk, const ChunkHeader& header);
/// \brief The plan as a message (exact), with the sender's settings (chainConfigToYaml) for the
/// consumers' consistency check.
NcJobPlan toMsg(const NcPlan& plan, std::uint32_t job_id, const std::string& settings_yaml);
/// \brief The plan of a message: the program rebuilt bit for bit (ncProgramFromSegments).
/// \throws std::invalid_argument if the segment arrays differ in length
NcPlan fromMsg(const NcJobPlan& msg);
}  // namespace scanhead
