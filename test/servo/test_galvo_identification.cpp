#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>

#include <yaml-cpp/yaml.h>

#include "scanhead/common/errors.hpp"
#include "scanhead/servo/identification/galvo_identification.hpp"
#include "scanhead/servo/identification/identification_report.hpp"

using namespace scanhead;

namespace
{
/// A plant with real i/U poles (large B, small L) besides the default Y galvo (complex pair).
GalvoPlantParams realPolePlant()
{
  GalvoPlantParams p;
  p.resistance_ohm = 3.0;
  p.inductance_h = 1.0e-4;
  p.torque_constant_nm_per_a = 0.01;
  p.inertia_kgm2 = 8.0e-8;
  p.viscous_nms = 1.0e-6;
  return p;
}

double relErr(double identified, double truth)
{
  return std::abs(identified / truth - 1.0);
}
}  // namespace

// THESIS eq. (2.13) inverts the forms exactly (round-off: 1e-9), for real and complex i/U poles;
// d = 1/G2 − R = Kc²/B as derived from the plant equations.
TEST(GalvoIdentification, RecoveryFormulasInvertTheForms)
{
  for (const GalvoPlantParams& p : {GalvoPlantParams(), realPolePlant()})
  {
    const TransferForms f = transferFormsOf(p);
    EXPECT_NEAR(f.g1_rad_per_as, p.torque_constant_nm_per_a / p.viscous_nms, 1e-9 * f.g1_rad_per_as);
    const PhysicalParams r = recoverPhysicalParams(f);
    EXPECT_LT(relErr(r.resistance_ohm, p.resistance_ohm), 1e-9);
    EXPECT_LT(relErr(r.inductance_h, p.inductance_h), 1e-9);
    EXPECT_LT(relErr(r.torque_constant_nm_per_a, p.torque_constant_nm_per_a), 1e-9);
    EXPECT_LT(relErr(r.viscous_nms, p.viscous_nms), 1e-9);
    EXPECT_LT(relErr(r.inertia_kgm2, p.inertia_kgm2), 1e-9);
    // The form with these parameters equals the plant's base-model i/U (no mode): 1e-12.
    GalvoPlantParams rigid = p;
    rigid.mode_gain = 0.0;
    for (double hz : {1.0, 100.0, 3000.0})
      EXPECT_LT(std::abs(currentPerVoltage(f, hz) / trueCurrentPerVoltage(rigid, hz) - 1.0), 1e-12);
  }
  // The default Y galvo has a complex i/U pole pair, the real-pole plant two real poles.
  EXPECT_GT(std::abs(transferFormsOf(GalvoPlantParams()).tau2().imag()), 0.0);
  EXPECT_EQ(transferFormsOf(realPolePlant()).tau2().imag(), 0.0);
}

// Acceptance (issue 4): R, L, Kc, B, Jeq within 5 % and the fitted Bode within 1 dB of the true
// plant up to 2 kHz, on the default Y galvo with its friction as configured (the ramp keeps the
// rotor speed one-signed: asserted). Measured with the default config: errors ≤ 0.2 % (Jeq), Bode
// ≤ 0.05 dB (the flexible mode at 5.5 kHz, not in the form, is most of it).
TEST(GalvoIdentification, RecoversDefaultGalvoWithinFivePercent)
{
  const GalvoPlantParams truth;
  const IdentificationConfig config;
  const IdentificationResult r = identifyGalvo(truth, config);
  EXPECT_EQ(r.velocity_sign_changes, 0u);
  EXPECT_EQ(r.saturated_samples, 0u);
  EXPECT_LT(relErr(r.identified.resistance_ohm, truth.resistance_ohm), 0.05);
  EXPECT_LT(relErr(r.identified.inductance_h, truth.inductance_h), 0.05);
  EXPECT_LT(relErr(r.identified.torque_constant_nm_per_a, truth.torque_constant_nm_per_a), 0.05);
  EXPECT_LT(relErr(r.identified.viscous_nms, truth.viscous_nms), 0.05);
  EXPECT_LT(relErr(r.identified.inertia_kgm2, truth.inertia_kgm2), 0.05);
  EXPECT_LT(r.theta_bode_max_error_db, 1.0);
  EXPECT_LT(r.current_bode_max_error_db, 1.0);
  // The angle stays in the ±10° range of a 3-axis head.
  EXPECT_LT(std::max(-r.angle_min_rad, r.angle_max_rad), 10.0 * 3.14159265358979 / 180.0);
  std::printf(
      "errors R %.2e L %.2e Kc %.2e B %.2e Jeq %.2e; Bode %.3f dB / %.3f dB; residuals %.2e %.2e\n",
      relErr(r.identified.resistance_ohm, truth.resistance_ohm), relErr(r.identified.inductance_h, truth.inductance_h),
      relErr(r.identified.torque_constant_nm_per_a, truth.torque_constant_nm_per_a),
      relErr(r.identified.viscous_nms, truth.viscous_nms), relErr(r.identified.inertia_kgm2, truth.inertia_kgm2),
      r.theta_bode_max_error_db, r.current_bode_max_error_db, r.theta_fit_rms_residual, r.current_fit_rms_residual);
}

// Real i/U poles, no friction, no mode, open loop would drift: the weak loop holds it. Same 5 %
// and 1 dB criteria (measured ≤ 0.3 %).
TEST(GalvoIdentification, RecoversRealPolePlant)
{
  GalvoPlantParams truth = realPolePlant();
  truth.mode_gain = 0.0;
  IdentificationConfig config;
  config.zero_friction = true;
  config.ramp_rad_per_s = 0.0;
  config.prbs.amplitude = 0.2;
  const IdentificationResult r = identifyGalvo(truth, config);
  EXPECT_LT(relErr(r.identified.resistance_ohm, truth.resistance_ohm), 0.05);
  EXPECT_LT(relErr(r.identified.inductance_h, truth.inductance_h), 0.05);
  EXPECT_LT(relErr(r.identified.torque_constant_nm_per_a, truth.torque_constant_nm_per_a), 0.05);
  EXPECT_LT(relErr(r.identified.viscous_nms, truth.viscous_nms), 0.05);
  EXPECT_LT(relErr(r.identified.inertia_kgm2, truth.inertia_kgm2), 0.05);
  EXPECT_LT(r.theta_bode_max_error_db, 1.0);
  EXPECT_LT(r.current_bode_max_error_db, 1.0);
}

// Without the ramp, PRBS excitation around rest makes the rotor speed change sign all the time:
// Coulomb friction then acts as a large extra damping and the identified B is far off (measured:
// several times the true B). This is why the default experiment runs on a ramp.
TEST(GalvoIdentification, CoulombFrictionWithoutRampBiasesB)
{
  const GalvoPlantParams truth;
  IdentificationConfig config;
  config.ramp_rad_per_s = 0.0;
  config.prbs.amplitude = 0.5;
  const IdentificationResult r = identifyGalvo(truth, config);
  EXPECT_GT(r.velocity_sign_changes, 100u);
  EXPECT_GT(r.identified.viscous_nms / truth.viscous_nms, 1.5);
  std::printf("no ramp: B identified / true = %.2f, Kc %.3f, Jeq %.3f, sign changes %zu\n",
              r.identified.viscous_nms / truth.viscous_nms,
              r.identified.torque_constant_nm_per_a / truth.torque_constant_nm_per_a,
              r.identified.inertia_kgm2 / truth.inertia_kgm2, r.velocity_sign_changes);
}

// The report is YAML with the true / identified values and errors; the CSV has a header and rows.
TEST(GalvoIdentification, ReportAndCsv)
{
  const GalvoPlantParams truth;
  IdentificationConfig config;
  config.prbs.order = 14;  // fast; accuracy not asserted here
  const std::string yaml = identificationReport(truth, config, "");
  const YAML::Node node = YAML::Load(yaml);
  for (const char* key : {"R_ohm", "L_h", "Kc_nm_per_a", "B_nms", "Jeq_kgm2"})
  {
    EXPECT_DOUBLE_EQ(node["true"][key].as<double>(), std::string(key) == "R_ohm" ? truth.resistance_ohm
                                                     : std::string(key) == "L_h" ? truth.inductance_h
                                                     : std::string(key) == "Kc_nm_per_a"
                                                         ? truth.torque_constant_nm_per_a
                                                     : std::string(key) == "B_nms" ? truth.viscous_nms
                                                                                   : truth.inertia_kgm2);
    EXPECT_TRUE(node["identified"][key].IsScalar()) << key;
    EXPECT_TRUE(node["relative_error"][key].IsScalar()) << key;
  }
  EXPECT_TRUE(node["fit"]["theta_current_rms_residual"].IsScalar());
  EXPECT_TRUE(node["bode_check"]["theta_current_max_error_db"].IsScalar());
  const IdentificationResult r = identifyGalvo(truth, config);
  const std::string csv = bodeCsv(r, truth);
  std::istringstream lines(csv);
  std::string header, row;
  std::getline(lines, header);
  EXPECT_EQ(header.rfind("frequency_hz,theta_meas_db", 0), 0u);
  int rows = 0;
  while (std::getline(lines, row))
  {
    ++rows;
    EXPECT_EQ(std::count(row.begin(), row.end(), ','), 14);
  }
  EXPECT_GT(rows, 100);
}

// With a folder, the report writes bode.csv and identification.yaml, then calls the plot hook once
// on that folder (the files complete by then).
TEST(GalvoIdentification, ReportWritesTheFolderThenCallsThePlotHook)
{
  const GalvoPlantParams truth;
  IdentificationConfig config;
  config.prbs.order = 14;
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "scanhead_test_identification";
  std::filesystem::remove_all(dir);
  int calls = 0;
  const std::string yaml = identificationReport(truth, config, dir.string(), [&](const std::string& folder) {
    ++calls;
    EXPECT_EQ(std::filesystem::path(folder), dir);
    EXPECT_GT(std::filesystem::file_size(dir / "bode.csv"), 0u);
    EXPECT_GT(std::filesystem::file_size(dir / "identification.yaml"), 0u);
  });
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(yaml, identificationReport(truth, config, ""));  // the folder changes nothing in the text
  std::filesystem::remove_all(dir);
}

TEST(GalvoIdentification, InvalidConfigNamesTheField)
{
  IdentificationConfig config;
  config.theta_fit_max_hz = 1e6;
  try
  {
    config.validate();
    FAIL();
  }
  catch (const ConfigError& e)
  {
    EXPECT_NE(std::string(e.what()).find("identification.theta_fit_max_hz must be"), std::string::npos) << e.what();
  }
  config = IdentificationConfig();
  config.prbs.order = 1;
  EXPECT_THROW(config.validate(), ConfigError);
  config = IdentificationConfig();
  config.averaged_periods = 0;
  EXPECT_THROW(config.validate(), ConfigError);
}
