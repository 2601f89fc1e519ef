// A UDPv4 transport for the recorder that polls its unicast sockets instead of blocking on them.
//
// Why: every datagram to a thread blocked in recv makes the *sender* wake that thread. On this VM a wake-up
// on another vCPU costs the sender ~15-20 us (an inter-processor interrupt, a VM exit), so the recorder's
// six samples per tick slowed the lockstep chain by 30-40 % (perf: the time sits in sock_def_readable under
// the chain's sendto). A socket nobody sleeps on costs the sender only the copy. So the recorder's unicast
// sockets (where the 1 kHz samples arrive) are drained by one thread every `poll_period`; multicast
// discovery and every send stay with Fast DDS's own UDPv4 transport underneath (ChainingTransport).
// The price: samples reach the recorder up to one period later, which a recorder does not mind.
#pragma once

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/rtps/transport/ChainingTransport.h>
#include <fastdds/rtps/transport/ChainingTransportDescriptor.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace mft::services {

struct PollingUdpTransportDescriptor : public eprosima::fastdds::rtps::ChainingTransportDescriptor {
  PollingUdpTransportDescriptor(std::shared_ptr<eprosima::fastdds::rtps::UDPv4TransportDescriptor> udp,
                                std::chrono::microseconds poll_period);
  eprosima::fastdds::rtps::TransportInterface* create_transport() const override;

  std::shared_ptr<eprosima::fastdds::rtps::UDPv4TransportDescriptor> udp;
  std::chrono::microseconds poll_period;
};

// Counters a caller (and a test) can read while the transport runs.
struct PollingUdpStats {
  std::atomic<std::uint64_t> polls{0};
  std::atomic<std::uint64_t> datagrams{0};
  std::atomic<std::uint64_t> max_datagrams_per_poll{0};
  std::atomic<std::int64_t> last_poll_ns{0};  // CLOCK_MONOTONIC
  // How long ago the receive thread last polled (a starved thread shows here).
  std::int64_t sincePollNs() const;
};

class PollingUdpTransport : public eprosima::fastdds::rtps::ChainingTransport {
 public:
  explicit PollingUdpTransport(const PollingUdpTransportDescriptor& descriptor);
  ~PollingUdpTransport() override;

  bool OpenInputChannel(const eprosima::fastrtps::rtps::Locator_t& locator,
                        eprosima::fastdds::rtps::TransportReceiverInterface* receiver,
                        std::uint32_t max_message_size) override;
  bool IsInputChannelOpen(const eprosima::fastrtps::rtps::Locator_t& locator) const override;
  bool CloseInputChannel(const eprosima::fastrtps::rtps::Locator_t& locator) override;

  bool send(eprosima::fastrtps::rtps::SenderResource* low_sender_resource, const eprosima::fastrtps::rtps::octet* buffer,
            std::uint32_t size, eprosima::fastrtps::rtps::LocatorsIterator* destinations_begin,
            eprosima::fastrtps::rtps::LocatorsIterator* destinations_end,
            const std::chrono::steady_clock::time_point& timeout) override;
  void receive(eprosima::fastdds::rtps::TransportReceiverInterface* next_receiver,
               const eprosima::fastrtps::rtps::octet* buffer, std::uint32_t size,
               const eprosima::fastrtps::rtps::Locator_t& local_locator,
               const eprosima::fastrtps::rtps::Locator_t& remote_locator) override;

  eprosima::fastdds::rtps::TransportDescriptorInterface* get_configuration() override { return &descriptor_; }

  // The statistics of the transport most recently created in this process (the recorder has one).
  static const PollingUdpStats& lastStats();

 private:
  struct Channel {
    int fd = -1;
    std::uint16_t port = 0;
    eprosima::fastrtps::rtps::Locator_t local;
    eprosima::fastdds::rtps::TransportReceiverInterface* receiver = nullptr;
  };
  void pollLoop();
  std::vector<std::string> bindAddresses(const eprosima::fastrtps::rtps::Locator_t& locator) const;

  PollingUdpTransportDescriptor descriptor_;  // its udp and poll_period configure everything below
  mutable std::mutex mutex_;  // held while delivering: a closed channel gets nothing after Close returns
  std::vector<Channel> channels_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::shared_ptr<PollingUdpStats> stats_;
};

// How a participant receives: the socket buffer of its UDPv4 transports and, with a poll period, the
// polling receive path above. Applied to a QoS built from the profile (the profile itself stays as is).
struct ReceiveTuning {
  std::uint32_t socket_buffer_bytes = 0;           // 0: the profile's
  std::chrono::microseconds poll_period{0};        // 0: Fast DDS's blocking receive
};
void applyReceiveTuning(const ReceiveTuning& tuning, eprosima::fastdds::dds::DomainParticipantQos* qos);

}  // namespace mft::services
