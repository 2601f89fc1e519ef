#include "services/sim/topic_pushes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace mft::services {

TopicPushes::TopicPushes(ServiceContext& ctx, CommandLink& link, double max_push_Ns, double control_period_s)
    : link_(link),
      max_push_Ns_(max_push_Ns),
      control_period_s_(control_period_s),
      verdicts_(ctx.participant(), "mft-sim", msg::COMMAND_SOURCE_SIMULATOR),
      reader_(ctx.reading("Disturbance"), [this](const msg::Disturbance& m) { onRequest(m); }) {
  pending_.reserve(64);
  applied_.reserve(64);
}

void TopicPushes::onRequest(const msg::Disturbance& m) {
  const auto verdict = chain::checkDisturbance(m.impulse(), m.trigger(), m.time_s(), m.leg(), max_push_Ns_);
  std::lock_guard<std::mutex> lock(link_.mutex());
  ++received_;
  const std::uint64_t published_tick = link_.driver().publishedTick();
  const double now_s = static_cast<double>(published_tick) * control_period_s_;
  Slot* slot = nullptr;
  for (auto& p : slots_)
    if (p.id == 0) {
      slot = &p;
      break;
    }
  const auto seq = m.seq();
  if (verdict != chain::InputVerdict::Ok || !slot) {
    if (rejected_++ < 3)
      std::printf("mft-sim: refused a Disturbance (seq %llu): %s\n", static_cast<unsigned long long>(seq),
                  slot ? chain::toString(verdict) : "too many pushes waiting");
    if (!slot)
      verdicts_.post(seq, msg::VERDICT_REJECTED, published_tick, 0, "%zu pushes are already waiting to be applied",
                     slots_.size());
    else if (verdict == chain::InputVerdict::NonFinite)
      verdicts_.post(seq, msg::VERDICT_REJECTED, published_tick, 0, "impulse or time is not a finite number");
    else if (verdict == chain::InputVerdict::BadEnum)
      verdicts_.post(seq, msg::VERDICT_REJECTED, published_tick, 0, "unknown trigger %d or leg %d (0 right, 1 left)",
                     m.trigger(), m.leg());
    else if (m.time_s() < 0.0)
      verdicts_.post(seq, msg::VERDICT_REJECTED, published_tick, 0, "negative time %.3f s", m.time_s());
    else
      verdicts_.post(seq, msg::VERDICT_REJECTED, published_tick, 0,
                     "impulse %.3f N s beyond the largest accepted push %.3f N s (mft-sim --max-push)", m.impulse(),
                     max_push_Ns_);
    return;
  }
  sim::ImpulseSpec spec;
  spec.impulse_Ns = {m.impulse(), 0.0};
  spec.time_s = m.time_s();
  spec.trigger = m.trigger() == msg::TRIGGER_AT_NEXT_LIFTOFF ? sim::ImpulseTrigger::AtLiftOff : sim::ImpulseTrigger::AtTime;
  spec.leg = std::max<int>(0, m.leg());
  spec.id = next_id_++;
  *slot = {spec.id, seq};
  pending_.push_back(spec);
  if (spec.trigger == sim::ImpulseTrigger::AtLiftOff)
    verdicts_.post(seq, msg::VERDICT_SCHEDULED, published_tick, 0,
                   "push of %.3f N s will be applied at the next %s-foot lift-off", m.impulse(),
                   spec.leg == 0 ? "right" : "left");
  else
    verdicts_.post(seq, msg::VERDICT_SCHEDULED, published_tick, 0, "push of %.3f N s will be applied at t = %.3f s",
                   m.impulse(), std::max(spec.time_s, now_s));
}

void TopicPushes::scheduleInto(chain::SimNode& node) {
  std::lock_guard<std::mutex> lock(link_.mutex());
  for (const auto& p : pending_) node.schedule(p);
  pending_.clear();
}

void TopicPushes::reportApplied(const chain::SimNode& node, std::uint64_t k) {
  const auto& impulses = node.simulator().stats().impulses;
  for (std::size_t i = node.firstNewImpulse(); i < impulses.size(); ++i) {
    const auto& applied = impulses[i];
    if (applied.id == 0) continue;  // a scenario push
    std::lock_guard<std::mutex> lock(link_.mutex());
    for (auto& p : slots_)
      if (p.id == applied.id) {
        ++applied_count_;
        if (applied_.size() < applied_.capacity())
          applied_.push_back({applied.impulse_Ns.x(), applied.time_s, static_cast<double>(k)});
        verdicts_.post(p.seq, msg::VERDICT_APPLIED, k, static_cast<std::uint64_t>(std::llround(applied.time_s * 1e9)),
                       "push of %.3f N s applied at t = %.4f s (tick %llu)", applied.impulse_Ns.x(), applied.time_s,
                       static_cast<unsigned long long>(k));
        p = Slot{};
      }
  }
}

void TopicPushes::writeCounts(config::JsonWriter& w) const {
  w.field("disturbances_received", received_).field("disturbances_applied", applied_count_);
  w.field("disturbances_rejected", rejected_);
}

void TopicPushes::writeApplied(config::JsonWriter& w) const {
  w.beginArray();
  for (const auto& a : applied_) w.beginArray().fixed(a[0], 4).fixed(a[1], 4).fixed(a[2], 0).endArray();
  w.endArray();
}

}  // namespace mft::services
