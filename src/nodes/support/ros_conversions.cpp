#include "ros_conversions.hpp"

#include <stdexcept>

namespace scanhead
{
const char* const kJointNames[2] = {"galvo_x", "galvo_y"};

namespace
{
template <class Chunk>
Chunk emptyChunk(const ChunkHeader& header, std::size_t size)
{
  Chunk chunk;
  chunk.first_index = header.first_index;
  chunk.period_s = header.period;
  chunk.samples.resize(size);
  return chunk;
}

void checkSize(std::size_t actual, std::size_t expected, const char* what)
{
  if (actual != expected)
    throw std::invalid_argument(std::string(what) + ": array of " + std::to_string(actual) + " values, expected " +
                                std::to_string(expected));
}

void put2(std::vector<double>& out, const Eigen::Vector2d& v)
{
  out.push_back(v.x());
  out.push_back(v.y());
}
}  // namespace

ChunkHeader makeChunkHeader(std::uint32_t job_id, std::uint64_t first_index, double period_s,
                            std::uint64_t total_samples)
{
  ChunkHeader header;
  header.header.stamp = ros::Time(static_cast<double>(first_index) * period_s);
  header.job_id = job_id;
  header.first_index = first_index;
  header.period = period_s;
  header.total_samples = total_samples;
  return header;
}

Job fromMsg(const ScanJob& msg)
{
  Job job;
  job.name = msg.name;
  job.source = msg.source;
  job.placement.rotation_deg = msg.placement_rotation_deg;
  job.placement.offset_m = Eigen::Vector2d(msg.placement_offset_m[0], msg.placement_offset_m[1]);
  job.placement.centred = msg.placement_centred;
  for (const ScanPolyline& p : msg.polylines)
  {
    checkSize(p.y.size(), p.x.size(), "ScanPolyline.y");
    Polyline line;
    line.type = p.type == ScanPolyline::JUMP ? PolylineType::Jump : PolylineType::Mark;
    line.speed_mps = p.speed;
    line.power_w = p.power;
    line.dwell_s = p.dwell;
    line.role = p.role == ScanPolyline::CONTOUR ? PolylineRole::Contour
                : p.role == ScanPolyline::HATCH ? PolylineRole::Hatch
                                                : PolylineRole::Unspecified;
    for (std::size_t k = 0; k < p.x.size(); ++k)
      line.points.emplace_back(p.x[k], p.y[k]);
    job.polylines.push_back(std::move(line));
  }
  return job;
}

ScanJob toMsg(const Job& job, std::uint32_t job_id)
{
  ScanJob msg;
  msg.job_id = job_id;
  msg.name = job.name;
  msg.source = job.source;
  msg.placement_rotation_deg = job.placement.rotation_deg;
  msg.placement_offset_m = {job.placement.offset_m.x(), job.placement.offset_m.y()};
  msg.placement_centred = job.placement.centred;
  for (const Polyline& line : job.polylines)
  {
    ScanPolyline p;
    p.type = line.type == PolylineType::Jump ? ScanPolyline::JUMP : ScanPolyline::MARK;
    p.speed = line.speed_mps;
    p.power = line.power_w;
    p.dwell = line.dwell_s;
    p.role = line.role == PolylineRole::Contour ? ScanPolyline::CONTOUR
             : line.role == PolylineRole::Hatch ? ScanPolyline::HATCH
                                                : ScanPolyline::UNSPECIFIED;
    for (const Eigen::Vector2d& q : line.points)
    {
      p.x.push_back(q.x());
      p.y.push_back(q.y());
    }
    msg.polylines.push_back(std::move(p));
  }
  return msg;
}

SetpointChunk fromMsg(const NcSetpoint& msg)
{
  auto chunk = emptyChunk<SetpointChunk>(msg.chunk, msg.trajectory.points.size());
  for (std::size_t k = 0; k < chunk.samples.size(); ++k)
  {
    const auto& p = msg.trajectory.points[k];
    checkSize(p.positions.size(), 2, "NcSetpoint positions");
    checkSize(p.velocities.size(), 2, "NcSetpoint velocities");
    checkSize(p.accelerations.size(), 2, "NcSetpoint accelerations");
    chunk.samples[k].position = Eigen::Vector2d(p.positions[0], p.positions[1]);
    chunk.samples[k].velocity = Eigen::Vector2d(p.velocities[0], p.velocities[1]);
    chunk.samples[k].acceleration = Eigen::Vector2d(p.accelerations[0], p.accelerations[1]);
  }
  return chunk;
}

NcSetpoint toMsg(const SetpointChunk& chunk, const ChunkHeader& header)
{
  NcSetpoint msg;
  msg.chunk = header;
  msg.trajectory.header.stamp = header.header.stamp;
  msg.trajectory.joint_names = {kJointNames[0], kJointNames[1]};
  msg.trajectory.points.resize(chunk.samples.size());
  for (std::size_t k = 0; k < chunk.samples.size(); ++k)
  {
    const SetpointSample& s = chunk.samples[k];
    auto& p = msg.trajectory.points[k];
    p.positions = {s.position.x(), s.position.y()};
    p.velocities = {s.velocity.x(), s.velocity.y()};
    p.accelerations = {s.acceleration.x(), s.acceleration.y()};
    p.time_from_start = ros::Duration(static_cast<double>(k) * chunk.period_s);
  }
  return msg;
}

LaserChunk fromMsg(const NcLaser& msg)
{
  auto chunk = emptyChunk<LaserChunk>(msg.chunk, msg.power.size());
  for (std::size_t k = 0; k < chunk.samples.size(); ++k)
    chunk.samples[k].power_w = msg.power[k];
  return chunk;
}

NcLaser toMsg(const LaserChunk& chunk, const ChunkHeader& header)
{
  NcLaser msg;
  msg.chunk = header;
  msg.power.reserve(chunk.samples.size());
  for (const LaserSample& s : chunk.samples)
    msg.power.push_back(s.power_w);
  return msg;
}

NcDebug toMsg(const NcDebugChunk& chunk, const ChunkHeader& header)
{
  NcDebug msg;
  msg.chunk = header;
  for (const NcDebugSample& s : chunk.samples)
  {
    put2(msg.x_inter, s.x_inter);
    put2(msg.q_inter, s.q_inter);
    put2(msg.q_inter_velocity, s.q_inter_velocity);
    put2(msg.q_inter_acceleration, s.q_inter_acceleration);
    put2(msg.q_filt1, s.q_filt1);
    put2(msg.q_filt1_velocity, s.q_filt1_velocity);
    put2(msg.q_filt1_acceleration, s.q_filt1_acceleration);
  }
  return msg;
}

JointChunk fromMsg(const JointStreamChunk& msg)
{
  checkSize(msg.joint_names.size(), 2, "JointStreamChunk joint_names");
  const std::size_t n = msg.position.size() / 2;
  checkSize(msg.position.size(), 2 * n, "JointStreamChunk position");
  checkSize(msg.velocity.size(), 2 * n, "JointStreamChunk velocity");
  checkSize(msg.effort.size(), 2 * n, "JointStreamChunk effort");
  auto chunk = emptyChunk<JointChunk>(msg.chunk, n);
  for (std::size_t k = 0; k < n; ++k)
  {
    chunk.samples[k].position = Eigen::Vector2d(msg.position[2 * k], msg.position[2 * k + 1]);
    chunk.samples[k].velocity = Eigen::Vector2d(msg.velocity[2 * k], msg.velocity[2 * k + 1]);
    chunk.samples[k].current = Eigen::Vector2d(msg.effort[2 * k], msg.effort[2 * k + 1]);
  }
  return chunk;
}

JointStreamChunk toMsg(const JointChunk& chunk, const ChunkHeader& header)
{
  JointStreamChunk msg;
  msg.chunk = header;
  msg.joint_names = {kJointNames[0], kJointNames[1]};
  const std::size_t n = chunk.samples.size();  // sized once: no regrowth while filling
  msg.position.reserve(2 * n);
  msg.velocity.reserve(2 * n);
  msg.effort.reserve(2 * n);
  for (const JointSample& s : chunk.samples)
  {
    put2(msg.position, s.position);
    put2(msg.velocity, s.velocity);
    put2(msg.effort, s.current);
  }
  return msg;
}

SpotChunk fromMsg(const SpotStream& msg)
{
  const std::size_t n = msg.power.size();
  checkSize(msg.actual.size(), 2 * n, "SpotStream actual");
  checkSize(msg.setpoint.size(), 2 * n, "SpotStream setpoint");
  checkSize(msg.direction.size(), 3 * n, "SpotStream direction");
  checkSize(msg.angle_error.size(), 2 * n, "SpotStream angle_error");
  auto chunk = emptyChunk<SpotChunk>(msg.chunk, n);
  for (std::size_t k = 0; k < n; ++k)
  {
    SpotSample& s = chunk.samples[k];
    s.actual = Eigen::Vector2d(msg.actual[2 * k], msg.actual[2 * k + 1]);
    s.setpoint = Eigen::Vector2d(msg.setpoint[2 * k], msg.setpoint[2 * k + 1]);
    s.direction = Eigen::Vector3d(msg.direction[3 * k], msg.direction[3 * k + 1], msg.direction[3 * k + 2]);
    s.angle_error = Eigen::Vector2d(msg.angle_error[2 * k], msg.angle_error[2 * k + 1]);
    s.power_w = msg.power[k];
  }
  return chunk;
}

SpotStream toMsg(const SpotChunk& chunk, const ChunkHeader& header)
{
  SpotStream msg;
  msg.chunk = header;
  const std::size_t n = chunk.samples.size();  // sized once: no regrowth while filling
  msg.actual.reserve(2 * n);
  msg.setpoint.reserve(2 * n);
  msg.direction.reserve(3 * n);
  msg.angle_error.reserve(2 * n);
  msg.power.reserve(n);
  for (const SpotSample& s : chunk.samples)
  {
    put2(msg.actual, s.actual);
    put2(msg.setpoint, s.setpoint);
    msg.direction.insert(msg.direction.end(), {s.direction.x(), s.direction.y(), s.direction.z()});
    put2(msg.angle_error, s.angle_error);
    msg.power.push_back(s.power_w);
  }
  return msg;
}

NcJobPlan toMsg(const NcPlan& plan, std::uint32_t job_id, const std::string& settings_yaml)
{
  NcJobPlan msg;
  msg.job_id = job_id;
  msg.job_name = plan.job_name;
  msg.period_s = plan.period_s;
  msg.total_samples = plan.total_samples;
  msg.speed_cap_mps = plan.speed_cap_mps;
  msg.filter_delay_s = plan.filter_delay_s;
  msg.gate_shift_s = plan.gate_shift_s;
  msg.longest_t1_s = plan.longest_t1_s;
  msg.longest_t2_s = plan.longest_t2_s;
  msg.servo_delay_s = plan.servo_delay_s;
  msg.start_joints_rad = {plan.start_joints_rad.x(), plan.start_joints_rad.y()};
  msg.laser_on_delay_s = plan.program.laser_on_delay_s;
  msg.laser_off_delay_s = plan.program.laser_off_delay_s;
  const NcProgramStats& stats = plan.program.stats;
  msg.capped_polylines = stats.capped_polylines;
  msg.delay_holds = stats.delay_holds;
  msg.polygon_holds = stats.polygon_holds;
  msg.skywritten_corners = stats.skywritten_corners;
  msg.added_time_s = stats.added_time_s;
  for (const PathSegment& s : plan.program.timeline.segments())
  {
    msg.start_x.push_back(s.start_m.x());
    msg.start_y.push_back(s.start_m.y());
    msg.end_x.push_back(s.end_m.x());
    msg.end_y.push_back(s.end_m.y());
    msg.speed_mps.push_back(s.speed_mps);
    msg.power_w.push_back(s.power_w);
    msg.duration_s.push_back(s.duration_s);
    msg.length_m.push_back(s.length_m);
    msg.flags.push_back(static_cast<std::uint8_t>((s.mark ? 1 : 0) | (s.implicit_jump ? 2 : 0) | (s.dwell ? 4 : 0) |
                                                  (s.delay ? 8 : 0) | (s.skywriting ? 16 : 0)));
    msg.polyline.push_back(s.polyline);
    msg.vertex.push_back(s.vertex);
  }
  msg.settings_yaml = settings_yaml;
  return msg;
}

NcPlan fromMsg(const NcJobPlan& msg)
{
  const std::size_t n = msg.start_x.size();
  for (std::size_t size :
       {msg.start_y.size(), msg.end_x.size(), msg.end_y.size(), msg.speed_mps.size(), msg.power_w.size(),
        msg.duration_s.size(), msg.length_m.size(), msg.flags.size(), msg.polyline.size(), msg.vertex.size()})
  {
    if (size != n)
      throw std::invalid_argument("nc/plan of job " + std::to_string(msg.job_id) +
                                  ": segment arrays of different lengths");
  }
  std::vector<PathSegment> segments(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    PathSegment& s = segments[k];
    s.start_m = Eigen::Vector2d(msg.start_x[k], msg.start_y[k]);
    s.end_m = Eigen::Vector2d(msg.end_x[k], msg.end_y[k]);
    s.speed_mps = msg.speed_mps[k];
    s.power_w = msg.power_w[k];
    s.duration_s = msg.duration_s[k];
    s.length_m = msg.length_m[k];
    s.mark = (msg.flags[k] & 1) != 0;
    s.implicit_jump = (msg.flags[k] & 2) != 0;
    s.dwell = (msg.flags[k] & 4) != 0;
    s.delay = (msg.flags[k] & 8) != 0;
    s.skywriting = (msg.flags[k] & 16) != 0;
    s.polyline = static_cast<std::size_t>(msg.polyline[k]);
    s.vertex = static_cast<std::size_t>(msg.vertex[k]);
  }
  NcProgramStats stats;
  stats.capped_polylines = static_cast<std::size_t>(msg.capped_polylines);
  stats.delay_holds = static_cast<std::size_t>(msg.delay_holds);
  stats.polygon_holds = static_cast<std::size_t>(msg.polygon_holds);
  stats.skywritten_corners = static_cast<std::size_t>(msg.skywritten_corners);
  stats.added_time_s = msg.added_time_s;
  NcPlan plan;
  plan.job_name = msg.job_name;
  plan.program = ncProgramFromSegments(std::move(segments), msg.laser_on_delay_s, msg.laser_off_delay_s, stats);
  plan.period_s = msg.period_s;
  plan.total_samples = msg.total_samples;
  plan.speed_cap_mps = msg.speed_cap_mps;
  plan.filter_delay_s = msg.filter_delay_s;
  plan.gate_shift_s = msg.gate_shift_s;
  plan.longest_t1_s = msg.longest_t1_s;
  plan.longest_t2_s = msg.longest_t2_s;
  plan.servo_delay_s = msg.servo_delay_s;
  plan.start_joints_rad = Eigen::Vector2d(msg.start_joints_rad[0], msg.start_joints_rad[1]);
  return plan;
}
}  // namespace scanhead
