/// \file thermal_layer.cpp
/// \brief PATH eq. 5 on a window that follows the spot: LOD backward Euler, Thomas solves (SPEC §5).
#include "scanhead/thermal/thermal_layer.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>

#include "scanhead/common/errors.hpp"

namespace scanhead
{
namespace
{
constexpr double kFlushK = 1.0e-100;       // rises below this are set to 0 (no denormals far from the track)
constexpr double kMaxSubsteps = 1.0e6;     // a longer laser-on segment in one sample is garbage
constexpr double kMarchStepCells = 1.0;     // melt-pool marching step [cells]
constexpr int kRefineHalvings = 3;         // then the bracket is halved 3 times (1/8 cell) and interpolated
constexpr double kWidthStationsCells = 1.0;  // spacing of the cross-track marches [cells]

const ThermalConfig& validated(const ThermalConfig& config)
{
  config.validate();
  return config;
}

std::int64_t floorDiv64(std::int64_t a)
{
  return a >= 0 ? a / 64 : -((-a + 63) / 64);
}

std::int64_t tileKey(std::int64_t ti, std::int64_t tj)
{
  return static_cast<std::int64_t>((static_cast<std::uint64_t>(static_cast<std::uint32_t>(ti)) << 32) |
                                   static_cast<std::uint64_t>(static_cast<std::uint32_t>(tj)));
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
// Global record of melted cells
// ---------------------------------------------------------------------------------------------
bool ThermalLayer::Record::get(std::int64_t gi, std::int64_t gj) const
{
  const std::int64_t ti = floorDiv64(gi), tj = floorDiv64(gj);
  const auto it = tiles.find(tileKey(ti, tj));
  if (it == tiles.end())
    return false;
  return (it->second[static_cast<std::size_t>(gj - 64 * tj)] >> (gi - 64 * ti)) & 1u;
}

void ThermalLayer::Record::set(std::int64_t gi, std::int64_t gj)
{
  const std::int64_t ti = floorDiv64(gi), tj = floorDiv64(gj);
  auto it = tiles.find(tileKey(ti, tj));
  if (it == tiles.end())
  {
    Tile empty;
    empty.fill(0);
    it = tiles.emplace(tileKey(ti, tj), empty).first;
  }
  std::uint64_t& word = it->second[static_cast<std::size_t>(gj - 64 * tj)];
  const std::uint64_t bit = std::uint64_t(1) << (gi - 64 * ti);
  if (!(word & bit))
  {
    word |= bit;
    ++count;
  }
}

// ---------------------------------------------------------------------------------------------
// Construction, stream
// ---------------------------------------------------------------------------------------------
ThermalLayer::ThermalLayer(const ThermalConfig& config) : config_(validated(config))
{
  cell_ = config_.cell_m;
  n_ = static_cast<int>(std::ceil(config_.window_m / cell_ - 1e-9));
  w_ = 0.5 * config_.spot_diameter_m;
  h_area_ = config_.layer_thickness_m * cell_ * cell_;
  kappa_s_ = config_.kappaMelted();
  lambda_s_ = config_.conductivityMelted();
  keep_energy_ = config_.phase_switch == "keep_energy";
  face_ = config_.face_conductivity == "harmonic" ? &harmonicMean : &arithmeticMean;
  kappa_p_ = config_.kappaPowder();
  loss_ = config_.lossCoefficient();
  melt_rise_ = config_.meltRiseK();
  const std::size_t cells = static_cast<std::size_t>(n_) * n_;
  t_.assign(cells, 0.0);
  inv_kappa_.assign(cells, 0.0);
  lambda_.assign(cells, 0.0);
  fx_.assign(cells, 0.0);
  fy_.assign(cells, 0.0);
  solid_.assign(cells, 0);
  src_.assign(cells, 0.0);
  cp_.assign(cells, 0.0);
  const int stencil = 2 * static_cast<int>(std::ceil(config_.source_truncation_radii * w_ / cell_)) + 3;
  gx_.assign(stencil, 0.0);
  gy_.assign(stencil, 0.0);
  reset();
}

void ThermalLayer::reset()
{
  std::fill(t_.begin(), t_.end(), 0.0);
  std::fill(src_.begin(), src_.end(), 0.0);
  std::fill(solid_.begin(), solid_.end(), 0);
  std::fill(inv_kappa_.begin(), inv_kappa_.end(), 1.0 / kappa_p_);
  std::fill(lambda_.begin(), lambda_.end(), config_.conductivity_powder_w_m_k);
  std::fill(fx_.begin(), fx_.end(), config_.conductivity_powder_w_m_k);
  std::fill(fy_.begin(), fy_.end(), config_.conductivity_powder_w_m_k);
  switched_.clear();
  placed_ = false;
  oi_ = oj_ = 0;
  box_ = Box();
  record_ = Record();
  started_ = false;
  next_index_ = 0;
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
  stats_ = MeltPoolStats();
  sum_len_ = sum_len2_ = sum_wid_ = sum_wid2_ = sum_pk_ = sum_pk2_ = 0.0;
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
  if (started_ && chunk.period_s != period_s_)
  {
    std::ostringstream msg;
    msg << "thermal: chunk period_s changed from " << period_s_ << " to " << chunk.period_s << " s at sample "
        << chunk.first_index;
    throw InputError(msg.str());
  }
  for (std::size_t k = 0; k < chunk.samples.size(); ++k)
  {
    const std::uint64_t index = chunk.first_index + k;
    if (started_ && index < next_index_)
      continue;  // overlap or late chunk: already simulated
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
      msg << "thermal: sample " << index << " has a non-finite spot position (" << s.actual.x() << ", "
          << s.actual.y() << ") m while the laser is on (" << s.power_w << " W)";
      throw NumericalError(msg.str());
    }
    period_s_ = chunk.period_s;
    if (started_)
    {
      for (std::uint64_t g = next_index_; g < index; ++g)  // gap: laser off where the spot last was
      {
        SpotSample off;
        off.actual = off.setpoint = last_pos_;
        off.power_w = 0.0;
        pushSample(off, g);
      }
    }
    started_ = true;
    pushSample(s, index);
    if (s.actual.allFinite())
      last_pos_ = s.actual;
    next_index_ = index + 1;
  }
}

void ThermalLayer::pushSample(const SpotSample& s, std::uint64_t index)
{
  pending_.push_back(Pending{ s, index });
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
  step.steady = all_on &&
                static_cast<double>(step.first_index - burst_start_index_) * ts >= config_.settle_time_s;

  // Window placement.
  if (step.laser_on)
  {
    const Eigen::Vector2d centre = 0.5 * (lo + hi);
    if (!placed_)
      placeWindow(centre);
    else
    {
      const double m = config_.recentre_margin_m / cell_;
      const double ulo = lo.x() / cell_ - oi_, uhi = hi.x() / cell_ - oi_;
      const double vlo = lo.y() / cell_ - oj_, vhi = hi.y() / cell_ - oj_;
      if (ulo < m || vlo < m || uhi > n_ - m || vhi > n_ - m)
        placeWindow(centre);
    }
  }

  // Source.
  Box src_box;
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
  const double a_max = std::max(lambda_s_, config_.conductivity_powder_w_m_k) /
                       std::min(kappa_s_, kappa_p_);
  const int grow = 2 + static_cast<int>(std::ceil(3.0 * std::sqrt(a_max * dt) / cell_));
  Box b = box_;
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
    b.i1 = std::min(n_ - 1, b.i1 + grow);
    b.j1 = std::min(n_ - 1, b.j1 + grow);
  }
  box_ = b;

  int peak_i = -1, peak_j = -1;
  if (!box_.empty())
  {
    // Loss exactly, half before and half after the source and the diffusion (Strang): for one
    // material it commutes with the diffusion, so a dwell's energy is second-order accurate in dt.
    decay_s_ = std::exp(-0.5 * dt * loss_ / kappa_s_);
    decay_p_ = std::exp(-0.5 * dt * loss_ / kappa_p_);
    lost_s_ = -std::expm1(-0.5 * dt * loss_ / kappa_s_) * kappa_s_ * h_area_;  // (1 − f)·κ·h·cell² [J/K]
    lost_p_ = -std::expm1(-0.5 * dt * loss_ / kappa_p_) * kappa_p_ * h_area_;
    double lost = 0.0;
    if (step_count_ % 2 == 0)
    {
      sweepX(box_, true, dt, lost);
      sweepY(box_, false, dt, lost);
    }
    else
    {
      sweepY(box_, true, dt, lost);
      sweepX(box_, false, dt, lost);
    }
    books_.lost_j += lost;
    if (!src_box.empty())
    {
      for (int j = src_box.j0; j <= src_box.j1; ++j)
        std::fill(src_.begin() + static_cast<std::size_t>(j) * n_ + src_box.i0,
                  src_.begin() + static_cast<std::size_t>(j) * n_ + src_box.i1 + 1, 0.0);
    }
    postStep(peak_i, peak_j);
    // Box for the next step: cells above the threshold, grown.
    if (!box_.empty())
    {
      box_.i0 = std::max(0, box_.i0 - grow);
      box_.j0 = std::max(0, box_.j0 - grow);
      box_.i1 = std::min(n_ - 1, box_.i1 + grow);
      box_.j1 = std::min(n_ - 1, box_.j1 + grow);
    }
    // Cells of the solved box outside the new one are below the threshold: drop them.
    auto drop = [&](int j, int i_from, int i_to) {
      double* row = &t_[static_cast<std::size_t>(j) * n_];
      const std::uint8_t* sol = &solid_[static_cast<std::size_t>(j) * n_];
      for (int i = i_from; i <= i_to; ++i)
      {
        if (row[i] != 0.0)
        {
          books_.truncated_j += (sol[i] ? kappa_s_ : kappa_p_) * row[i] * h_area_;
          row[i] = 0.0;
        }
      }
    };
    for (int j = b.j0; j <= b.j1; ++j)
    {
      if (box_.empty() || j < box_.j0 || j > box_.j1)
        drop(j, b.i0, b.i1);
      else
      {
        drop(j, b.i0, box_.i0 - 1);
        drop(j, box_.i1 + 1, b.i1);
      }
    }
  }
  ++step_count_;

  if (peak_i >= 0)
  {
    step.peak_k = t_[static_cast<std::size_t>(peak_j) * n_ + peak_i];
    if (step.peak_k > melt_rise_)
      measurePool(peak_i, peak_j, step);
  }
  addStats(step);
  last_ = step;
  recent_.push_back(step);
}

void ThermalLayer::placeWindow(const Eigen::Vector2d& centre)
{
  const std::int64_t new_oi = static_cast<std::int64_t>(std::floor(centre.x() / cell_)) - n_ / 2;
  const std::int64_t new_oj = static_cast<std::int64_t>(std::floor(centre.y() / cell_)) - n_ / 2;
  if (placed_ && new_oi == oi_ && new_oj == oj_)
    return;
  if (placed_ && !box_.empty())
  {
    // Move the hot box (T = 0 elsewhere); what falls off carries its energy away.
    const std::int64_t di = new_oi - oi_, dj = new_oj - oj_;
    std::vector<double>& tmp = cp_;  // scratch
    Box nb;
    nb.i0 = static_cast<int>(std::max<std::int64_t>(0, box_.i0 - di));
    nb.i1 = static_cast<int>(std::min<std::int64_t>(n_ - 1, box_.i1 - di));
    nb.j0 = static_cast<int>(std::max<std::int64_t>(0, box_.j0 - dj));
    nb.j1 = static_cast<int>(std::min<std::int64_t>(n_ - 1, box_.j1 - dj));
    if (nb.empty())
      nb = Box();
    for (int j = nb.j0; j <= nb.j1; ++j)
      std::fill(tmp.begin() + static_cast<std::size_t>(j) * n_ + nb.i0,
                tmp.begin() + static_cast<std::size_t>(j) * n_ + nb.i1 + 1, 0.0);
    for (int j = box_.j0; j <= box_.j1; ++j)
    {
      for (int i = box_.i0; i <= box_.i1; ++i)
      {
        const std::size_t k = static_cast<std::size_t>(j) * n_ + i;
        const double t = t_[k];
        if (t == 0.0)
          continue;
        t_[k] = 0.0;
        const std::int64_t ni = i - di, nj = j - dj;
        if (ni < 0 || nj < 0 || ni >= n_ || nj >= n_)
          books_.left_window_j += (solid_[k] ? kappa_s_ : kappa_p_) * t * h_area_;
        else
          tmp[static_cast<std::size_t>(nj) * n_ + static_cast<std::size_t>(ni)] = t;
      }
    }
    for (int j = nb.j0; j <= nb.j1; ++j)
    {
      for (int i = nb.i0; i <= nb.i1; ++i)
      {
        const std::size_t k = static_cast<std::size_t>(j) * n_ + i;
        t_[k] = tmp[k];
      }
    }
    box_ = nb;  // empty when nothing is left
  }
  else
  {
    box_ = Box();
  }
  oi_ = new_oi;
  oj_ = new_oj;
  placed_ = true;
  // States from the global record (it holds every cell that ever switched).
  for (int j = 0; j < n_; ++j)
  {
    const std::int64_t gj = oj_ + j;
    const std::int64_t tj = floorDiv64(gj);
    for (int i = 0; i < n_;)
    {
      const std::int64_t gi = oi_ + i;
      const std::int64_t ti = floorDiv64(gi);
      const int run = static_cast<int>(std::min<std::int64_t>(n_ - i, 64 * (ti + 1) - gi));
      const auto it = record_.tiles.find(tileKey(ti, tj));
      std::uint8_t* out = &solid_[static_cast<std::size_t>(j) * n_ + i];
      if (it == record_.tiles.end())
        std::fill(out, out + run, std::uint8_t(0));
      else
      {
        const std::uint64_t word = it->second[static_cast<std::size_t>(gj - 64 * tj)];
        const int b0 = static_cast<int>(gi - 64 * ti);
        for (int r = 0; r < run; ++r)
          out[r] = static_cast<std::uint8_t>((word >> (b0 + r)) & 1u);
      }
      i += run;
    }
  }
  for (std::size_t k = 0; k < solid_.size(); ++k)
  {
    inv_kappa_[k] = 1.0 / (solid_[k] ? kappa_s_ : kappa_p_);
    lambda_[k] = solid_[k] ? lambda_s_ : config_.conductivity_powder_w_m_k;
  }
  for (int j = 0; j < n_; ++j)
  {
    for (int i = 0; i < n_; ++i)
    {
      const std::size_t k = static_cast<std::size_t>(j) * n_ + i;
      if (i + 1 < n_)
        fx_[k] = face_(lambda_[k], lambda_[k + 1]);
      if (j + 1 < n_)
        fy_[k] = face_(lambda_[k], lambda_[k + n_]);
    }
  }
}

void ThermalLayer::depositPoint(double x, double y, double energy_j, Box& src_box)
{
  const double u = x / cell_ - static_cast<double>(oi_);
  const double v = y / cell_ - static_cast<double>(oj_);
  const double r = config_.source_truncation_radii * w_ / cell_;
  if (!(u + r >= 0.0 && v + r >= 0.0 && u - r < n_ && v - r < n_))
  {
    books_.outside_j += energy_j;
    return;
  }
  const int ilo = static_cast<int>(std::floor(u - r)), ihi = static_cast<int>(std::floor(u + r));
  const int jlo = static_cast<int>(std::floor(v - r)), jhi = static_cast<int>(std::floor(v + r));
  const double k2 = 2.0 * cell_ * cell_ / (w_ * w_);
  double sx = 0.0, sxin = 0.0, sy = 0.0, syin = 0.0;
  for (int i = ilo; i <= ihi; ++i)
  {
    const double d = i + 0.5 - u;
    const double g = std::exp(-k2 * d * d);
    gx_[i - ilo] = g;
    sx += g;
    if (i >= 0 && i < n_)
      sxin += g;
  }
  for (int j = jlo; j <= jhi; ++j)
  {
    const double d = j + 0.5 - v;
    const double g = std::exp(-k2 * d * d);
    gy_[j - jlo] = g;
    sy += g;
    if (j >= 0 && j < n_)
      syin += g;
  }
  const double scale = energy_j / (sx * sy);
  books_.outside_j += energy_j - scale * sxin * syin;
  const int i0 = std::max(ilo, 0), i1 = std::min(ihi, n_ - 1);
  const int j0 = std::max(jlo, 0), j1 = std::min(jhi, n_ - 1);
  if (i1 < i0 || j1 < j0)
    return;
  for (int j = j0; j <= j1; ++j)
  {
    double* row = &src_[static_cast<std::size_t>(j) * n_];
    const double gj = scale * gy_[j - jlo];
    for (int i = i0; i <= i1; ++i)
      row[i] += gj * gx_[i - ilo];
  }
  if (src_box.empty())
    src_box = Box{ i0, i1, j0, j1 };
  else
  {
    src_box.i0 = std::min(src_box.i0, i0);
    src_box.i1 = std::max(src_box.i1, i1);
    src_box.j0 = std::min(src_box.j0, j0);
    src_box.j1 = std::max(src_box.j1, j1);
  }
}

// (1 + r_i(W + E) + ½dt·c/κ_i) T'_i − r_i W T'_{i−1} − r_i E T'_{i+1} = T_i [+ E_src,i/(κ_i h cell²)],
// r_i = dt/(κ_i cell²), W/E the face conductivities (0 at the box edge).
// Stage "first": T ← f·T (half the loss, f = exp(−½dt·λ_s/(δ²κ))), + the step's source; then per line
// (1 + r_i(W + E)) T'_i − r_i W T'_{i−1} − r_i E T'_{i+1} = T_i,  r_i = dt/(κ_i cell²),
// W/E the face conductivities (0 at the box edge).
void ThermalLayer::sweepX(const Box& b, bool first, double dt, double& lost_j)
{
  const double r0 = dt / (cell_ * cell_);
  const double sk = 1.0 / h_area_;
  const double fs = decay_s_, fp = decay_p_;
  const double ls = lost_s_, lp = lost_p_;
  constexpr int kRows = 8;  // rows eliminated together: independent chains overlap in the pipeline
  double lost = 0.0;
  for (int jb = b.j0; jb <= b.j1; jb += kRows)
  {
    const int nr = std::min(kRows, b.j1 - jb + 1);
    double prev_c[kRows] = {}, prev_d[kRows] = {};
    for (int i = b.i0; i <= b.i1; ++i)
    {
      const bool has_w = i > b.i0, has_e = i < b.i1;
      for (int r = 0; r < nr; ++r)
      {
        const std::size_t k = static_cast<std::size_t>(jb + r) * n_ + i;
        const double west = has_w ? fx_[k - 1] : 0.0;
        const double east = has_e ? fx_[k] : 0.0;
        const double ik = inv_kappa_[k];
        const double rr = r0 * ik;
        const double a = -rr * west, c = -rr * east;
        const double diag = 1.0 + rr * (west + east);
        double rhs = t_[k];
        if (first)
        {
          const bool sol = solid_[k] != 0;
          lost += (sol ? ls : lp) * rhs;
          rhs = rhs * (sol ? fs : fp) + src_[k] * ik * sk;
        }
        const double m = 1.0 / (diag - a * prev_c[r]);
        prev_c[r] = c * m;
        prev_d[r] = (rhs - a * prev_d[r]) * m;
        cp_[k] = prev_c[r];
        t_[k] = prev_d[r];
      }
    }
    double x[kRows];
    for (int r = 0; r < nr; ++r)
      x[r] = t_[static_cast<std::size_t>(jb + r) * n_ + b.i1];
    for (int i = b.i1 - 1; i >= b.i0; --i)
    {
      for (int r = 0; r < nr; ++r)
      {
        const std::size_t k = static_cast<std::size_t>(jb + r) * n_ + i;
        x[r] = t_[k] - cp_[k] * x[r];
        t_[k] = x[r];
      }
    }
  }
  lost_j += lost;
}

void ThermalLayer::sweepY(const Box& b, bool first, double dt, double& lost_j)
{
  const double r0 = dt / (cell_ * cell_);
  const double sk = 1.0 / h_area_;
  const double fs = decay_s_, fp = decay_p_;
  const double ls = lost_s_, lp = lost_p_;
  const int i0 = b.i0, i1 = b.i1;
  double lost = 0.0;
  for (int j = b.j0; j <= b.j1; ++j)
  {
    const std::size_t row = static_cast<std::size_t>(j) * n_;
    double* t = &t_[row];
    double* cp = &cp_[row];
    const double* ik = &inv_kappa_[row];
    const double* s = &src_[row];
    const std::uint8_t* sol = &solid_[row];
    const double* fn = &fy_[row];
    const bool has_s = j > b.j0, has_n = j < b.j1;
    const double* fsouth = has_s ? &fy_[row - n_] : nullptr;
    const double* tp = has_s ? &t_[row - n_] : nullptr;
    const double* cpp = has_s ? &cp_[row - n_] : nullptr;
    for (int i = i0; i <= i1; ++i)
    {
      const double south = has_s ? fsouth[i] : 0.0;
      const double north = has_n ? fn[i] : 0.0;
      const double r = r0 * ik[i];
      const double a = -r * south, c = -r * north;
      const double diag = 1.0 + r * (south + north);
      double rhs = t[i];
      if (first)
      {
        lost += (sol[i] ? ls : lp) * rhs;
        rhs = rhs * (sol[i] ? fs : fp) + s[i] * ik[i] * sk;
      }
      const double m = has_s ? 1.0 / (diag - a * cpp[i]) : 1.0 / diag;
      cp[i] = c * m;
      t[i] = has_s ? (rhs - a * tp[i]) * m : rhs * m;
    }
  }
  for (int j = b.j1 - 1; j >= b.j0; --j)
  {
    const std::size_t row = static_cast<std::size_t>(j) * n_;
    double* t = &t_[row];
    const double* cp = &cp_[row];
    const double* tn = &t_[row + n_];
    for (int i = i0; i <= i1; ++i)
      t[i] -= cp[i] * tn[i];
  }
  lost_j += lost;
}

// Second half of the loss, peak, powder → solid switches, flush, and the box of cells above the
// threshold (box_ on return).
void ThermalLayer::postStep(int& peak_i, int& peak_j)
{
  const Box b = box_;
  const double fs = decay_s_, fp = decay_p_;
  const double ls = lost_s_, lp = lost_p_;
  double lost = 0.0;
  Box hot;
  bool any = false;
  double peak = -INFINITY;
  const double eps = config_.active_threshold_k;
  switched_.clear();
  for (int j = b.j0; j <= b.j1; ++j)
  {
    const std::size_t row = static_cast<std::size_t>(j) * n_;
    double* t = &t_[row];
    std::uint8_t* sol = &solid_[row];
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
          books_.phase_switch_j += (kappa_s_ - kappa_p_) * v * h_area_;
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
        books_.truncated_j += (sol[i] ? kappa_s_ : kappa_p_) * v * h_area_;
        t[i] = 0.0;
      }
    }
    if (row_first >= 0)
    {
      if (!any)
      {
        hot = Box{ row_first, row_last, j, j };
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
    const int i = k % n_, j = k / n_;
    record_.set(oi_ + i, oj_ + j);
    inv_kappa_[k] = 1.0 / kappa_s_;
    lambda_[k] = lambda_s_;
  }
  for (const std::int32_t k : switched_)
    updateFaces(k % n_, k / n_);
  box_ = any ? hot : Box();
}

void ThermalLayer::updateFaces(int i, int j)
{
  const std::size_t k = static_cast<std::size_t>(j) * n_ + i;
  if (i + 1 < n_)
    fx_[k] = face_(lambda_[k], lambda_[k + 1]);
  if (i > 0)
    fx_[k - 1] = face_(lambda_[k - 1], lambda_[k]);
  if (j + 1 < n_)
    fy_[k] = face_(lambda_[k], lambda_[k + n_]);
  if (j > 0)
    fy_[k - n_] = face_(lambda_[k - n_], lambda_[k]);
}

// ---------------------------------------------------------------------------------------------
// Melt pool, statistics, accessors
// ---------------------------------------------------------------------------------------------
double ThermalLayer::sampleLocal(double u, double v) const
{
  double x = u - 0.5, y = v - 0.5;
  x = std::min(std::max(x, 0.0), static_cast<double>(n_ - 1));
  y = std::min(std::max(y, 0.0), static_cast<double>(n_ - 1));
  int i = static_cast<int>(x), j = static_cast<int>(y);
  if (i > n_ - 2)
    i = n_ - 2;
  if (j > n_ - 2)
    j = n_ - 2;
  const double fx = x - i, fy = y - j;
  const double* r0 = &t_[static_cast<std::size_t>(j) * n_ + i];
  const double* r1 = r0 + n_;
  return (1.0 - fy) * ((1.0 - fx) * r0[0] + fx * r0[1]) + fy * ((1.0 - fx) * r1[0] + fx * r1[1]);
}

void ThermalLayer::measurePool(int peak_i, int peak_j, ThermalStep& step) const
{
  const double u0 = peak_i + 0.5, v0 = peak_j + 0.5;
  const double lim_lo = 0.5, lim_hi = n_ - 0.5;
  bool edge = false;
  // Distance [cells] from (u, v) along (du, dv) to where T drops to melting.
  auto march = [&](double u, double v, double du, double dv) {
    double prev = sampleLocal(u, v);
    double s = 0.0;
    for (;;)
    {
      const double sn = s + kMarchStepCells;
      const double pu = u + sn * du, pv = v + sn * dv;
      if (pu < lim_lo || pv < lim_lo || pu > lim_hi || pv > lim_hi)
      {
        edge = true;
        return s;
      }
      double val = sampleLocal(pu, pv);
      if (val <= melt_rise_)
      {
        // Bracket [s, sn]: halve it kRefineHalvings times, then interpolate linearly.
        double hi_s = sn;
        for (int k = 0; k < kRefineHalvings; ++k)
        {
          const double mid = 0.5 * (s + hi_s);
          const double vm = sampleLocal(u + mid * du, v + mid * dv);
          if (vm > melt_rise_)
          {
            s = mid;
            prev = vm;
          }
          else
          {
            hi_s = mid;
            val = vm;
          }
        }
        return s + (hi_s - s) * (prev - melt_rise_) / (prev - val);
      }
      prev = val;
      s = sn;
    }
  };
  const double du = dir_.x(), dv = dir_.y();
  const double front = march(u0, v0, du, dv);
  const double rear = march(u0, v0, -du, -dv);
  double width = 0.0;
  for (double s = -rear; s <= front; s += kWidthStationsCells)
  {
    const double pu = u0 + s * du, pv = v0 + s * dv;
    if (sampleLocal(pu, pv) <= melt_rise_)
      continue;
    width = std::max(width, march(pu, pv, -dv, du) + march(pu, pv, dv, -du));
  }
  step.length_m = (front + rear) * cell_;
  step.width_m = width * cell_;
  step.pool_at_window_edge = edge;
}

void ThermalLayer::addStats(const ThermalStep& step)
{
  MeltPoolStats& s = stats_;
  ++s.steps;
  if (step.laser_on)
    ++s.laser_on_steps;
  if (step.peak_k > melt_rise_)
    ++s.melting_steps;
  s.max_length_m = std::max(s.max_length_m, step.length_m);
  s.max_width_m = std::max(s.max_width_m, step.width_m);
  s.max_peak_k = std::max(s.max_peak_k, step.peak_k);
  if (!step.steady)
    return;
  ++s.steady_steps;
  sum_len_ += step.length_m;
  sum_len2_ += step.length_m * step.length_m;
  sum_wid_ += step.width_m;
  sum_wid2_ += step.width_m * step.width_m;
  sum_pk_ += step.peak_k;
  sum_pk2_ += step.peak_k * step.peak_k;
  const double n = static_cast<double>(s.steady_steps);
  auto spread = [n](double sum, double sum2) { return std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n))); };
  s.steady_length_mean_m = sum_len_ / n;
  s.steady_width_mean_m = sum_wid_ / n;
  s.steady_peak_mean_k = sum_pk_ / n;
  s.steady_length_std_m = spread(sum_len_, sum_len2_);
  s.steady_width_std_m = spread(sum_wid_, sum_wid2_);
  s.steady_peak_std_k = spread(sum_pk_, sum_pk2_);
}

ThermalEnergy ThermalLayer::energy() const
{
  ThermalEnergy e = books_;
  double stored = 0.0;
  if (!box_.empty())
  {
    for (int j = box_.j0; j <= box_.j1; ++j)
    {
      const std::size_t row = static_cast<std::size_t>(j) * n_;
      for (int i = box_.i0; i <= box_.i1; ++i)
        stored += (solid_[row + i] ? kappa_s_ : kappa_p_) * t_[row + i];
    }
  }
  e.stored_j = stored * h_area_;
  return e;
}

bool ThermalLayer::isMelted(const Eigen::Vector2d& p) const
{
  if (!p.allFinite())
    return false;
  return record_.get(static_cast<std::int64_t>(std::floor(p.x() / cell_)),
                     static_cast<std::int64_t>(std::floor(p.y() / cell_)));
}

double ThermalLayer::riseAt(const Eigen::Vector2d& p) const
{
  if (!placed_ || !p.allFinite())
    return 0.0;
  const double u = p.x() / cell_ - static_cast<double>(oi_), v = p.y() / cell_ - static_cast<double>(oj_);
  if (u < 0.0 || v < 0.0 || u > n_ || v > n_)
    return 0.0;
  return sampleLocal(u, v);
}

ThermalWindow ThermalLayer::window() const
{
  ThermalWindow w;
  w.cell_m = cell_;
  w.origin_i = oi_;
  w.origin_j = oj_;
  w.width = w.height = n_;
  w.rise_k = t_;
  w.solid = solid_;
  return w;
}

MeltedRaster ThermalLayer::meltedRaster() const
{
  MeltedRaster r;
  r.cell_m = cell_;
  r.count = record_.count;
  if (record_.count == 0)
    return r;
  std::int64_t gi0 = INT64_MAX, gi1 = INT64_MIN, gj0 = INT64_MAX, gj1 = INT64_MIN;
  std::vector<std::int64_t> keys;
  for (const auto& kv : record_.tiles)
  {
    const std::int64_t ti = static_cast<std::int32_t>(static_cast<std::uint64_t>(kv.first) >> 32);
    const std::int64_t tj = static_cast<std::int32_t>(static_cast<std::uint64_t>(kv.first) & 0xffffffffu);
    for (int b = 0; b < 64; ++b)
    {
      const std::uint64_t word = kv.second[static_cast<std::size_t>(b)];
      if (!word)
        continue;
      for (int a = 0; a < 64; ++a)
      {
        if ((word >> a) & 1u)
        {
          gi0 = std::min(gi0, 64 * ti + a);
          gi1 = std::max(gi1, 64 * ti + a);
          gj0 = std::min(gj0, 64 * tj + b);
          gj1 = std::max(gj1, 64 * tj + b);
        }
      }
    }
  }
  r.origin_i = gi0;
  r.origin_j = gj0;
  r.width = static_cast<int>(gi1 - gi0 + 1);
  r.height = static_cast<int>(gj1 - gj0 + 1);
  r.melted.assign(static_cast<std::size_t>(r.width) * r.height, 0);
  for (const auto& kv : record_.tiles)
  {
    const std::int64_t ti = static_cast<std::int32_t>(static_cast<std::uint64_t>(kv.first) >> 32);
    const std::int64_t tj = static_cast<std::int32_t>(static_cast<std::uint64_t>(kv.first) & 0xffffffffu);
    for (int b = 0; b < 64; ++b)
    {
      const std::uint64_t word = kv.second[static_cast<std::size_t>(b)];
      for (int a = 0; a < 64; ++a)
      {
        if ((word >> a) & 1u)
        {
          const std::int64_t x = 64 * ti + a - gi0, y = 64 * tj + b - gj0;
          r.melted[static_cast<std::size_t>(y) * r.width + static_cast<std::size_t>(x)] = 1;
        }
      }
    }
  }
  return r;
}

// ---------------------------------------------------------------------------------------------
// Steady moving-spot reference (constant solid properties)
// ---------------------------------------------------------------------------------------------
namespace
{
double simpson(const std::function<double(double)>& f, double a, double b, double fa, double fm, double fb,
               double whole, double tol, int depth)
{
  const double m = 0.5 * (a + b);
  const double lm = 0.5 * (a + m), rm = 0.5 * (m + b);
  const double flm = f(lm), frm = f(rm);
  const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
  const double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
  const double delta = left + right - whole;
  if (depth <= 0 || std::abs(delta) <= 15.0 * tol)
    return left + right + delta / 15.0;
  return simpson(f, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1) +
         simpson(f, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1);
}

double integrate(const std::function<double(double)>& f, double a, double b, double tol)
{
  const double fa = f(a), fb = f(b), fm = f(0.5 * (a + b));
  const double whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
  return simpson(f, a, b, fa, fm, fb, whole, tol, 48);
}
}  // namespace

double steadyMovingSpotRise(const ThermalConfig& config, double power_w, double speed_m_s, double xi_m, double eta_m)
{
  const double kappa = config.kappaMelted();
  const double a = config.conductivityMelted() / kappa;
  const double tau = kappa / config.lossCoefficient();
  const double w = 0.5 * config.spot_diameter_m;
  const double s0 = 0.25 * w * w;
  const double pref = config.absorptivity * power_w / (config.layer_thickness_m * kappa);
  if (pref == 0.0)
    return 0.0;
  const double v = speed_m_s;
  auto f = [&](double t) {
    const double s2 = s0 + 2.0 * a * t;
    const double dx = xi_m + v * t;
    return std::exp(-t / tau - (dx * dx + eta_m * eta_m) / (2.0 * s2)) / (2.0 * M_PI * s2);
  };
  // Breakpoints: geometric from the spot's diffusion time, and around the passage time −ξ/v.
  std::vector<double> br{ 0.0 };
  const double t_end = 60.0 * tau;
  for (double t = s0 / (2.0 * a) / 64.0; t < t_end; t *= 2.0)
    br.push_back(t);
  br.push_back(t_end);
  if (v > 0.0 && xi_m < 0.0)
  {
    const double tc = -xi_m / v;
    const double sig = std::sqrt(s0 + 2.0 * a * tc) / v;
    for (double k : { -6.0, -2.0, 0.0, 2.0, 6.0 })
    {
      const double t = tc + k * sig;
      if (t > 0.0 && t < t_end)
        br.push_back(t);
    }
  }
  std::sort(br.begin(), br.end());
  const double tol = 1e-7 * config.meltRiseK() / pref / static_cast<double>(br.size());
  double sum = 0.0;
  for (std::size_t k = 0; k + 1 < br.size(); ++k)
  {
    if (br[k + 1] > br[k])
      sum += integrate(f, br[k], br[k + 1], tol);
  }
  return pref * sum;
}

SteadyMeltPool steadyMeltPool(const ThermalConfig& config, double power_w, double speed_m_s)
{
  SteadyMeltPool out;
  const double tm = config.meltRiseK();
  const double w = 0.5 * config.spot_diameter_m;
  auto axis = [&](double xi) { return steadyMovingSpotRise(config, power_w, speed_m_s, xi, 0.0); };
  // Peak on the axis: scan, then golden section.
  double best_xi = 0.0, best = -1.0;
  for (double xi = -8.0 * w; xi <= 2.0 * w; xi += w / 16.0)
  {
    const double t = axis(xi);
    if (t > best)
    {
      best = t;
      best_xi = xi;
    }
  }
  {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double lo = best_xi - w / 16.0, hi = best_xi + w / 16.0;
    for (int it = 0; it < 40; ++it)
    {
      const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
      if (axis(x1) > axis(x2))
        hi = x2;
      else
        lo = x1;
    }
    best_xi = 0.5 * (lo + hi);
    best = axis(best_xi);
  }
  out.peak_k = best;
  out.peak_xi_m = best_xi;
  if (best <= tm)
    return out;
  // Crossing of tm along a ray from a point above it.
  auto cross = [&](const std::function<double(double)>& g) {
    double lo = 0.0, step = w;
    while (g(lo + step) > tm)
    {
      lo += step;
      step *= 2.0;
    }
    double hi = lo + step;
    while (hi - lo > 1e-9)
    {
      const double mid = 0.5 * (lo + hi);
      (g(mid) > tm ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  };
  out.front_m = best_xi + cross([&](double s) { return axis(best_xi + s); });
  out.rear_m = best_xi - cross([&](double s) { return axis(best_xi - s); });
  out.length_m = out.front_m - out.rear_m;
  auto half_width = [&](double xi) {
    if (axis(xi) <= tm)
      return 0.0;
    return cross([&](double eta) { return steadyMovingSpotRise(config, power_w, speed_m_s, xi, eta); });
  };
  const int n = 48;
  double best_w = 0.0, best_w_xi = best_xi;
  const double dxi = out.length_m / n;
  for (int k = 1; k < n; ++k)
  {
    const double xi = out.rear_m + k * dxi;
    const double hw = half_width(xi);
    if (hw > best_w)
    {
      best_w = hw;
      best_w_xi = xi;
    }
  }
  {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double lo = best_w_xi - dxi, hi = best_w_xi + dxi;
    for (int it = 0; it < 30; ++it)
    {
      const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
      if (half_width(x1) > half_width(x2))
        hi = x2;
      else
        lo = x1;
    }
    best_w = std::max(best_w, half_width(0.5 * (lo + hi)));
  }
  out.width_m = 2.0 * best_w;
  return out;
}
}  // namespace scanhead
