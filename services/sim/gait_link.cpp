#include "services/sim/gait_link.hpp"

#include <algorithm>

namespace mft::services {

GaitLink::GaitLink(ServiceContext& ctx)
    : lockstep_(ctx.lockstep()),
      reader_(ctx.reading("Reference"),
              [this](const msg::Reference& m) { onReference(m); }, ChainSlotReader::Delivery::Polled) {}

void GaitLink::onReference(const msg::Reference& m) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (have_ && m.tick() < tick_) return;  // a re-sent older tick
    have_ = true;
    tick_ = m.tick();
    newest_ = {true, m.step_index(), m.phase(), m.stance_leg()};
  }
  arrived_.notify_all();
}

chain::GaitPhase GaitLink::forTick(std::uint64_t k, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    reader_.pollChannel();  // on the chain channel: the slot's newest sample, delivered on this thread
    std::unique_lock<std::mutex> lock(mutex_);
    if (have_ && (tick_ >= k || !lockstep_)) return tick_ == k || !lockstep_ ? newest_ : chain::GaitPhase{};
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) break;
    const auto slice = std::min<std::chrono::steady_clock::duration>(deadline - now, std::chrono::milliseconds(1));
    if (reader_.viaChainChannel()) {
      lock.unlock();
      reader_.awaitChannel(slice);
    } else {
      arrived_.wait_for(lock, slice);
    }
  }
  ++misses_;
  return {};
}

std::unique_ptr<GaitLink> makeGaitLink(ServiceContext& ctx, const chain::Scenario& scenario) {
  const bool needed = std::any_of(scenario.pushes.begin(), scenario.pushes.end(),
                                  [](const chain::ScenarioPush& p) { return p.at_phase >= 0.0; });
  return needed ? std::make_unique<GaitLink>(ctx) : nullptr;
}

}  // namespace mft::services
