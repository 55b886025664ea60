/// \file run_plan.hpp
/// \brief What a batch run will take, computed before it runs, and the checks that refuse a run
/// that could not finish or is physically impossible.
///
/// The plan is analytic: the NC program is built (O(segments), the same buildNcProgram as the NC)
/// and every figure follows from its timeline, never by sampling, so it costs milliseconds and
/// bounded memory even for a speed of 1e-12 m/s or a dwell of 1e9 s.
///
/// \par Machine time and samples (exactly as NcInterpolator::start, nc_plan.hpp)
/// \f[ N = \lceil (t_{end} + t_{tail}) / T_s \rceil + 1,\quad
///     t_{end} = \max(D_{program} + 2 D,\ \text{last laser-off} + \text{shift}) \f]
/// with D the filter delay ((T1 + T2)/2, or the adaptive filter's), the program the job after the
/// recipe, the speed cap, the delays and skywriting. Machine time = N·Ts. Test: equal to the NC's.
///
/// \par Memory (the buffers that grow with the job or a setting; bytes)
/// - stream chunks: chunk_samples × (setpoint + laser + joints + spot samples in flight + the NC's
///   work arrays), ≈ 1 kB a sample;
/// - NC box FIRs: (⌈T/Ts⌉ + 2) taps × (2·channels + 1) doubles, 3 filters of 2 channels on T1, one
///   of 4 and one of 2 on T2 (box_filter.hpp);
/// - the program and its copies (NC, corner tracker, laser checks, layer metrics): segments × 128 B × 5;
/// - energy map (tiled_energy_map.hpp): directory 4 B a tile of 64² pixels over the job's box ±
///   energy.map_margin_m, plus the tiles the spot touches (16 KiB each; estimated by rasterising
///   the laser-on segments grown by the truncated footprint at tile resolution) up to
///   energy.tile_cache_bytes resident, the rest spilled to disk;
/// - layer metrics (layer_quality.hpp): the actual path, 8 B a sample when N <= contour_max_samples,
///   its nearest-path index at the end (≈ 8 B a sample), the fill grid (2 bits a spot-diameter cell),
///   the same-instant ring (32 B × 2^⌈log2(2W/Ts + 3)⌉) and command cache;
/// - track energy: laser-on samples up to energy.track_max_samples, 88 B each (vector capacity);
/// - thermal view (if on): (window/cell)² cells × 48 B;
/// - the results folder's images: the overview and each crop, averaged to at most 4000 / 8000 px a
///   side (energy_exports.hpp), 10 B a pixel (float map, TIFF rows, 16-bit PNG) + the colour PNG
///   (4 B a pixel, at most 2000 px a side);
/// - a fixed base (code, optics, libraries): measured 30 MB.
///
/// \par Wall time (an estimate: the rates measured on the 2-core development VM, README "Performance")
/// producer (NC + servo + optics) ≈ N·(0.55 µs + 0.065 µs·(controller steps a sample − 1) +
/// 2 ns·FIR taps), energy stage ≈ N·1.5 µs + pixels × 9 ns (pixels: exact, per mark rows × (length
/// + rows) with rows = 2·R_trunc/pixel; sampled, rows² per sub-step), thermal view 3e4 samples/s,
/// plus 20 ms of setup; two threads take the larger of producer and energy stage, one the sum.
/// Fitted to the README's THESIS layer (67.9 s chain, 3.05e7 samples, 2.5e9 band pixels) and hatch
/// (3.2–3.5× real time); stated as a range [0.5×, 2×] of that figure.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "scanhead/chain/chain_config.hpp"
#include "scanhead/job/scan_job.hpp"
#include "scanhead/optics/optical_model.hpp"

namespace scanhead
{
/// \brief How fast the spot can move: the physical bound and the NC's.
///
/// A galvo's rotor cannot turn faster than its no-load speed, where the back-EMF K_e·ω equals the
/// whole driver supply U (galvo_plant.hpp: U = R i + L di/dt + K_e ω, so at ω > U/K_e the current,
/// hence the torque, is negative for every admissible voltage): \f$\omega_0 = U_{supply}/K_e\f$
/// (30 V / 0.024 V·s/rad = 1250 rad/s for this project's galvos, galvo_params.hpp). The spot moves
/// by \f$\dot x = J\dot q\f$ (J = d spot / d q, the optical model's Jacobian: ≈ 2·d at the centre,
/// d the mirror-to-plane distance, 2 for the reflection doubling the angle), so
/// \f[ |\dot x| \le \max_{field}\big(|J_{:,x}|\,\omega_{0,x} + |J_{:,y}|\,\omega_{0,y}\big) \f]
/// (maximised on a 21 × 21 grid over the field, corners included). A programmed speed above it
/// is impossible whatever the NC does. The NC's own limit is its velocity saturation between the
/// FIRs, nc.max_joint_speed_radps: above \f$\omega_{NC}/g\f$ (g: the largest joint rate per spot speed
/// over the field, joint_gain.hpp) some axis saturates (fixed filters) or the speed is capped
/// (adaptive, cap_speeds): a warning.
struct SpeedBounds
{
  Eigen::Vector2d no_load_speed_radps = Eigen::Vector2d::Zero();  ///< ω0 per axis (x, y) [rad/s]
  double max_spot_speed_mps = 0.0;                                ///< the physical bound above [m/s]
  double joint_rate_gain_rad_per_m = 0.0;                         ///< g, largest over the axes [rad/m]
  double saturation_speed_mps = 0.0;                              ///< nc.max_joint_speed_radps / g [m/s]
};

/// \brief The bounds for \p config's galvos and \p optics (21 × 21 Newton inverses: a few ms).
/// \throws NumericalError if a grid point is out of the optics' reach
SpeedBounds galvoSpeedBounds(const ChainConfig& config, const OpticalModel& optics);

/// \brief Highest mark (laser-on) speed of LPBF machines [m/s]: EOS M 290 up to 7 m/s, SLM 280
/// up to 10 m/s (catalogue maxima); above it a mark speed is a warning.
constexpr double kLpbfMaxMarkSpeed_mps = 10.0;
/// \brief Longest box FIR that is not questionable [s]: the industrial NC's are 260 and 125 µs
/// (NC §2.2), the THESIS's 395 µs; a longer one rounds corners by ≈ V·T1/4 (warning).
constexpr double kQuestionableFir_s = 2.0e-3;
/// \brief Pixel coarser than spot_diameter/5 is a warning (< 5 pixels across the 1/e² diameter).
constexpr double kQuestionablePixelPerDiameter = 0.2;
/// \brief A tail longer than this is a warning [s]: filters and servos settle within milliseconds.
constexpr double kQuestionableTail_s = 1.0;

/// \brief The estimated peak memory by part [bytes] (see the file comment).
struct MemoryEstimate
{
  double base = 0.0;           ///< code, optics, libraries, results images
  double chunks = 0.0;         ///< stream chunks in flight and the NC's per-chunk work arrays
  double nc_filters = 0.0;     ///< the NC's box FIRs
  double program = 0.0;        ///< the NC program and its copies in the energy stage
  double map_directory = 0.0;  ///< 4 B a tile over the whole map
  double map_tiles = 0.0;      ///< resident tiles (at most energy.tile_cache_bytes)
  double contour_path = 0.0;   ///< the actual path kept for the nearest-path contour error
  double contour_index = 0.0;  ///< its nearest-path index (built at the end)
  double same_instant = 0.0;   ///< the same-instant ring and command cache
  double fill_grid = 0.0;      ///< the fill-rate grid
  double track = 0.0;          ///< the track-energy samples
  double thermal = 0.0;        ///< the thermal view's grid
  double results = 0.0;        ///< the results folder's images (overview, crops)
  double total() const;
  /// \brief The largest part and its name (for messages).
  std::string largestPart(double* bytes = nullptr) const;
};

/// \brief What a run of one job will take (see the file comment for how each figure is computed).
struct RunPlan
{
  std::string job_name;
  double period_s = 0.0;                     ///< Ts [s]
  double program_duration_s = 0.0;           ///< the NC program: Σ L/v + holds + skywriting [s]
  double filter_delay_s = 0.0;               ///< D [s]
  double tail_s = 0.0;                       ///< nc.tail_s [s]
  double last_laser_off_s = 0.0;             ///< the last laser window's end on the sample timeline [s]
  double samples = 0.0;                      ///< N (a double: an absurd job may exceed 2^64)
  double machine_time_s = 0.0;               ///< N·Ts [s]
  double laser_on_samples = 0.0;             ///< samples inside the laser windows
  std::size_t segments = 0;                  ///< segments of the NC program
  std::int64_t map_width_px = 0;             ///< energy map [pixels]
  std::int64_t map_height_px = 0;            ///< [pixels]
  double map_tiles = 0.0;                    ///< tiles in the map's directory
  double map_tiles_touched = 0.0;            ///< estimated tiles the spot touches
  double map_tiles_resident = 0.0;           ///< of which kept in memory (energy.tile_cache_bytes)
  double map_spill_bytes = 0.0;              ///< estimated spill file (touched beyond the cache) [bytes]
  double pixels_drawn = 0.0;                 ///< estimated pixel weights the deposit computes
  double controller_steps_per_sample = 1.0;  ///< cascade servo: controller periods a sample
  MemoryEstimate memory;                     ///< estimated peak [bytes]
  double wall_time_s = 0.0;                  ///< estimated wall time of the chain (an estimate: ×0.5..2) [s]
  double setup_wall_s = 0.0;                 ///< of which the fixed part, whatever the job's length [s]
  SpeedBounds speeds;                        ///< the galvos' bounds used for the checks
  std::vector<std::string> warnings;         ///< questionable but possible values, one sentence each
};

/// \brief The plan of \p job (validated: validateScanJob) under \p config (validated).
/// \throws ConfigError / InputError for a physically impossible value, naming the key or the job
/// field, the allowed range and why: a speed above SpeedBounds::max_spot_speed_mps, a power above
/// kMaxLaserPower_w; what buildNcProgram throws.
RunPlan planRun(const ChainConfig& config, const Job& job, const OpticalModel& optics);

/// \brief Physical memory of the machine [bytes] (sysconf pages × page size; /proc/meminfo's
/// MemTotal). 0 if unknown.
std::uint64_t physicalMemoryBytes();

/// \brief The memory bound in force: limits.max_memory_fraction × \p physical_bytes, or
/// limits.max_memory_bytes if that is set and smaller (or the physical size is unknown) [bytes].
double memoryLimitBytes(const LimitsConfig& limits, std::uint64_t physical_bytes);

/// \brief Refuses a plan beyond \p limits. \throws ConfigError naming the cause (machine time,
/// samples, memory and its largest part), the figure, the bound and the key to raise
/// (limits.max_machine_time_s, limits.max_samples, limits.max_memory_fraction / max_memory_bytes)
/// or the setting to change.
void enforceRunLimits(const RunPlan& plan, const LimitsConfig& limits, std::uint64_t physical_bytes);

/// \brief The plan for the user, two lines: machine time, samples, map; memory and wall time.
std::string runPlanText(const RunPlan& plan);
}  // namespace scanhead
