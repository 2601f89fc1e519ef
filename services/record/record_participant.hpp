#pragma once
// mft-record's own DDS participant: the project's "mft_participant" profile with larger socket buffers (and
// optionally polled receive, --poll-us). It takes in every topic of a 1 kHz stack (~10k messages/s counting the
// services' re-sends) on one receive thread; with the kernel's default 208 KB buffer, a few ms without CPU on a
// loaded machine overflowed it, and a lost sample of a KEEP_LAST 64 writer is gone for good (measured: ~1 % of
// ticks). In lockstep it also publishes RecorderProgress (the simulator's flow control).
#include <cstdint>
#include <string>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include "idl/msg_pubsub.hpp"
#include "services/runtime/dds_participant.hpp"
#include "services/runtime/dds_security.hpp"
#include "services/runtime/polling_udp_transport.hpp"

namespace mft::services {

class RecordParticipant {
 public:
  // Throws DdsError naming what could not be created.
  RecordParticipant(int domain, const std::string& profiles_file, const ReceiveTuning& tuning,
                    const SecurityOptions& security);
  ~RecordParticipant();
  RecordParticipant(const RecordParticipant&) = delete;
  RecordParticipant& operator=(const RecordParticipant&) = delete;

  eprosima::fastdds::dds::DomainParticipant* get() const { return participant_; }
  eprosima::fastdds::dds::Subscriber* subscriber() const { return subscriber_; }

  // Lockstep flow control: tells the simulator how far the recorder has read.
  void enableProgress();
  void publishProgress(std::uint64_t tick, std::uint64_t all_topics_tick, std::uint64_t received);

 private:
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::DataWriter* progress_writer_ = nullptr;
  msg::RecorderProgress progress_;
};

}  // namespace mft::services
