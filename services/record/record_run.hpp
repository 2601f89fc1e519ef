#pragma once
// mft-record's steps (services/record/main.cpp): its command line and settings, then one run: the recorder's
// writer thread (recorder.hpp), its own DDS participant with a reader per recorded topic (topic_table.hpp; the 1 kHz
// topics from the chain channel in a lockstep stack that has one), the main thread's 5 ms loop (lockstep progress,
// the receiving threads' priority), and at the end the drain, the linger and the summary.
#include <cstdint>
#include <memory>
#include <string>

#include "chain/scenario.hpp"
#include "services/record/record_participant.hpp"
#include "services/record/recorder.hpp"
#include "services/record/thread_priority.hpp"
#include "services/record/topic_table.hpp"
#include "services/runtime/chain_channel.hpp"
#include "services/runtime/process.hpp"

namespace mft::services {

struct RecordSettings {
  std::string mode;  // lockstep or realtime
  bool lockstep = true;
  chain::Scenario scenario;
  long nice_value = 10;
  Background background = Background::kNone;
  bool best_effort_readers = true;  // --reader-qos best_effort
  double linger_s = 0.2;
  long poll_us = 1000;                  // --poll-us: 0 = Fast DDS's blocking receive
  std::uint32_t socket_buffer_bytes = 0;  // --socket-buffer-mb
  rawlog::RecorderOptions recorder;  // with the metadata: the configuration every service ran with
};

// Every option of mft-record: the service contract's and its own.
void declareRecordOptions(CommandLine& cli);
// The settings of a parsed command line: the contract's options, read as ServiceContext does (but the recorder
// has its own participant), the recorder's, and the configuration stored in the metadata. Unless it continues a
// crashed recorder's recording, an existing recording at --output is refused or cleared. With --rt the process
// takes SCHED_FIFO here, before any thread exists. Exits 2 on a bad option or file.
RecordSettings readRecordSettings(const CommandLine& cli);

class RecordRun {
 public:
  // Starts the writer and creates the readers; exits 2 when either cannot start.
  RecordRun(const CommandLine& cli, const RecordSettings& settings);
  RecordRun(const RecordRun&) = delete;
  RecordRun& operator=(const RecordRun&) = delete;
  // The main thread until SIGINT/SIGTERM.
  void recordUntilShutdown();
  // Drains, closes the file and writes the summary; exit status 0, or 1 when the writer failed.
  int finish();

 private:
  void lingerUntilQuiet();
  static std::unique_ptr<ChainChannel> openChannel(const CommandLine& cli, bool lockstep);

  const CommandLine& cli_;
  const RecordSettings& settings_;
  rawlog::Recorder recorder_;
  std::unique_ptr<RecordParticipant> participant_;
  std::unique_ptr<ChainChannel> channel_;  // a lockstep stack's chain channel: the 1 kHz topics from there
  std::unique_ptr<TopicTable> topics_;
  ProgressReporter progress_;
  BackgroundPolicy priority_;
};

}  // namespace mft::services
