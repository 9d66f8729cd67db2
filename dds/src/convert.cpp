#include "bbw/dds/convert.hpp"

#include <cmath>

namespace bbw::dds {

void to_msg(const scenario::CornerSample& in, bool force_comp_used, msg::MeasurementSample& out) {
  out.seq(in.seq);
  out.time_s(in.time_s);
  out.position_rev(in.position_rev);
  out.speed_rev_per_s(in.speed_rev_per_s);
  out.force_internal_kN(in.force_internal_kN);
  out.force_external_kN(in.force_external_kN);
  out.force_true_kN(in.force_true_kN);
  out.temperature_C(in.temperature_C);
  out.motor_current_A(in.motor_current_A);
  out.command(in.command);
  std::uint32_t status = msg::STATUS_SIM_TRUTH_VALID | msg::STATUS_EXTERNAL_VALID;
  if (in.command_kind == scenario::CommandKind::Force) status |= msg::STATUS_FORCE_MODE;
  if (force_comp_used) status |= msg::STATUS_FRICTION_COMP;
  out.status(status);
}

void to_msg(const calibration::Calibrator& calibrator, std::uint8_t corner_id, std::uint64_t version,
            double time_s, msg::CalibrationState& out) {
  const auto& c = calibrator.curve();
  const auto& f = calibrator.friction();
  const auto& st = calibrator.stats();
  out.corner_id(corner_id);
  out.version(version);
  out.time_s(time_s);
  out.curve_a_kN_per_rev3(c.a);
  out.curve_b_kN_per_rev2(c.b);
  out.curve_c_kN_per_rev(c.c);
  out.curve_d_kN(c.d);
  out.friction_delta_rev(f.delta_rev);
  out.friction_stiffness_kN_per_rev(f.stiffness_kN_per_rev);
  out.friction_viscous_kN_per_rev_per_s(calibrator.config().viscous_friction ? f.viscous_kN_per_rev_per_s : 0.0);
  out.friction_load_gain(calibrator.config().load_friction_gain);
  out.friction_load_reference_kN(calibrator.config().load_friction_reference_kN);
  out.backlash_width_rev(calibrator.config().backlash_width_rev);
  out.load_cell_offset_kN_per_C(calibrator.config().load_cell_offset_kN_per_C);
  out.load_cell_offset_reference_C(calibrator.config().load_cell_offset_reference_C);
  out.fits_accepted(st.fits_accepted);
  out.fits_rejected(st.fits_rejected);
  out.cycles_detected(st.cycles_detected);
  out.last_fit_rms_kN(st.last_fit_rms_kN);
  out.last_fit_span_rev(st.last_fit_span_rev);
}

bool from_msg(const msg::CalibrationState& in, CalibrationModel& out) {
  const auto& d = in.friction_delta_rev();
  const auto& k = in.friction_stiffness_kN_per_rev();
  if (d.size() != k.size()) return false;
  for (double v : {in.curve_a_kN_per_rev3(), in.curve_b_kN_per_rev2(), in.curve_c_kN_per_rev(), in.curve_d_kN()}) {
    if (!std::isfinite(v)) return false;
  }
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (!std::isfinite(d[i]) || !(d[i] > 0.0) || !std::isfinite(k[i])) return false;
  }
  // The effect terms within their own bounds (the term objects CalibratorConfig::validate checks
  // through, bbw/model/effect_terms.hpp).
  calibration::EffectTermValues terms;
  terms.viscous_kN_per_rev_per_s = in.friction_viscous_kN_per_rev_per_s();
  terms.load_friction_gain = in.friction_load_gain();
  terms.load_friction_reference_kN = in.friction_load_reference_kN();
  terms.backlash_width_rev = in.backlash_width_rev();
  terms.load_cell_offset_kN_per_C = in.load_cell_offset_kN_per_C();
  terms.load_cell_offset_reference_C = in.load_cell_offset_reference_C();
  if (calibration::check_effect_terms(terms)) return false;
  out.curve = {in.curve_a_kN_per_rev3(), in.curve_b_kN_per_rev2(), in.curve_c_kN_per_rev(), in.curve_d_kN()};
  auto& f = out.friction;
  f.delta_rev.assign(d.begin(), d.end());
  f.stiffness_kN_per_rev.assign(k.begin(), k.end());
  f.viscous_kN_per_rev_per_s = in.friction_viscous_kN_per_rev_per_s();
  f.load_gain = in.friction_load_gain();
  f.load_reference_kN = in.friction_load_reference_kN();
  f.backlash_width_rev = in.backlash_width_rev();
  f.load_cell_offset_kN_per_C = in.load_cell_offset_kN_per_C();
  f.load_cell_offset_reference_C = in.load_cell_offset_reference_C();
  f.curve = {out.curve.a, out.curve.b, out.curve.c, out.curve.d};
  out.version = in.version();
  return true;
}

}  // namespace bbw::dds
