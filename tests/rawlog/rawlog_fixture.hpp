#pragma once
// The messages of tests/data/rawlog/schema1.rawlog, a recording made by the schema-1 recorder (before the layout
// became generic), and of schema2.rawlog, made by the schema-2 recorder before the rawlog's topic list was
// generated from the registry: the version test reads both with today's reader and compares with these.
// Plain formulas, no random numbers, so the list is the same on every machine. Integers stay below 2^53 and the
// ConfigChange value is the text schema 1 rebuilds from its numbers: schema 1 read these back exactly.
#include <cstdio>
#include <vector>

#include "services/record/rawlog_reader.hpp"

namespace mft::rawlog::fixture {

// Every whole message of a file, in file order, and the assembler's counts of incomplete and unknown ones.
inline std::vector<Message> readAll(RawlogReader& r, std::uint64_t* incomplete = nullptr, std::uint64_t* unknown = nullptr) {
  MessageAssembler a(r.metadata().time_base_unix_ns);
  std::vector<Message> out;
  mrpt::obs::CObservation::Ptr obs;
  Message m;
  std::int64_t t;
  while (r.next(&obs))
    if (a.add(*obs, &m, &t)) out.push_back(m);
  if (incomplete) *incomplete = a.incomplete();
  if (unknown) *unknown = a.unknown();
  return out;
}

inline double val(std::uint64_t k, int i) { return 0.125 * static_cast<double>(k) + 1.0 / (3.0 + i) - 0.5 * i; }

template <std::size_t N>
void fill(std::array<double, N>& a, std::uint64_t k, int base) {
  for (std::size_t i = 0; i < N; ++i) a[i] = val(k, base + static_cast<int>(i));
}

inline std::vector<Message> tickMessages(std::uint64_t k) {
  const std::uint64_t stamp = k * 1'000'000;
  msg::GroundTruth gt;
  gt.tick(k), gt.stamp_ns(stamp), fill(gt.q(), k, 0), fill(gt.qd(), k, 20), fill(gt.contact_force(), k, 40);
  fill(gt.lti(), k, 50);
  msg::SensorData sd;
  sd.tick(k), sd.stamp_ns(stamp), fill(sd.actuated_pos(), k, 1), fill(sd.actuated_vel(), k, 5);
  fill(sd.passive_pos(), k, 9), fill(sd.passive_vel(), k, 13), fill(sd.sea_torque(), k, 17);
  sd.gyro_pitch_rate(val(k, 21)), fill(sd.accel(), k, 22), sd.contact({k % 2 == 0, k % 3 == 0});
  msg::RobotState rs;
  rs.tick(k), rs.stamp_ns(stamp), fill(rs.q(), k, 30), fill(rs.qd(), k, 45), rs.contact({true, k % 2 == 1});
  msg::Reference rf;
  rf.tick(k), rf.stamp_ns(stamp), rf.step_index(k / 2), rf.phase(val(k, 60)), rf.stance_leg(k % 2 ? 1 : -1);
  rf.foot_in_stance({true, false}), fill(rf.base_z(), k, 61), fill(rf.base_pitch(), k, 64), fill(rf.foot_pos(), k, 67);
  fill(rf.foot_vel(), k, 71), fill(rf.foot_acc(), k, 75), fill(rf.base_x(), k, 79), rf.hold_base_x(k % 2 == 0);
  msg::JointCommand jc;
  jc.tick(k), jc.stamp_ns(stamp), jc.seq(k + 1), fill(jc.tau(), k, 82), jc.mode(k == 2 ? 1 : 0);
  msg::WbcDiagnostics wd;
  wd.tick(k), wd.stamp_ns(stamp), wd.solve_time_us(val(k, 86)), wd.tick_time_us(val(k, 87)), wd.iterations(7);
  wd.status(static_cast<std::int32_t>(k % 2)), wd.active_constraints(3), wd.slack_norm(val(k, 88));
  fill(wd.task_error(), k, 89), fill(wd.lti(), k, 95), fill(wd.raci(), k, 97), wd.safety_events(k * 3);
  wd.holding(k == 1), wd.damping(k == 2);
  return {gt, sd, rs, rf, jc, wd};
}

// Ticks 0..3, with an operator command, a push and a live change among them (events follow their tick).
inline std::vector<Message> messages() {
  std::vector<Message> out;
  for (std::uint64_t k = 0; k < 4; ++k) {
    for (const auto& m : tickMessages(k)) out.push_back(m);
    if (k == 1) {
      msg::OperatorCommand o;
      o.seq(4'000'000'000'123ULL), o.z_cmd(0.43), o.v_cmd(0.25), o.mode(msg::LOCOMOTION_WALK);
      out.push_back(o);
      msg::Disturbance d;
      d.seq(9'007'199'254'740'991ULL), d.impulse(-4.5), d.trigger(msg::TRIGGER_AT_NEXT_LIFTOFF), d.time_s(1.75), d.leg(1);
      out.push_back(d);
    }
    if (k == 2) {
      msg::ConfigChange c;
      c.seq(31), c.target(msg::CONFIG_TARGET_WBC), c.applied(true), c.at_s(0.002), c.tick(2), c.count(2);
      c.number({300.0, 250.0});
      std::snprintf(c.key().data(), c.key().size(), "%s", "gains.swing_foot.kp");
      std::snprintf(c.value().data(), c.value().size(), "%s", "[300, 250]");
      out.push_back(c);
    }
  }
  return out;
}

// schema2.rawlog: the same, then a verdict (recorded from schema 2 on) with its reason as text and a seq above
// 2^53 (schema 2 keeps both exactly). Pushed last, it is stamped with tick 3's time and written after tick 3's
// messages.
inline std::vector<Message> schema2Messages() {
  auto out = messages();
  msg::CommandVerdict v;
  v.seq((std::uint64_t{1} << 53) + 3), v.source(msg::COMMAND_SOURCE_SIMULATOR), v.verdict(msg::VERDICT_SCHEDULED);
  v.accepted(true), v.tick(3), v.stamp_ns(3'000'000);
  std::snprintf(v.reason().data(), v.reason().size(), "%s", "push armed for the next lift-off of leg 1, \"left\"");
  out.push_back(v);
  return out;
}

}  // namespace mft::rawlog::fixture
