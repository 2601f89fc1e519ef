// mft-inject: a test participant for the security tests and the fault matrix (docs/guide/security.md, docs/results/faults.md).
//  --listen TOPICS        joins the domain (with no identity, or --secure DIR --identity NAME), subscribes and
//                         counts samples per topic: matched writers, received, non-finite samples, largest gap.
//                         With --wait-writers S it first waits (at most S seconds) until every listened topic has a
//                         matched writer, so that a slow discovery or secure handshake does not eat the window.
//  --publish TOPIC        publishes on TOPIC: values from --value (nan, inf, -inf, range, or a number) in the
//                         --field fields (default all floating-point fields). With --follow it copies every
//                         real sample of TOPIC and re-publishes it corrupted at once, its tick advanced by
//                         --tick-offset (so a service takes the corrupted sample as the newest one); otherwise
//                         it publishes at --rate with its own tick counter.
// Any topic of the registry (idl/topics.yaml); `all` the ones the fault matrix corrupts. It reports what happened
// (participant and writer created or refused, samples written, matched readers) as text or --json, and exits 0,
// or 4 when the participant or the writer was refused.
#include "common/tool_io.hpp"
#include "tools/mft-inject/inject_session.hpp"

static int toolMain(int argc, char** argv) {
  const mft::inject::Options options = mft::inject::parseOptions(argc, argv);
  mft::inject::Session session;
  session.open(options);
  session.awaitMatches(options);
  session.runWindow(options);
  session.report(options);
  session.close();
  return session.exit_code;
}

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-inject", [&] { return toolMain(argc, argv); });
}
