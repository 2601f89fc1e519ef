#pragma once
// The life of a service process, in the order of the service contract (services/mft-supervisor): the command line
// (the contract's options, then Loop::declareOptions), the context, the service's own configuration
// (Loop::load(ctx, cli): exits 2 on an error; --check-config ends after it), the loop's endpoints
// (Loop(ctx, cli, loaded)), READY, then Loop::serve(): its exit status.
#include "services/runtime/process.hpp"
#include "services/runtime/service_context.hpp"

namespace mft::services {

template <class Loop>
int runService(const char* service, const char* about, int argc, char** argv) {
  CommandLine cli(service, about);
  ServiceContext::declareOptions(cli);
  Loop::declareOptions(cli);
  cli.parse(argc, argv);
  installShutdownHandlers();
  ServiceContext ctx(service, cli);
  const auto loaded = Loop::load(ctx, cli);
  if (ctx.checkOnly()) return ctx.reportConfigOk();
  Loop loop(ctx, cli, loaded);
  announceReady(service);
  return loop.serve();
}

// serve() of a service whose work runs in its DDS callbacks: nothing on the main thread until SIGINT/SIGTERM,
// then the summary (Loop::summaryJson()) and exit status 0.
template <class Loop>
int serveUntilShutdown(ServiceContext& ctx, Loop& loop) {
  waitForShutdown();
  ctx.writeSummary(loop.summaryJson());
  return 0;
}

}  // namespace mft::services
