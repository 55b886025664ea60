/// \file identification_report.hpp
/// \brief The identification's report: the YAML summary (true vs identified R, L, Kc, B, Jeq and
/// their relative errors, fit residuals, Bode check) and the Bode CSV, written into a folder for
/// the plots (SPEC §3; THESIS §2.2.1.2).
///
/// The relative error of an identified parameter p̂ against the true p is
/// \f[ e_p = \hat p / p - 1. \f]
#pragma once

#include <string>

#include "scanhead/common/plot_hook.hpp"
#include "scanhead/servo/identification/galvo_identification.hpp"

namespace scanhead
{
/// \brief identifyGalvo() as YAML: experiment, fitted forms and residuals, true / identified
/// R_ohm, L_h, Kc_nm_per_a, B_nms, Jeq_kgm2 and their relative errors, Bode check. If \p out_dir
/// is non-empty, writes out_dir/bode.csv and out_dir/identification.yaml, then calls \p plots on
/// out_dir (the tools pass the hook that runs scripts/plot_bode.py: bode_theta_current.png,
/// bode_current_voltage.png).
/// \param[in] plots  "data written, make the plots now"; empty: no plots
/// \throws InputError if out_dir cannot be written
std::string identificationReport(const GalvoPlantParams& truth, const IdentificationConfig& config,
                                 const std::string& out_dir, const PlotHook& plots = {});

/// \brief The Bode CSV: one row per kept bin (log-thinned to at most 200 rows per decade), columns
/// frequency_hz, then for θ/i and i/U the measured, fitted and true magnitude [dB] and phase [deg],
/// and the coherence; magnitudes as \f$20\log_{10}|G|\f$.
std::string bodeCsv(const IdentificationResult& result, const GalvoPlantParams& truth);
}  // namespace scanhead
