// libFuzzer's entry point for a fuzz target (fuzz_target.hpp): an outcome without a message is a finding.
#include <cstdio>
#include <cstdlib>

#include "fuzz/fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const mft::fuzz::Outcome outcome = mft::fuzz::runOne(data, size);
  if (outcome.message.empty()) {
    std::fprintf(stderr, "fuzz: an outcome without a message\n");
    std::abort();
  }
  return 0;
}
