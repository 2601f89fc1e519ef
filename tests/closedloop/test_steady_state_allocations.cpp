// No allocation in a steady-state tick (issue 18: "nothing allocated in the control loop"): the chain's four
// nodes (chain/: simulator, estimator, planner, WBC), driven in the lockstep order as the services and
// mft-closedloop drive them, with every heap allocation of this process counted (operator new and the C
// allocator, which ODE uses), separately around each node's call. The nodes are each service's compute. The
// transport between them, the chain channel (serialize, copy into the slot, take, deserialize: the default path
// of every chain topic), is counted the same way. Only the counting thread's allocations count: DDS's own threads
// (discovery, the listener) run beside it.
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include <sys/mman.h>
#include <unistd.h>

#include "chain/closed_loop.hpp"
#include "chain/estimator_node.hpp"
#include "chain/planner_node.hpp"
#include "chain/sim_node.hpp"
#include "chain/wbc_node.hpp"
#include "idl/msg_pubsub.hpp"
#include "idl/msg_types.hpp"
#include "services/runtime/topic_io.hpp"

extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);
extern "C" void* __libc_memalign(std::size_t, std::size_t);
extern "C" void __libc_free(void*);

namespace {
thread_local bool counting = false;  // this executable's static TLS: reading it never allocates
std::atomic<long> allocations{0};
void note() {
  if (counting) allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

// The C allocator: ODE and anything in C allocate through these.
extern "C" void* malloc(std::size_t n) {
  note();
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t a, std::size_t b) {
  note();
  return __libc_calloc(a, b);
}
extern "C" void* realloc(void* p, std::size_t n) {
  note();
  return __libc_realloc(p, n);
}
extern "C" void* memalign(std::size_t a, std::size_t n) {
  note();
  return __libc_memalign(a, n);
}
extern "C" int posix_memalign(void** out, std::size_t a, std::size_t n) {
  note();
  *out = __libc_memalign(a, n);
  return *out ? 0 : 12;  // ENOMEM
}
extern "C" void* aligned_alloc(std::size_t a, std::size_t n) {
  note();
  return __libc_memalign(a, n);
}
// operator new through malloc above (libstdc++'s does too; defined here so that a static libstdc++ cannot
// bypass the count).
void* operator new(std::size_t n) {
  void* p = malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  return p;
}
void* operator new[](std::size_t n) { return operator new(n); }
void* operator new(std::size_t n, std::align_val_t a) {
  void* p = aligned_alloc(static_cast<std::size_t>(a), n ? n : 1);
  if (!p) throw std::bad_alloc();
  return p;
}
void* operator new[](std::size_t n, std::align_val_t a) { return operator new(n, a); }
void operator delete(void* p) noexcept { __libc_free(p); }
void operator delete[](void* p) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { __libc_free(p); }

using namespace mft;

namespace {

struct Counted {
  long estimator = 0, planner = 0, wbc = 0, sim = 0;
};

template <class F>
auto counted(long* into, F&& f) -> decltype(f()) {
  allocations = 0;
  counting = true;
  auto result = f();
  counting = false;
  *into += allocations.load();
  return result;
}

}  // namespace

TEST(SteadyStateTick, NoNodeAllocates) {
  const closedloop::Configs c = closedloop::loadConfigs(MFT_CONFIG_DIR);
  // Stand 1 s, then step in place: the ticks counted (2-4 s) cover swing, touchdown and stance of both legs.
  const chain::Scenario scenario = closedloop::makeScenario(0.42, 0.0, 4.0, "mft", "kalman", 1.0);
  const sim::Terrain terrain = sim::loadTerrain(c.config_dir + "/terrain/" + scenario.terrain + ".yaml");
  chain::SimNode sim(c.robot, c.sim, terrain, scenario, 1.0);
  chain::EstimatorNode estimator(chain::withScenarioMode(c.estimator, scenario.estimator), c.robot);
  chain::PlannerNode planner(c.planner, c.robot, scenario);
  chain::WbcNode wbc(c.robot, chain::withScenarioController(c.wbc, scenario.controller), c.polytope);
  Counted n;
  long ticks_counted = 0;
  const std::uint64_t warm_up = 2000;
  model::GroundTruthState truth;
  while (sim.tick() < sim.ticksTotal()) {
    const bool count = sim.tick() >= warm_up;
    Counted tick;
    truth = sim.truth();
    const model::RobotStateEstimate* estimate = nullptr;
    const wbc::WbcReference* reference = nullptr;
    const model::ActuatorCommand* command = nullptr;
    estimate = counted(&tick.estimator, [&] { return &estimator.update(sim.sensors(), &truth); });
    planner.applyScenarioCommands(estimate->time_s, [](const planner::OperatorCommand&, const planner::CommandResult&) {});
    reference = counted(&tick.planner, [&] { return &planner.plan(*estimate); });
    command = counted(&tick.wbc, [&] { return &wbc.update(*estimate, *reference); });
    const bool fell = counted(&tick.sim, [&] { return sim.step(*command); });
    ASSERT_FALSE(fell) << "the robot fell at tick " << sim.tick() << ": no steady state to count";
    if (count) {
      ++ticks_counted;
      n.estimator += tick.estimator;
      n.planner += tick.planner;
      n.wbc += tick.wbc;
      n.sim += tick.sim;
    }
  }
  EXPECT_EQ(ticks_counted, 2000);
  RecordProperty("allocations_estimator", static_cast<int>(n.estimator));
  EXPECT_EQ(n.estimator, 0) << "heap allocations in the estimator's update over " << ticks_counted << " ticks";
  EXPECT_EQ(n.planner, 0) << "heap allocations in the planner's plan over " << ticks_counted << " ticks";
  EXPECT_EQ(n.wbc, 0) << "heap allocations in the WBC's update over " << ticks_counted << " ticks";
  EXPECT_EQ(n.sim, 0) << "heap allocations in the simulator's step over " << ticks_counted << " ticks";
}

TEST(SteadyStateTick, TheCounterSeesAnAllocation) {
  long seen = 0;
  counted(&seen, [] {
    auto* p = new std::vector<double>(100);
    delete p;
    return 0;
  });
  EXPECT_GE(seen, 2);  // the vector object and its storage
}

namespace {

// One chain topic over the channel, as two services of a stack pass it (the writer's process and the reader's;
// here two participants of one process): `ticks` writes, each taken by the reader on this thread (Polled), the
// allocations of the last `ticks - warm_up` counted. Returns them; `received` the samples the reader got.
template <class Msg, class PubSubType>
long channelAllocations(services::DdsParticipant& from, services::DdsParticipant& to, const std::string& topic,
                        const std::string& writer_profile, const std::string& reader_profile, int ticks, int warm_up,
                        std::uint64_t* received) {
  std::uint64_t last_tick = 0;
  services::TopicWriter<Msg, PubSubType> writer(from, topic, writer_profile);
  services::TopicReader<Msg, PubSubType> reader(to, topic, reader_profile, [&](const Msg& m) { last_tick = m.tick(); },
                                                services::ChainSlotReader::Delivery::Polled);
  EXPECT_TRUE(writer.viaChainChannel() && reader.viaChainChannel()) << topic;
  // Discovery settled: the writer matched the chain's DDS listener and counts no reader to send to over DDS.
  EXPECT_TRUE(services::waitUntil([&] { return writer.ddsMatched() == 1 && writer.outsideReaders() == 0; },
                                  std::chrono::milliseconds(5000))) << topic << ": DDS matched " << writer.ddsMatched() << ", outside " << writer.outsideReaders();
  Msg m;
  long n = 0;
  for (int k = 1; k <= ticks; ++k) {
    m.tick(static_cast<std::uint64_t>(k));
    counted(&n, [&] {
      writer.write(m);
      return reader.pollChannel();
    });
    if (k == warm_up) n = 0;
  }
  EXPECT_EQ(last_tick, static_cast<std::uint64_t>(ticks)) << topic;
  *received = reader.received();
  return n;
}

}  // namespace

TEST(SteadyStateTick, TheChainChannelPathAllocatesNothing) {
  const std::string name = "/mft-test-alloc-" + std::to_string(getpid());
  const int domain = 100 + static_cast<int>((getpid() + 61) % 100);
  services::DdsParticipant sim(domain, MFT_DDS_PROFILES, "alloc_writer");
  services::DdsParticipant est(domain, MFT_DDS_PROFILES, "alloc_reader");
  sim.openChainChannel(name);
  est.openChainChannel(name);
  shm_unlink(name.c_str());  // both have it mapped
  constexpr int kTicks = 3000, kWarmUp = 1000;
  for (const auto& [w, r] : {std::pair<std::string, std::string>{"control_writer", "control_reader"},
                             std::pair<std::string, std::string>{"lockstep_writer", "lockstep_reader"}}) {
    std::uint64_t got[6] = {};
    using namespace mft::msg;
    const long counts[6] = {
        channelAllocations<SensorData, SensorDataPubSubType>(sim, est, "SensorData", w, r, kTicks, kWarmUp, &got[0]),
        channelAllocations<GroundTruth, GroundTruthPubSubType>(sim, est, "GroundTruth", w, r, kTicks, kWarmUp, &got[1]),
        channelAllocations<RobotState, RobotStatePubSubType>(est, sim, "RobotState", w, r, kTicks, kWarmUp, &got[2]),
        channelAllocations<Reference, ReferencePubSubType>(est, sim, "Reference", w, r, kTicks, kWarmUp, &got[3]),
        channelAllocations<JointCommand, JointCommandPubSubType>(est, sim, "JointCommand", w, r, kTicks, kWarmUp, &got[4]),
        channelAllocations<WbcDiagnostics, WbcDiagnosticsPubSubType>(est, sim, "WbcDiagnostics", w, r, kTicks, kWarmUp,
                                                                     &got[5])};
    for (int i = 0; i < 6; ++i) {
      EXPECT_EQ(counts[i], 0) << "heap allocations on the channel path, topic " << i << ", profiles " << w << "/" << r;
      EXPECT_EQ(got[i], static_cast<std::uint64_t>(kTicks)) << "topic " << i << ": every sample taken once";
    }
  }
}
