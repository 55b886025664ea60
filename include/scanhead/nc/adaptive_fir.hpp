/// \file adaptive_fir.hpp
/// \brief Speed-adaptive jerk-limiting filter of the work-plane path (SPEC §2.6, NC §3.5).
///
/// The path X(t) of a PathTimeline is piecewise linear: its velocity is piecewise constant and
/// changes by a step Δv_k (a 2-vector) at each knot t_k (segment boundaries, t = 0 and the end).
/// A box T1 then a box T2 (the industrial filter) turns every step into a ramp whose acceleration
/// is the trapezoid rect_T1 ∗ rect_T2 (SPEC §2.3). Here each knot gets its own durations
/// (T1_k, T2_k), the shortest that keep the acceleration and jerk norms within the limits for the
/// worst step the local programmed speed V_k allows, a reversal Δ = 2·V_k:
/// \f[ T_1 = \max(\Delta/A,\ \sqrt{\Delta/J}),\qquad T_2 = \Delta/(J\,T_1) \le T_1 \f]
/// so that peak |Ẍ| = Δ/T1 <= A and peak |X⃛| = Δ/(T1·T2) <= J. V_k is the largest programmed
/// speed of the segments within ±W of t_k, W = T1 + T2 of the fastest speed in the job, so that
/// near a speed change the longer kernels win.
///
/// Corners closer than T1 + T2 superpose their kernels, and that sum can exceed what the rule
/// above guarantees for one step (two reversals T1 apart: 2·J; a 90° staircase: √2·J; kernels
/// of different lengths). The constructor checks the sum exactly (the acceleration is piecewise
/// linear and the jerk piecewise constant between the kernels' breakpoints t_k ± (T1_k ± T2_k)/2)
/// and lengthens every kernel taking part in an excess, as for a step that much larger, until
/// none is left; isolated corners keep the shortest durations.
///
/// The output is the superposition of the smoothed steps, each kernel centred on its knot, the
/// whole delayed by D = max_k (T1_k + T2_k)/2 (causal, at rest before t = 0):
/// \f[ X_f(t) = X(t - D) + \sum_k \Delta v_k \,\big[R_k(t - D - t_k) - \max(t - D - t_k, 0)\big] \f]
/// with R_k the position response to a unit velocity step (zero outside the kernel's support,
/// where the bracket vanishes by symmetry). With equal durations at every knot this is exactly
/// box_T1(box_T2(X)) delayed by D − (T1 + T2)/2. Velocity and acceleration are the exact
/// derivatives of the same expression.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "scanhead/job/path_timeline.hpp"

namespace scanhead
{
/// \brief Limits on the norm of the work-plane acceleration and jerk.
struct PlaneLimits
{
  double max_accel_mps2 = 0.0;  ///< A > 0 [m/s²]
  double max_jerk_mps3 = 0.0;   ///< J > 0 [m/s³]
};

struct FilterDurations
{
  double t1_s = 0.0;  ///< first box [s], >= t2_s
  double t2_s = 0.0;  ///< second box [s]
};

/// \brief Shortest T1 >= T2 with step/T1 <= A and step/(T1·T2) <= J (see the file comment);
/// {0, 0} for a zero step. \param step_mps Δ >= 0 [m/s]
FilterDurations minimalDurations(double step_mps, const PlaneLimits& limits);

/// \brief Kinematic state of the filtered path at one instant.
struct PlaneState
{
  Eigen::Vector2d position = Eigen::Vector2d::Zero();      ///< [m]
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();      ///< [m/s]
  Eigen::Vector2d acceleration = Eigen::Vector2d::Zero();  ///< [m/s²]
};

class AdaptiveFir
{
public:
  struct Knot
  {
    double t_s = 0.0;                                    ///< knot time on the path timeline [s]
    Eigen::Vector2d step_mps = Eigen::Vector2d::Zero();  ///< Δv_k [m/s]
    double local_speed_mps = 0.0;                        ///< V_k [m/s]
    FilterDurations durations;                           ///< (T1_k, T2_k), lengthened if kernels overlapped
  };

  /// \brief Where to resume; one per monotone reader (amortised O(active knots) per call).
  struct Cursor
  {
    std::size_t first_active = 0;  ///< first knot whose kernel has not ended (all before it have)
    PathTimeline::Cursor path;     ///< segment of X(t − D)
  };

  AdaptiveFir() = default;
  /// \param[in] timeline kept by reference: must outlive this
  /// \throws ConfigError if a limit is not finite and > 0
  /// \throws NumericalError if the lengthening of overlapping kernels does not settle (never seen)
  AdaptiveFir(const PathTimeline& timeline, const PlaneLimits& limits);

  /// \brief Both boxes (the setpoint path) at output time \p t_s.
  PlaneState filtered(double t_s, Cursor& cursor) const;
  /// \brief The first box only (T1_k kernels, same delay D): the analogue of Q_filt1.
  PlaneState firstStage(double t_s, Cursor& cursor) const;

  double delay() const { return delay_s_; }  ///< D [s]
  const std::vector<Knot>& knots() const { return knots_; }
  FilterDurations longest() const { return longest_; }  ///< durations of the fastest knot

private:
  /// Hot per-knot data of the evaluation loop (path time, not output time).
  struct Kernel
  {
    Eigen::Vector2d step_mps = Eigen::Vector2d::Zero();  ///< Δv_k [m/s]
    double t_s = 0.0;                                    ///< t_k [s]
    double half_s = 0.0;                                 ///< h = (T1 + T2)/2 [s]
    double plateau_s = 0.0;                              ///< a = (T1 − T2)/2 [s]
    double half_t1_s = 0.0;                              ///< T1/2 [s]
    double t2_s = 0.0;                                   ///< T2 [s]
    double inv_t1 = 0.0;                                 ///< 1/T1 [1/s]
    double inv_t1t2 = 0.0;                               ///< 1/(T1·T2) [1/s²] (0 if T2 = 0: never used then)
  };

  PlaneState evaluate(double t_s, Cursor& cursor, bool first_stage) const;
  void setKernels();
  bool lengthenWhereOverlapsExceed(std::vector<double>& accel_step_mps, std::vector<double>& jerk_step_mps,
                                   std::vector<char>& changed) const;

  const PathTimeline* timeline_ = nullptr;
  PlaneLimits limits_;
  std::vector<Knot> knots_;
  double delay_s_ = 0.0;
  FilterDurations longest_;
  std::vector<Kernel> kernels_;                ///< one per knot, same order
  std::vector<double> prefix_max_end_s_;       ///< max_{j <= k} (t_j + h_j) [s]
  std::vector<double> suffix_min_start_s_;     ///< min_{j >= k} (t_j − h_j) [s]
  std::vector<Eigen::Vector2d> seg_velocity_;  ///< (end − start)/duration per segment [m/s]
};
}  // namespace scanhead
