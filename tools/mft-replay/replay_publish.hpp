#pragma once
// mft-replay's playback: a rawlog's messages onto their DDS topics with the recorded timing. One writer per
// recorded topic, whichever the registry holds (idl/topics.yaml): the message type chooses the topic.
#include <array>
#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "common/command_line.hpp"
#include "services/record/rawlog_reader.hpp"
#include "services/runtime/dds_participant.hpp"

namespace mft::replay {

class Publisher {
 public:
  // Writers for `topics`: the event topics with event_writer, the others with `stream_profile`.
  Publisher(services::DdsParticipant& p, const std::set<rawlog::Topic>& topics, const std::string& stream_profile);
  ~Publisher();
  void publish(const rawlog::Message& m);
  // Readers matched on the 1 kHz topics.
  int matched() const;

  struct Writer;

 private:
  std::array<std::unique_ptr<Writer>, rawlog::kNumTopics> writers_;
};

// Plays `file` (again and again with --loop) and reports; the exit status.
int playback(const std::string& file, std::unique_ptr<rawlog::RawlogReader> reader, const config::CommandLine& cli);

}  // namespace mft::replay
