// No allocation in a steady-state tick (issue 18: "nothing allocated in the control loop"): the chain's four
// nodes (chain/: simulator, estimator, planner, WBC), driven in the lockstep order as the services and
// mft-closedloop drive them, with every heap allocation of this process counted (operator new and the C
// allocator, which ODE uses), separately around each node's call. The nodes are each service's compute; the DDS
// path of a service (serialization, the listener) is not covered here.
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

#include "chain/estimator_node.hpp"
#include "chain/planner_node.hpp"
#include "chain/sim_node.hpp"
#include "chain/wbc_node.hpp"
#include "tools/closedloop/closed_loop.hpp"

extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);
extern "C" void* __libc_memalign(std::size_t, std::size_t);

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
void note() {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
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
void operator delete(void* p) noexcept { free(p); }
void operator delete[](void* p) noexcept { free(p); }
void operator delete(void* p, std::size_t) noexcept { free(p); }
void operator delete[](void* p, std::size_t) noexcept { free(p); }
void operator delete(void* p, std::align_val_t) noexcept { free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { free(p); }

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
