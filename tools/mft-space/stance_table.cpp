#include "stance_table.hpp"

#include <cmath>
#include <cstdio>

#include "json_writer.hpp"

namespace mft::tools {

using namespace mft::model;

std::vector<StanceRow> stanceTable(const RobotDescription& robot, const MftCriteria& c, const MftLegPolygon& polygon,
                                   double from, double to, double step) {
  const MftLegModel leg = MftLegModel::from(robot);
  MftCriteria opt = c, fixed = c;
  opt.raci_options.form = RaciForm::OptimalRatio;
  fixed.raci_options.form = RaciForm::FixedDrive;
  std::vector<StanceRow> rows;
  const int n = static_cast<int>(std::floor((to - from) / step + 1e-9)) + 1;
  for (int i = 0; i < n; ++i) {
    StanceRow r;
    r.base_height = from + i * step;
    r.d = r.base_height - robot.foot_radius_m;
    r.eval = evaluateVerticalStance(leg, c, r.base_height);
    r.raci_optimal = evaluateVerticalStance(leg, opt, r.base_height).raci.raci;
    r.raci_fixed = evaluateVerticalStance(leg, fixed, r.base_height).raci.raci;
    r.inside = r.eval.status == FiveBarStatus::Ok && polygon.contains(r.eval.pose.q_rear, r.eval.pose.q_fore);
    rows.push_back(r);
  }
  return rows;
}

std::string stanceText(const std::vector<StanceRow>& rows, const MftCriteria& c) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "Vertical stance (foot below the hip, d = z_B - foot radius). RACI* optimal ratio, RACI(k) fixed drive "
                "k = %.3g; a_max = %.4g m/s^2%s.\n"
                "preferable: LTI in [%.3g, %.3g] and RACI (%s) in [%.5g, %.5g]\n",
                c.raci_options.drive_k, c.raci_options.accel_max_mps2, c.raci_options.gravity ? ", with gravity" : "",
                c.lti.lo, c.lti.hi, raciFormName(c.raci_options.form), c.raci.lo, c.raci.hi);
  std::string s = buf;
  s += " z_B [m]  d [m]   q_rear   q_fore    ITI    OTI    LTI   RACI*  RACI(k)  preferable  in polygon\n";
  for (const auto& r : rows) {
    const auto& e = r.eval;
    if (e.status != FiveBarStatus::Ok) {
      std::snprintf(buf, sizeof buf, "  %.3f  %.3f   (%s)\n", r.base_height, r.d, fiveBarStatusName(e.status));
    } else {
      std::snprintf(buf, sizeof buf, "  %.3f  %.3f  %7.4f  %7.4f  %.3f  %.3f  %.3f  %6.1f  %6.1f    %-10s  %s\n",
                    r.base_height, r.d, e.pose.q_rear, e.pose.q_fore, e.indices.iti(), e.indices.oti, e.indices.lti(),
                    r.raci_optimal, r.raci_fixed, e.preferable ? "yes" : "no", r.inside ? "inside" : "OUTSIDE");
    }
    s += buf;
  }
  return s;
}

std::string stanceJson(const std::vector<StanceRow>& rows) {
  JsonWriter w;
  w.beginArray();
  for (const auto& r : rows) {
    const auto& e = r.eval;
    w.beginObject()
                               .field("base_height_m", r.base_height, kDigits)
                               .field("d_m", r.d, kDigits)
                               .field("status", fiveBarStatusName(e.status))
                               .field("q_rear", e.pose.q_rear, kDigits)
                               .field("q_fore", e.pose.q_fore, kDigits)
                               .field("iti", e.indices.iti(), kDigits)
                               .field("oti", e.indices.oti, kDigits)
                               .field("lti", e.indices.lti(), kDigits)
                               .field("raci", e.raci.raci, kDigits)
                               .field("raci_optimal", r.raci_optimal, kDigits)
                               .field("raci_fixed", r.raci_fixed, kDigits)
                               .field("preferable", e.preferable)
                               .field("inside_polygon", r.inside)
                               .endObject();
  }
  return w.endArray().str();
}

std::string indexText(const LegEvaluation& e, const MftCriteria& c) {
  char buf[1024];
  if (e.status != FiveBarStatus::Ok) {
    std::snprintf(buf, sizeof buf,
                  "q_rear %.5f  q_fore %.5f: %s (the loop %s)\nLTI 0 (input/output indices 0), RACI infinite\n",
                  e.pose.q_rear, e.pose.q_fore, fiveBarStatusName(e.status),
                  e.status == FiveBarStatus::Degenerate ? "is degenerate: the thighs coincide" : "cannot close");
    return buf;
  }
  std::snprintf(buf, sizeof buf,
                "q_rear %.5f  q_fore %.5f   foot (%.4f, %.4f) m   knees rear %.4f fore %.4f rad%s\n"
                "input transmission   ITI rear %.4f  fore %.4f  (gamma_I %.4f)\n"
                "output transmission  OTI %.4f  (gamma_O)\n"
                "LTI                  %.4f   range [%.3g, %.3g]\n"
                "RACI (%s%s)     %.2f N/sqrt(kg)  (rear %.2f, fore %.2f)   range [%.5g, %.5g], a_max %.4g m/s^2%s\n"
                "preferable           %s\n",
                e.pose.q_rear, e.pose.q_fore, e.pose.foot.x(), e.pose.foot.y(), e.pose.knee_rear, e.pose.knee_fore,
                e.within_limits ? "" : "   (outside the joint limits)", e.indices.iti_rear, e.indices.iti_fore,
                e.indices.iti(), e.indices.oti, e.indices.lti(), c.lti.lo, c.lti.hi, raciFormName(c.raci_options.form),
                c.raci_options.gravity ? ", gravity" : "", e.raci.raci, e.raci.tau_rear, e.raci.tau_fore, c.raci.lo,
                c.raci.hi, c.raci_options.accel_max_mps2, e.raci.singular ? "  (singular)" : "",
                e.preferable ? "yes" : "no");
  return buf;
}

std::string indexJson(const LegEvaluation& e, const MftCriteria& c) {
  return JsonWriter().beginObject()
      .field("q_rear", e.pose.q_rear, kDigits)
      .field("q_fore", e.pose.q_fore, kDigits)
      .field("status", fiveBarStatusName(e.status))
      .field("within_limits", e.within_limits)
      .field("foot_x", e.status == FiveBarStatus::Ok ? e.pose.foot.x() : NAN, kDigits)
      .field("foot_z", e.status == FiveBarStatus::Ok ? e.pose.foot.y() : NAN, kDigits)
      .field("knee_rear", e.status == FiveBarStatus::Ok ? e.pose.knee_rear : NAN, kDigits)
      .field("knee_fore", e.status == FiveBarStatus::Ok ? e.pose.knee_fore : NAN, kDigits)
      .field("iti_rear", e.indices.iti_rear, kDigits)
      .field("iti_fore", e.indices.iti_fore, kDigits)
      .field("gamma_I", e.indices.iti(), kDigits)
      .field("gamma_O", e.indices.oti, kDigits)
      .field("lti", e.indices.lti(), kDigits)
      .field("raci_form", raciFormName(c.raci_options.form))
      .field("raci_gravity", c.raci_options.gravity)
      .field("raci", e.raci.raci, kDigits)
      .field("raci_rear", e.raci.tau_rear, kDigits)
      .field("raci_fore", e.raci.tau_fore, kDigits)
      .field("singular", e.raci.singular || e.indices.lti() == 0.0)
      .field("preferable", e.preferable)
      .endObject().str();
}

}  // namespace mft::tools
