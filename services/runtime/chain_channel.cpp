#include "services/runtime/chain_channel.hpp"
#include "services/runtime/process.hpp"

#include <fcntl.h>
#include <linux/futex.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <signal.h>

#include <cerrno>
#include <cstdio>
#include <thread>
#include <climits>
#include <cstring>

namespace mft::services {

namespace {

static_assert(std::atomic<std::uint32_t>::is_always_lock_free && sizeof(std::atomic<std::uint32_t>) == 4,
              "the futex word must be a plain 32-bit integer");

// Shared (not FUTEX_PRIVATE): the waiters and the waker are different processes.
long futexWait(std::atomic<std::uint32_t>* word, std::uint32_t expected, const timespec* timeout) {
  return syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(word), FUTEX_WAIT, expected, timeout, nullptr, 0);
}
void futexWakeAll(std::atomic<std::uint32_t>* word) {
  syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(word), FUTEX_WAKE, INT_MAX, nullptr, nullptr, 0);
}

std::string errnoText(const std::string& what, const std::string& name) {
  return what + " " + name + ": " + std::strerror(errno);
}

}  // namespace

int chainSlotIndex(const std::string& topic_name) {
  const int row = msg::topicIndex(topic_name);
  return row < 0 ? -1 : msg::kTopics[static_cast<std::size_t>(row)].chain_slot;
}

std::size_t ChainChannel::segmentBytes() { return kHeaderBytes + sizeof(Slot) * kSlots; }

namespace {
void* mapSegment(int fd) {
  void* memory = mmap(nullptr, ChainChannel::segmentBytes(), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  return memory == MAP_FAILED ? nullptr : memory;
}
bool processAlive(std::int64_t pid) { return pid > 0 && (kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM); }
std::string megabytes(std::size_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f MB", static_cast<double>(bytes) / 1e6);
  return buf;
}
}  // namespace

ChainChannel::ChainChannel(const std::string& name) : name_(name) {
  static_assert(sizeof(Header) <= kHeaderBytes && kHeaderBytes % alignof(Slot) == 0, "header layout");
  if (name.size() < 2 || name[0] != '/' || name.find('/', 1) != std::string::npos || name.size() > 200)
    throw ChainChannelError("--chain-shm " + name + ": expected a name like /mft-chain-NAME (one leading slash)");
  int fd = shm_open(name.c_str(), O_RDWR | O_CREAT | O_EXCL, 0600);
  const bool creator = fd >= 0;
  if (!creator && errno == EEXIST) fd = shm_open(name.c_str(), O_RDWR, 0600);
  if (fd < 0) throw ChainChannelError(errnoText("cannot open the shared-memory segment", name));
  try {
    memory_ = creator ? create(fd) : attach(fd);
  } catch (...) {
    close(fd);
    throw;
  }
  close(fd);
  slots_ = reinterpret_cast<Slot*>(static_cast<unsigned char*>(memory_) + kHeaderBytes);
}

void* ChainChannel::create(int fd) {
  const std::size_t bytes = segmentBytes();
  // Reserve every page now: on a full /dev/shm a mapping that was only truncated faults (SIGBUS) at a write.
  const int err = ftruncate(fd, static_cast<off_t>(bytes)) != 0 ? errno : posix_fallocate(fd, 0, static_cast<off_t>(bytes));
  void* memory = err == 0 ? mapSegment(fd) : nullptr;
  if (!memory) {
    const int why = err ? err : errno;
    shm_unlink(name_.c_str());
    throw ChainChannelError("cannot reserve " + megabytes(bytes) + " for the shared-memory segment " + name_ +
                            " in /dev/shm: " + std::strerror(why) +
                            (why == ENOSPC ? " (free space in /dev/shm, or run with --chain-transport dds)" : ""));
  }
  auto* header = static_cast<Header*>(memory);
  header->version = kVersion;
  header->bytes = bytes;
  header->creator_pid = getpid();
  header->stack_pid = getppid();
  header->magic.store(kMagic, std::memory_order_release);
  return memory;
}

void* ChainChannel::attach(int fd) {
  const std::string refuse = "the shared-memory segment " + name_ + " (/dev/shm" + name_ + ") ";
  const std::string remedy = ": not this stack's chain segment (stale or foreign); remove it or choose another name";
  struct stat st {};
  if (fstat(fd, &st) != 0) throw ChainChannelError(errnoText("cannot inspect the shared-memory segment", name_));
  // The creator truncates to the full size, reserves, then writes the header (magic last): an empty segment or
  // a zero magic may be one being made (waited for, bounded); any other size or magic is not a chain segment.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (st.st_size == 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    if (fstat(fd, &st) != 0) throw ChainChannelError(errnoText("cannot inspect the shared-memory segment", name_));
  }
  if (static_cast<std::size_t>(st.st_size) != segmentBytes())
    throw ChainChannelError(refuse + "has " + std::to_string(st.st_size) + " bytes, not " +
                            std::to_string(segmentBytes()) + remedy);
  void* memory = mapSegment(fd);
  if (!memory) throw ChainChannelError(errnoText("cannot map the shared-memory segment", name_));
  auto* header = static_cast<Header*>(memory);
  while (header->magic.load(std::memory_order_acquire) == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  std::string wrong;
  if (header->magic.load(std::memory_order_acquire) != kMagic)
    wrong = "has no chain header";
  else if (header->version != kVersion || header->bytes != segmentBytes())
    wrong = "has layout version " + std::to_string(header->version) + ", not " + std::to_string(kVersion);
  else if (!processAlive(header->stack_pid) && !processAlive(header->creator_pid))
    wrong = "was made under process " + std::to_string(header->stack_pid) + ", which is gone";
  if (!wrong.empty()) {
    munmap(memory, segmentBytes());
    throw ChainChannelError(refuse + wrong + remedy);
  }
  return memory;
}

ChainChannel::~ChainChannel() {
  if (memory_) munmap(memory_, segmentBytes());
}

void ChainChannel::unlinkName() const { shm_unlink(name_.c_str()); }

ChainSlotWriter::ChainSlotWriter(ChainChannel& channel, int slot_index) : slot_(channel.slot(slot_index)) {
  slot_.writers.fetch_add(1);
}

ChainSlotWriter::~ChainSlotWriter() { slot_.writers.fetch_sub(1); }

void ChainSlotWriter::write(const unsigned char* bytes, std::size_t size) {
  if (size > ChainChannel::kSlotBytes) throw ChainChannelError("a chain sample is larger than its slot");
  const std::uint32_t n = slot_.head.load(std::memory_order_relaxed);
  ChainChannel::Entry& entry = slot_.ring[n % ChainChannel::kRing];
  entry.seq.store(2 * n + 1, std::memory_order_relaxed);  // odd: a reader copying this entry now retries
  std::atomic_thread_fence(std::memory_order_release);
  std::memcpy(entry.data, bytes, size);
  entry.size.store(static_cast<std::uint32_t>(size), std::memory_order_relaxed);
  entry.seq.store(2 * n + 2, std::memory_order_release);
  slot_.head.store(n + 1, std::memory_order_seq_cst);
  // seq_cst store then load, against the reader's seq_cst increment then load: one of the two sees the other.
  if (slot_.sleepers.load(std::memory_order_seq_cst) > 0) futexWakeAll(&slot_.head);
}

namespace {
std::uint64_t idWord(const ChainChannel::EndpointId& id, int half) {
  std::uint64_t w = 0;
  std::memcpy(&w, id.data() + 8 * half, 8);
  return w;
}
}  // namespace

int addEndpoint(ChainChannel::EndpointList& list, const ChainChannel::EndpointId& id) {
  const int place = static_cast<int>(list.added.fetch_add(1) % ChainChannel::kEndpoints);
  list.id[place][0].store(idWord(id, 0));
  list.id[place][1].store(idWord(id, 1));
  list.version.fetch_add(1);
  return place;
}

void removeEndpoint(ChainChannel::EndpointList& list, int place, const ChainChannel::EndpointId& id) {
  if (place < 0 || place >= ChainChannel::kEndpoints) return;
  if (list.id[place][0].load() != idWord(id, 0) || list.id[place][1].load() != idWord(id, 1)) return;
  list.id[place][0].store(0);
  list.id[place][1].store(0);
  list.version.fetch_add(1);
}

bool hasEndpoint(const ChainChannel::EndpointList& list, const ChainChannel::EndpointId& id) {
  const std::uint64_t w0 = idWord(id, 0), w1 = idWord(id, 1);
  if (w0 == 0 && w1 == 0) return false;
  for (const auto& entry : list.id)
    if (entry[0].load(std::memory_order_acquire) == w0 && entry[1].load(std::memory_order_acquire) == w1) return true;
  return false;
}

long copyChainSample(const ChainChannel::Slot& slot, std::uint32_t n, unsigned char* buffer) {
  const ChainChannel::Entry& entry = slot.ring[n % ChainChannel::kRing];
  if (entry.seq.load(std::memory_order_acquire) != 2 * n + 2) return -1;
  const std::uint32_t size = entry.size.load(std::memory_order_relaxed);
  if (size > ChainChannel::kSlotBytes) return -1;
  std::memcpy(buffer, entry.data, size);
  std::atomic_thread_fence(std::memory_order_acquire);
  if (entry.seq.load(std::memory_order_relaxed) != 2 * n + 2) return -1;  // overwritten while copying
  return static_cast<long>(size);
}

ChainSlotReader::ChainSlotReader(ChainChannel& channel, int slot_index, Deliver deliver, Delivery delivery)
    : slot_(channel.slot(slot_index)), deliver_(std::move(deliver)) {
  last_head_ = slot_.head.load();  // what is there now is an earlier stack's tick: not delivered
  slot_.readers.fetch_add(1);
  if (delivery == Delivery::Woken) thread_ = std::thread([this] { run(); });
}

ChainSlotReader::~ChainSlotReader() {
  if (thread_.joinable()) {
    stop_ = true;
    futexWakeAll(&slot_.head);  // a spurious wake-up for the slot's other readers: they look and sleep again
    thread_.join();
  }
  slot_.readers.fetch_sub(1);
}

ChainSlotReader::Take ChainSlotReader::take(std::uint32_t head) {
  if (head == last_head_) return Take::Nothing;
  const long size = copyChainSample(slot_, head - 1, buffer_);
  if (size < 0) {  // lapped while copying (a writer far ahead): take the newer one
    torn_.fetch_add(1, std::memory_order_relaxed);
    return Take::Torn;
  }
  last_head_ = head;
  deliver_(buffer_, static_cast<std::size_t>(size));
  return Take::Delivered;
}

bool ChainSlotReader::poll() {
  if (thread_.joinable()) return false;
  for (;;) {
    const Take t = take(slot_.head.load(std::memory_order_acquire));
    if (t != Take::Torn) return t == Take::Delivered;
  }
}

void ChainSlotReader::sleepWhile(std::uint32_t head, const struct timespec* timeout) {
  slot_.sleepers.fetch_add(1, std::memory_order_seq_cst);
  if (slot_.head.load(std::memory_order_seq_cst) == head && !stop_.load())
    futexWait(&slot_.head, head, timeout);  // returns at once if head moved on meanwhile
  slot_.sleepers.fetch_sub(1, std::memory_order_seq_cst);
}

bool ChainSlotReader::awaitNew(std::chrono::nanoseconds timeout) {
  if (thread_.joinable()) return false;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const std::uint32_t head = slot_.head.load(std::memory_order_acquire);
    const Take t = take(head);
    if (t == Take::Delivered) return true;
    if (t == Take::Torn) continue;
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    const timespec ts{static_cast<time_t>(left.count() / 1000000000), static_cast<long>(left.count() % 1000000000)};
    sleepWhile(head, &ts);
  }
}

void ChainSlotReader::run() {
  enterLoopThread();  // a 1 kHz thread of the chain (realtime: SCHED_FIFO on the chain's core; else nothing)
  const timespec poll_stop{0, 100 * 1000 * 1000};  // the longest a stopping reader sleeps on
  while (!stop_.load(std::memory_order_relaxed)) {
    const std::uint32_t head = slot_.head.load(std::memory_order_acquire);
    if (take(head) == Take::Nothing) sleepWhile(head, &poll_stop);
  }
}

ChainSlotArchive::ChainSlotArchive(ChainChannel& channel, int slot_index)
    : slot_(channel.slot(slot_index)), cursor_(slot_.head.load()) {
  slot_.readers.fetch_add(1);
}

ChainSlotArchive::~ChainSlotArchive() { slot_.readers.fetch_sub(1); }

std::uint64_t ChainSlotArchive::drain(const Deliver& deliver, std::uint64_t max_samples) {
  const std::uint32_t head = slot_.head.load(std::memory_order_acquire);
  if (head - cursor_ > ChainChannel::kRing) {  // lapped: the oldest entries are gone
    lost_ += head - cursor_ - ChainChannel::kRing;
    cursor_ = head - ChainChannel::kRing;
  }
  std::uint64_t delivered = 0;
  for (; cursor_ != head && delivered < max_samples; ++cursor_) {
    const long size = copyChainSample(slot_, cursor_, buffer_);
    if (size < 0) {
      ++lost_;
      continue;
    }
    deliver(buffer_, static_cast<std::size_t>(size));
    ++delivered;
  }
  return delivered;
}

}  // namespace mft::services
