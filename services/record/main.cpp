// mft-record: subscribes to every topic (topic_table.hpp) and writes an MRPT rawlog (rawlog_format.hpp) from a
// writer thread (recorder.hpp); the DDS callbacks only copy into a bounded queue. Lockstep: it publishes its
// progress for the simulator's flow control. Service contract: READY once the readers exist, exit 0 on
// SIGINT/SIGTERM after draining and closing the file, JSON summary via --summary. The steps: record_run.hpp.
#include <cstdio>
#include <filesystem>

#include "common/tool_io.hpp"
#include "services/record/record_run.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/service_context.hpp"

using namespace mft;

namespace {

// --check-config: the configuration (read by readRecordSettings) and the DDS profile file; starts nothing.
int reportConfigOk(const services::CommandLine& cli) {
  const std::string problem = services::checkProfilesFile(services::ServiceContext::profilesFile(cli));
  if (!problem.empty()) cli.fail(problem);
  std::printf("mft-record: configuration ok\n");
  return 0;
}

int toolMain(int argc, char** argv) {
  services::CommandLine cli("mft-record",
                            "Records every topic to an MRPT rawlog (observations-only format, standard classes,\n"
                            "metadata comment first, sidecar FILE.yaml). See docs/guide/recording.md.");
  services::declareRecordOptions(cli);
  cli.parse(argc, argv);
  services::installShutdownHandlers();
  const services::RecordSettings settings = services::readRecordSettings(cli);
  if (cli.isSet("check-config")) return reportConfigOk(cli);
  std::filesystem::create_directories(std::filesystem::path(settings.recorder.output).parent_path());
  services::RecordRun run(cli, settings);
  services::announceReady("mft-record");
  run.recordUntilShutdown();
  return run.finish();
}

}  // namespace

// I/O errors and anything else escaping the main: one line and a documented exit status, never an abort.
int main(int argc, char** argv) {
  return mft::config::guardedMain("mft-record", [&] { return toolMain(argc, argv); });
}
