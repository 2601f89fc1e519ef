#pragma once
// The newest valid input of one topic that a chain service holds for its next tick: a valid sample replaces it
// (converted with fromMsg), an invalid one is refused and counted by the TickJoin and the last good input stays
// (msg_guard.hpp). The caller holds its mutex around every call.
#include "services/runtime/convert.hpp"
#include "services/runtime/msg_guard.hpp"
#include "services/runtime/tick_join.hpp"

namespace mft::services {

template <class T>
struct HeldInput {
  T value{};
  bool have = false;

  // A second input of a tick (not the one that names it): false when refused.
  template <class Msg>
  bool take(TickJoin& join, const Msg& m, const char* topic) {
    if (!join.accept(validInput(m), topic, m.tick())) return false;
    fromMsg(m, &value);
    have = true;
    return true;
  }
  // The tick-naming input (TickJoin::acceptTick): false when refused or a stray tick; `new_clock` as there.
  template <class Msg>
  bool takeTick(TickJoin& join, const Msg& m, const char* topic, bool* new_clock = nullptr) {
    if (!join.acceptTick(validInput(m), topic, m.tick(), new_clock)) return false;
    fromMsg(m, &value);
    have = true;
    return true;
  }
};

}  // namespace mft::services
