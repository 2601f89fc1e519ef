#include "services/runtime/polling_udp_transport.hpp"

#include <fastrtps/utils/IPLocator.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <ctime>

namespace mft::services {

namespace rtps = eprosima::fastrtps::rtps;
namespace fdds = eprosima::fastdds::rtps;
using eprosima::fastrtps::rtps::IPLocator;

namespace {

std::shared_ptr<PollingUdpStats>& lastStatsSlot() {
  static std::shared_ptr<PollingUdpStats> slot = std::make_shared<PollingUdpStats>();
  return slot;
}

// A whitelist entry is an IPv4 address or an interface name; Fast DDS accepts both.
std::vector<std::string> resolveInterface(const std::string& entry) {
  in_addr addr{};
  if (inet_pton(AF_INET, entry.c_str(), &addr) == 1) return {entry};
  std::vector<std::string> out;
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return out;
  for (ifaddrs* i = list; i; i = i->ifa_next) {
    if (!i->ifa_addr || i->ifa_addr->sa_family != AF_INET || entry != i->ifa_name) continue;
    char text[INET_ADDRSTRLEN];
    inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(i->ifa_addr)->sin_addr, text, sizeof text);
    out.emplace_back(text);
  }
  freeifaddrs(list);
  return out;
}

// A non-blocking socket bound exclusively to address:port (a port in use fails, and Fast DDS then tries
// the next participant id, as with its own transport).
int openBoundSocket(const std::string& address, std::uint16_t port, std::uint32_t receive_buffer) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (receive_buffer > 0) {
    const int size = static_cast<int>(receive_buffer);
    // FORCE passes net.core.rmem_max when we may; otherwise the kernel caps the plain request.
    if (::setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &size, sizeof size) != 0)
      ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &size, sizeof size);
  }
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(port);
  if (inet_pton(AF_INET, address.c_str(), &sa.sin_addr) != 1 ||
      ::bind(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

}  // namespace

PollingUdpTransportDescriptor::PollingUdpTransportDescriptor(std::shared_ptr<fdds::UDPv4TransportDescriptor> udp_descriptor,
                                                             std::chrono::microseconds period)
    : ChainingTransportDescriptor(udp_descriptor), udp(std::move(udp_descriptor)), poll_period(period) {}

fdds::TransportInterface* PollingUdpTransportDescriptor::create_transport() const { return new PollingUdpTransport(*this); }

PollingUdpTransport::PollingUdpTransport(const PollingUdpTransportDescriptor& d)
    : ChainingTransport(d), descriptor_(d), stats_(std::make_shared<PollingUdpStats>()) {
  lastStatsSlot() = stats_;
  thread_ = std::thread([this] { pollLoop(); });
}

PollingUdpTransport::~PollingUdpTransport() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Channel& c : channels_) ::close(c.fd);
  channels_.clear();
}

namespace {
std::int64_t monotonicNs() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1000000000LL + t.tv_nsec;
}
}  // namespace

std::int64_t PollingUdpStats::sincePollNs() const {
  const std::int64_t last = last_poll_ns.load(std::memory_order_relaxed);
  return last == 0 ? 0 : monotonicNs() - last;
}

const PollingUdpStats& PollingUdpTransport::lastStats() { return *lastStatsSlot(); }

std::vector<std::string> PollingUdpTransport::bindAddresses(const rtps::Locator_t& locator) const {
  if (!IPLocator::isAny(locator)) return {IPLocator::toIPv4string(locator)};
  if (descriptor_.udp->interfaceWhiteList.empty()) return {"0.0.0.0"};
  std::vector<std::string> out;
  for (const std::string& entry : descriptor_.udp->interfaceWhiteList)
    for (const std::string& a : resolveInterface(entry)) out.push_back(a);
  return out;
}

bool PollingUdpTransport::OpenInputChannel(const rtps::Locator_t& locator, fdds::TransportReceiverInterface* receiver,
                                           std::uint32_t max_message_size) {
  // Multicast (discovery announcements, a few per second) stays with the blocking transport below.
  if (IPLocator::isMulticast(locator)) return ChainingTransport::OpenInputChannel(locator, receiver, max_message_size);
  const std::uint16_t port = IPLocator::getPhysicalPort(locator);
  const std::vector<std::string> addresses = bindAddresses(locator);
  if (addresses.empty()) return false;
  std::vector<Channel> opened;
  for (const std::string& address : addresses) {
    const int fd = openBoundSocket(address, port, descriptor_.udp->receiveBufferSize);
    if (fd < 0) {
      for (const Channel& c : opened) ::close(c.fd);
      return false;
    }
    Channel c;
    c.fd = fd;
    c.port = port;
    IPLocator::createLocator(LOCATOR_KIND_UDPv4, address, port, c.local);
    c.receiver = receiver;
    opened.push_back(c);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  channels_.insert(channels_.end(), opened.begin(), opened.end());
  return true;
}

bool PollingUdpTransport::IsInputChannelOpen(const rtps::Locator_t& locator) const {
  if (IPLocator::isMulticast(locator)) return ChainingTransport::IsInputChannelOpen(locator);
  const std::uint16_t port = IPLocator::getPhysicalPort(locator);
  std::lock_guard<std::mutex> lock(mutex_);
  return std::any_of(channels_.begin(), channels_.end(), [&](const Channel& c) { return c.port == port; });
}

bool PollingUdpTransport::CloseInputChannel(const rtps::Locator_t& locator) {
  if (IPLocator::isMulticast(locator)) return ChainingTransport::CloseInputChannel(locator);
  const std::uint16_t port = IPLocator::getPhysicalPort(locator);
  std::lock_guard<std::mutex> lock(mutex_);  // waits for a delivery in progress
  bool closed = false;
  for (auto it = channels_.begin(); it != channels_.end();) {
    if (it->port == port) {
      ::close(it->fd);
      it = channels_.erase(it);
      closed = true;
    } else {
      ++it;
    }
  }
  return closed;
}

bool PollingUdpTransport::send(rtps::SenderResource* low_sender_resource, const rtps::octet* buffer, std::uint32_t size,
                               rtps::LocatorsIterator* destinations_begin, rtps::LocatorsIterator* destinations_end,
                               const std::chrono::steady_clock::time_point& timeout) {
  return low_sender_resource->send(buffer, size, destinations_begin, destinations_end, timeout);
}

void PollingUdpTransport::receive(fdds::TransportReceiverInterface* next_receiver, const rtps::octet* buffer,
                                  std::uint32_t size, const rtps::Locator_t& local_locator,
                                  const rtps::Locator_t& remote_locator) {
  next_receiver->OnDataReceived(buffer, size, local_locator, remote_locator);
}

void PollingUdpTransport::pollLoop() {
  std::vector<rtps::octet> buffer(65536);  // the largest UDP payload: allocated once
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  while (!stop_) {
    std::uint64_t n = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const Channel& c : channels_) {
        for (;;) {
          sockaddr_in from{};
          socklen_t from_len = sizeof from;
          const ssize_t got = ::recvfrom(c.fd, buffer.data(), buffer.size(), 0, reinterpret_cast<sockaddr*>(&from), &from_len);
          if (got < 0) break;  // EAGAIN: drained (or an error, retried next period)
          rtps::Locator_t remote;
          IPLocator::setIPv4(remote, reinterpret_cast<const unsigned char*>(&from.sin_addr.s_addr));
          remote.kind = LOCATOR_KIND_UDPv4;
          IPLocator::setPhysicalPort(remote, ntohs(from.sin_port));
          c.receiver->OnDataReceived(buffer.data(), static_cast<std::uint32_t>(got), c.local, remote);
          ++n;
        }
      }
    }
    stats_->polls.fetch_add(1, std::memory_order_relaxed);
    stats_->last_poll_ns.store(monotonicNs(), std::memory_order_relaxed);
    stats_->datagrams.fetch_add(n, std::memory_order_relaxed);
    if (n > stats_->max_datagrams_per_poll.load(std::memory_order_relaxed))
      stats_->max_datagrams_per_poll.store(n, std::memory_order_relaxed);
    // An absolute schedule that never tries to catch up: after a long stall, poll again one period later.
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    next.tv_nsec += static_cast<long>(descriptor_.poll_period.count()) * 1000;
    while (next.tv_nsec >= 1000000000L) {
      next.tv_nsec -= 1000000000L;
      ++next.tv_sec;
    }
    if (next.tv_sec < now.tv_sec || (next.tv_sec == now.tv_sec && next.tv_nsec < now.tv_nsec)) next = now;
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
  }
}

void applyReceiveTuning(const ReceiveTuning& tuning, eprosima::fastdds::dds::DomainParticipantQos* qos) {
  if (tuning.socket_buffer_bytes == 0 && tuning.poll_period.count() == 0) return;
  std::vector<std::shared_ptr<fdds::TransportDescriptorInterface>> transports;
  for (const auto& t : qos->transport().user_transports) {
    auto udp = std::dynamic_pointer_cast<fdds::UDPv4TransportDescriptor>(t);
    if (!udp) {
      transports.push_back(t);
      continue;
    }
    auto copy = std::make_shared<fdds::UDPv4TransportDescriptor>(*udp);
    if (tuning.socket_buffer_bytes > 0) copy->receiveBufferSize = tuning.socket_buffer_bytes;
    if (tuning.poll_period.count() > 0)
      transports.push_back(std::make_shared<PollingUdpTransportDescriptor>(copy, tuning.poll_period));
    else
      transports.push_back(copy);
  }
  qos->transport().user_transports = transports;
  if (tuning.socket_buffer_bytes > 0) qos->transport().listen_socket_buffer_size = tuning.socket_buffer_bytes;
}

}  // namespace mft::services
