/// \file thermal_layer.cpp
/// \brief PATH eq. 5 on a window that follows the spot (SPEC §5): the stream cut into steps, the
/// source, the step's sequence (loss, LOD solves, switches, active box) and the energy books.
#include "scanhead/thermal/thermal_layer.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr double kFlushK = 1.0e-100;    // rises below this are set to 0 (no denormals far from the track)
constexpr double kMaxSubsteps = 1.0e6;  // a longer laser-on segment in one sample is garbage

const ThermalConfig& validated(const ThermalConfig& config)
{
  config.validate();
  return config;
}

double harmonicMean(double a, double b)
{
  return 2.0 * a * b / (a + b);
}

double arithmeticMean(double a, double b)
{
  return 0.5 * (a + b);
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// Construction, stream
// ---------------------------------------------------------------------------------------------
ThermalLayer::ThermalLayer(const ThermalConfig& config)
  : config_(validated(config))
{
  const double cell = config_.cell_m;
  const int n = static_cast<int>(std::ceil(config_.window_m / cell - 1e-9));
  w_ = 0.5 * config_.spot_diameter_m;
  kappa_s_ = config_.kappaMelted();
  lambda_s_ = config_.conductivityMelted();
  keep_energy_ = config_.phase_switch == "keep_energy";
  kappa_p_ = config_.kappaPowder();
  loss_ = config_.lossCoefficient();
  melt_rise_ = config_.meltRiseK();
  CellMaterials materials;
  materials.kappa_solid = kappa_s_;
  materials.kappa_powder = kappa_p_;
  materials.lambda_solid = lambda_s_;
  materials.lambda_powder = config_.conductivity_powder_w_m_k;
  materials.h_area = config_.layer_thickness_m * cell * cell;
  materials.face = config_.face_conductivity == "harmonic" ? &harmonicMean : &arithmeticMean;
  window_.allocate(n, cell, materials);
  pool_stats_ = MeltPoolAccumulator(melt_rise_);
  const int stencil = 2 * static_cast<int>(std::ceil(config_.source_truncation_radii * w_ / cell)) + 3;
  gx_.assign(stencil, 0.0);
  gy_.assign(stencil, 0.0);
  reset();
}

void ThermalLayer::reset()
{
  window_.reset();
  switched_.clear();
  record_ = MeltedRecord();
  sequence_.reset();
  period_s_ = 0.0;
  pending_.clear();
  step_count_ = 0;
  burst_on_ = false;
  burst_start_index_ = 0;
  has_on_pos_ = false;
  last_on_pos_ = last_pos_ = Eigen::Vector2d::Zero();
  dir_ = Eigen::Vector2d(1.0, 0.0);
  recent_.clear();
  last_ = ThermalStep();
  pool_stats_.reset();
  books_ = ThermalEnergy();
}

void ThermalLayer::process(const SpotChunk& chunk)
{
  recent_.clear();
  if (!(chunk.period_s > 0.0) || !std::isfinite(chunk.period_s))
  {
    std::ostringstream msg;
    msg << "thermal: chunk period_s must be > 0 (got " << chunk.period_s << ") at sample " << chunk.first_index;
    throw InputError(msg.str());
  }
  const bool started = sequence_.started();
  if (started && chunk.period_s != period_s_)
  {
    std::ostringstream msg;
    msg << "thermal: chunk period_s changed from " << period_s_ << " to " << chunk.period_s << " s at sample "
        << chunk.first_index;
    throw InputError(msg.str());
  }
  period_s_ = chunk.period_s;  // checked above; set before any sample may throw
  const ChunkAdmission admission = sequence_.admit(chunk.first_index, chunk.samples.size());
  for (std::size_t k = admission.skip; k < chunk.samples.size(); ++k)  // earlier ones already simulated
  {
    const std::uint64_t index = chunk.first_index + k;
    const SpotSample& s = chunk.samples[k];
    if (!std::isfinite(s.power_w) || s.power_w < 0.0)
    {
      std::ostringstream msg;
      msg << "thermal: sample " << index << " has power " << s.power_w << " W (must be finite and >= 0)";
      throw NumericalError(msg.str());
    }
    if (s.power_w > 0.0 && !s.actual.allFinite())
    {
      std::ostringstream msg;
      msg << "thermal: sample " << index << " has a non-finite spot position (" << s.actual.x() << ", " << s.actual.y()
          << ") m while the laser is on (" << s.power_w << " W)";
      throw NumericalError(msg.str());
    }
    if (k == admission.skip && admission.broken(started))
    {
      for (std::uint64_t g = index - admission.missing; g < index; ++g)  // gap: laser off where the spot last was
      {
        SpotSample off;
        off.actual = off.setpoint = last_pos_;
        off.power_w = 0.0;
        pushSample(off, g);
      }
    }
    pushSample(s, index);
    if (s.actual.allFinite())
      last_pos_ = s.actual;
  }
}

void ThermalLayer::pushSample(const SpotSample& s, std::uint64_t index)
{
  pending_.push_back(Pending{s, index});
  const std::size_t n = config_.step_samples;
  if (pending_.size() == n + 1)
  {
    runStep(n, &pending_[n].sample);
    pending_[0] = pending_[n];
    pending_.resize(1);
  }
}

void ThermalLayer::finish()
{
  recent_.clear();
  if (!pending_.empty())
  {
    runStep(pending_.size(), nullptr);
    pending_.clear();
  }
}

// ---------------------------------------------------------------------------------------------
// One thermal step
// ---------------------------------------------------------------------------------------------
void ThermalLayer::runStep(std::size_t count, const SpotSample* next)
{
  const int n = window_.n;
  const double cell = window_.cell_m;
  const double h_area = window_.materials.h_area;
  const double ts = period_s_;
  const double dt = static_cast<double>(count) * ts;
  ThermalStep step;
  step.first_index = pending_[0].index;
  step.samples = static_cast<std::uint32_t>(count);
  step.time_s = static_cast<double>(step.first_index + count) * ts;

  // Laser bursts, scan direction, segments.
  bool all_on = true;
  Eigen::Vector2d lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  for (std::size_t k = 0; k < count; ++k)
  {
    const SpotSample& s = pending_[k].sample;
    if (s.power_w > 0.0)
    {
      step.laser_on = true;
      if (!burst_on_)
      {
        burst_on_ = true;
        burst_start_index_ = pending_[k].index;
      }
      if (has_on_pos_)
      {
        const Eigen::Vector2d d = s.actual - last_on_pos_;
        const double norm = d.norm();
        if (norm > 1e-9)
          dir_ = d / norm;
      }
      last_on_pos_ = s.actual;
      has_on_pos_ = true;
      const SpotSample* to = k + 1 < count ? &pending_[k + 1].sample : next;
      const Eigen::Vector2d end = (to && to->actual.allFinite()) ? to->actual : s.actual;
      lo = lo.cwiseMin(s.actual).cwiseMin(end);
      hi = hi.cwiseMax(s.actual).cwiseMax(end);
    }
    else
    {
      all_on = false;
      burst_on_ = false;
      has_on_pos_ = false;
    }
  }
  step.steady = all_on && static_cast<double>(step.first_index - burst_start_index_) * ts >= config_.settle_time_s;

  // Window placement.
  if (step.laser_on)
  {
    const Eigen::Vector2d centre = 0.5 * (lo + hi);
    if (!window_.placed)
      window_.place(centre, record_, books_.left_window_j);
    else
    {
      const double m = config_.recentre_margin_m / cell;
      const double ulo = lo.x() / cell - window_.oi, uhi = hi.x() / cell - window_.oi;
      const double vlo = lo.y() / cell - window_.oj, vhi = hi.y() / cell - window_.oj;
      if (ulo < m || vlo < m || uhi > n - m || vhi > n - m)
        window_.place(centre, record_, books_.left_window_j);
    }
  }

  // Source.
  CellBox src_box;
  for (std::size_t k = 0; k < count; ++k)
  {
    const SpotSample& s = pending_[k].sample;
    if (!(s.power_w > 0.0))
      continue;
    const SpotSample* to = k + 1 < count ? &pending_[k + 1].sample : next;
    const Eigen::Vector2d end = (to && to->actual.allFinite()) ? to->actual : s.actual;
    const double energy = config_.absorptivity * s.power_w * ts;
    books_.absorbed_j += energy;
    const double length = (end - s.actual).norm();
    const double sub = std::max(1.0, std::ceil(length / (config_.max_substep_radii * w_)));
    if (sub > kMaxSubsteps)
    {
      std::ostringstream msg;
      msg << "thermal: sample " << pending_[k].index << ": spot moved " << length
          << " m in one sample with the laser on (implausible)";
      throw NumericalError(msg.str());
    }
    const int m = static_cast<int>(sub);
    for (int q = 0; q < m; ++q)
    {
      const double f = (q + 0.5) / sub;
      depositPoint(s.actual.x() + f * (end.x() - s.actual.x()), s.actual.y() + f * (end.y() - s.actual.y()),
                   energy / sub, src_box);
    }
  }

  // Active box: hot cells (grown last step) ∪ footprint, grown by the diffusion reach of one step.
  const double a_max = std::max(lambda_s_, config_.conductivity_powder_w_m_k) / std::min(kappa_s_, kappa_p_);
  const int grow = 2 + static_cast<int>(std::ceil(3.0 * std::sqrt(a_max * dt) / cell));
  CellBox b = window_.box;
  if (!src_box.empty())
  {
    if (b.empty())
      b = src_box;
    else
    {
      b.i0 = std::min(b.i0, src_box.i0);
      b.i1 = std::max(b.i1, src_box.i1);
      b.j0 = std::min(b.j0, src_box.j0);
      b.j1 = std::max(b.j1, src_box.j1);
    }
    b.i0 = std::max(0, b.i0 - grow);
    b.j0 = std::max(0, b.j0 - grow);
    b.i1 = std::min(n - 1, b.i1 + grow);
    b.j1 = std::min(n - 1, b.j1 + grow);
  }
  window_.box = b;

  int peak_i = -1, peak_j = -1;
  if (!window_.box.empty())
  {
    // Loss exactly, half before and half after the source and the diffusion (Strang): for one
    // material it commutes with the diffusion, so a dwell's energy is second-order accurate in dt.
    const LossHalfStep loss = lossHalfStep(dt, loss_, window_.materials);
    double lost = 0.0;
    if (step_count_ % 2 == 0)
    {
      lodSweepX(window_, window_.box, true, dt, loss, lost);
      lodSweepY(window_, window_.box, false, dt, loss, lost);
    }
    else
    {
      lodSweepY(window_, window_.box, true, dt, loss, lost);
      lodSweepX(window_, window_.box, false, dt, loss, lost);
    }
    books_.lost_j += lost;
    if (!src_box.empty())
    {
      for (int j = src_box.j0; j <= src_box.j1; ++j)
        std::fill(window_.src.begin() + static_cast<std::size_t>(j) * n + src_box.i0,
                  window_.src.begin() + static_cast<std::size_t>(j) * n + src_box.i1 + 1, 0.0);
    }
    postStep(loss, peak_i, peak_j);
    // Box for the next step: cells above the threshold, grown.
    if (!window_.box.empty())
    {
      window_.box.i0 = std::max(0, window_.box.i0 - grow);
      window_.box.j0 = std::max(0, window_.box.j0 - grow);
      window_.box.i1 = std::min(n - 1, window_.box.i1 + grow);
      window_.box.j1 = std::min(n - 1, window_.box.j1 + grow);
    }
    // Cells of the solved box outside the new one are below the threshold: drop them.
    auto drop = [&](int j, int i_from, int i_to) {
      double* row = &window_.t[static_cast<std::size_t>(j) * n];
      const std::uint8_t* sol = &window_.solid[static_cast<std::size_t>(j) * n];
      for (int i = i_from; i <= i_to; ++i)
      {
        if (row[i] != 0.0)
        {
          books_.truncated_j += (sol[i] ? kappa_s_ : kappa_p_) * row[i] * h_area;
          row[i] = 0.0;
        }
      }
    };
    for (int j = b.j0; j <= b.j1; ++j)
    {
      if (window_.box.empty() || j < window_.box.j0 || j > window_.box.j1)
        drop(j, b.i0, b.i1);
      else
      {
        drop(j, b.i0, window_.box.i0 - 1);
        drop(j, window_.box.i1 + 1, b.i1);
      }
    }
  }
  ++step_count_;

  if (peak_i >= 0)
  {
    step.peak_k = window_.t[static_cast<std::size_t>(peak_j) * n + peak_i];
    if (step.peak_k > melt_rise_)
      measureMeltPool(window_, peak_i, peak_j, dir_, melt_rise_, step);
  }
  pool_stats_.add(step);
  last_ = step;
  recent_.push_back(step);
}

void ThermalLayer::depositPoint(double x, double y, double energy_j, CellBox& src_box)
{
  const int n = window_.n;
  const double cell = window_.cell_m;
  const double u = x / cell - static_cast<double>(window_.oi);
  const double v = y / cell - static_cast<double>(window_.oj);
  const double r = config_.source_truncation_radii * w_ / cell;
  if (!(u + r >= 0.0 && v + r >= 0.0 && u - r < n && v - r < n))
  {
    books_.outside_j += energy_j;
    return;
  }
  const int ilo = static_cast<int>(std::floor(u - r)), ihi = static_cast<int>(std::floor(u + r));
  const int jlo = static_cast<int>(std::floor(v - r)), jhi = static_cast<int>(std::floor(v + r));
  const double k2 = 2.0 * cell * cell / (w_ * w_);
  double sx = 0.0, sxin = 0.0, sy = 0.0, syin = 0.0;
  for (int i = ilo; i <= ihi; ++i)
  {
    const double d = i + 0.5 - u;
    const double g = std::exp(-k2 * d * d);
    gx_[i - ilo] = g;
    sx += g;
    if (i >= 0 && i < n)
      sxin += g;
  }
  for (int j = jlo; j <= jhi; ++j)
  {
    const double d = j + 0.5 - v;
    const double g = std::exp(-k2 * d * d);
    gy_[j - jlo] = g;
    sy += g;
    if (j >= 0 && j < n)
      syin += g;
  }
  const double scale = energy_j / (sx * sy);
  books_.outside_j += energy_j - scale * sxin * syin;
  const int i0 = std::max(ilo, 0), i1 = std::min(ihi, n - 1);
  const int j0 = std::max(jlo, 0), j1 = std::min(jhi, n - 1);
  if (i1 < i0 || j1 < j0)
    return;
  for (int j = j0; j <= j1; ++j)
  {
    double* row = &window_.src[static_cast<std::size_t>(j) * n];
    const double gj = scale * gy_[j - jlo];
    for (int i = i0; i <= i1; ++i)
      row[i] += gj * gx_[i - ilo];
  }
  if (src_box.empty())
    src_box = CellBox{i0, i1, j0, j1};
  else
  {
    src_box.i0 = std::min(src_box.i0, i0);
    src_box.i1 = std::max(src_box.i1, i1);
    src_box.j0 = std::min(src_box.j0, j0);
    src_box.j1 = std::max(src_box.j1, j1);
  }
}

// Second half of the loss, peak, powder → solid switches, flush, and the box of cells above the
// threshold (window_.box on return).
void ThermalLayer::postStep(const LossHalfStep& loss, int& peak_i, int& peak_j)
{
  const int n = window_.n;
  const double h_area = window_.materials.h_area;
  const CellBox b = window_.box;
  const double fs = loss.decay_solid, fp = loss.decay_powder;
  const double ls = loss.lost_solid, lp = loss.lost_powder;
  double lost = 0.0;
  CellBox hot;
  bool any = false;
  double peak = -INFINITY;
  const double eps = config_.active_threshold_k;
  switched_.clear();
  for (int j = b.j0; j <= b.j1; ++j)
  {
    const std::size_t row = static_cast<std::size_t>(j) * n;
    double* t = &window_.t[row];
    std::uint8_t* sol = &window_.solid[row];
    int row_first = -1, row_last = -1;
    for (int i = b.i0; i <= b.i1; ++i)
    {
      double v = t[i];
      lost += (sol[i] ? ls : lp) * v;
      v *= sol[i] ? fs : fp;
      t[i] = v;
      if (v > melt_rise_ && !sol[i])
      {
        sol[i] = 1;
        if (keep_energy_)
        {
          v *= kappa_p_ / kappa_s_;
          t[i] = v;
        }
        else
          books_.phase_switch_j += (kappa_s_ - kappa_p_) * v * h_area;
        switched_.push_back(static_cast<std::int32_t>(row + i));
      }
      if (v > peak)
      {
        peak = v;
        peak_i = i;
        peak_j = j;
      }
      if (v > eps)
      {
        row_first = row_first < 0 ? i : row_first;
        row_last = i;
      }
      else if (v < kFlushK && v != 0.0)
      {
        books_.truncated_j += (sol[i] ? kappa_s_ : kappa_p_) * v * h_area;
        t[i] = 0.0;
      }
    }
    if (row_first >= 0)
    {
      if (!any)
      {
        hot = CellBox{row_first, row_last, j, j};
        any = true;
      }
      hot.i0 = std::min(hot.i0, row_first);
      hot.i1 = std::max(hot.i1, row_last);
      hot.j1 = j;
    }
  }
  books_.lost_j += lost;
  for (const std::int32_t k : switched_)
  {
    const int i = k % n, j = k / n;
    record_.set(window_.oi + i, window_.oj + j);
    window_.inv_kappa[k] = 1.0 / kappa_s_;
    window_.lambda[k] = lambda_s_;
  }
  for (const std::int32_t k : switched_)
    window_.updateFaces(k % n, k / n);
  window_.box = any ? hot : CellBox();
}

// ---------------------------------------------------------------------------------------------
// Books, accessors
// ---------------------------------------------------------------------------------------------
ThermalEnergy ThermalLayer::energy() const
{
  ThermalEnergy e = books_;
  e.stored_j = window_.storedEnergy();
  return e;
}

bool ThermalLayer::isMelted(const Eigen::Vector2d& p) const
{
  if (!p.allFinite())
    return false;
  return record_.get(static_cast<std::int64_t>(std::floor(p.x() / window_.cell_m)),
                     static_cast<std::int64_t>(std::floor(p.y() / window_.cell_m)));
}

double ThermalLayer::riseAt(const Eigen::Vector2d& p) const
{
  return window_.riseAt(p);
}

ThermalWindow ThermalLayer::window() const
{
  return window_.snapshot();
}

MeltedRaster ThermalLayer::meltedRaster() const
{
  return record_.raster(window_.cell_m);
}
}  // namespace scanhead
