// sim_hash_probe: runs a fixed episode (stand under PD, a push at the next right lift-off or at 0.3 s, then
// zero torque: a fall with impacts) and prints the final state hash. The determinism test compares the
// hashes of two processes with its own.
#include <cinttypes>
#include <cstdio>
#include <exception>

#include "sim_test_support.hpp"

int main() {
  try {
    using namespace mft::sim;
    Simulator sim(test::robot(), test::options(), test::terrainFile("course.yaml"));
    std::printf("%016" PRIx64 "\n", test::runHashEpisode(sim));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sim_hash_probe: %s\n", e.what());
    return 1;
  }
}
