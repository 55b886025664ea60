/// \file benchmark_stroke_deposit.hpp
/// \brief Cost of drawing one stroke on the energy map (StrokeDeposit::weigh + apply), for scanhead_benchmark.
///
/// A header (inline), not a .cpp: every src/tools/*.cpp is an executable. Not a test: wall-clock times
/// (steady_clock), run it on a quiet machine. Strokes of n samples at 1.5 m/s and Ts = 10 µs (the THESIS recipe 1
/// speed; on its layer 61 % of the strokes are single samples, the servo's ringing stopping the merge), nominal spot,
/// 5 µm pixels by default (the configuration's energy settings), at three angles to the map's rows.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "scanhead/energy/energy_config.hpp"
#include "scanhead/energy/segment_integral.hpp"
#include "scanhead/energy/spot_footprint.hpp"
#include "scanhead/energy/stroke_deposit.hpp"
#include "scanhead/energy/tiled_energy_map.hpp"

namespace scanhead
{
/// \brief Prints, per stroke length and angle: √A, pixels a stroke, ns a stroke and ns a pixel for weighing and for
/// adding to the map (best of \p repeat runs of 20 000 strokes along a raster of an 8 mm square, the map in memory).
inline void benchmarkStrokeDeposit(const EnergyConfig& config, int repeat)
{
  using Clock = std::chrono::steady_clock;
  const double speed_mps = 1.5, period_s = 1e-5;
  constexpr int kStrokes = 20000;
  std::printf("\nstroke deposit alone (energy.method exact, %.3g um pixels, %.3g m/s, best of %d x %d strokes)\n",
              config.pixel_m * 1e6, speed_mps, repeat, kStrokes);
  std::printf("%8s %6s %6s %10s %12s %10s %12s %10s\n", "samples", "angle", "sqrtA", "px/stroke", "weigh ns/st",
              "ns/px", "apply ns/st", "ns/px");
  TiledEnergyMap map(Eigen::Vector2d(-0.006, -0.006), Eigen::Vector2d(0.006, 0.006), config.pixel_m,
                     std::size_t{1} << 30);
  StrokeDeposit deposit(config);
  StrokeWeights weights;
  for (std::uint64_t samples : {1u, 2u, 5u, 9u, 40u})
    for (double angle_deg : {0.0, 30.0, 90.0})
    {
      Stroke stroke;
      stroke.samples = samples;
      stroke.power_w = 200.0;
      stroke.period_s = period_s;
      const double a = angle_deg * M_PI / 180.0;
      stroke.step = Eigen::Vector2d(std::cos(a), std::sin(a)) * speed_mps * period_s;
      stroke.footprint = spotFootprint(config, Eigen::Vector3d(0.0, 0.0, -1.0));
      double weigh_s = 1e300, apply_s = 1e300, pixels = 0.0, outside_j = 0.0;
      for (int r = 0; r < repeat; ++r)
      {
        double w_s = 0.0, a_s = 0.0, px = 0.0;
        for (int k = 0; k < kStrokes; ++k)
        {
          // Starts along a raster, as a scan path visits the map (20 µm apart, lines 100 µm apart), each at another
          // sub-pixel phase.
          const double phase = std::fmod(k * 0.6180339887, 1.0) * config.pixel_m;
          stroke.start = Eigen::Vector2d(-0.004 + (k % 400) * 20e-6 + phase, -0.004 + (k / 400) * 100e-6 + phase);
          const auto t0 = Clock::now();
          deposit.weigh(map, stroke, weights);
          const auto t1 = Clock::now();
          deposit.apply(map, weights, outside_j);
          const auto t2 = Clock::now();
          w_s += std::chrono::duration<double>(t1 - t0).count();
          a_s += std::chrono::duration<double>(t2 - t1).count();
          for (const StrokeWeights::Row& row : weights.rows)
            px += row.n;
        }
        weigh_s = std::min(weigh_s, w_s);
        apply_s = std::min(apply_s, a_s);
        pixels = px / kStrokes;
      }
      const SegmentIntegral si(stroke.footprint, stroke.displacement());
      std::printf("%8llu %6.0f %6.2f %10.0f %12.0f %10.2f %12.0f %10.2f\n", static_cast<unsigned long long>(samples),
                  angle_deg, si.sqrt_a, pixels, weigh_s * 1e9 / kStrokes, weigh_s * 1e9 / kStrokes / pixels,
                  apply_s * 1e9 / kStrokes, apply_s * 1e9 / kStrokes / pixels);
    }
}
}  // namespace scanhead
