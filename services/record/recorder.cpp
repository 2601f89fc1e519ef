#include "services/record/recorder.hpp"

#include <mrpt/obs/CObservationComment.h>
#include <mrpt/serialization/CArchive.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "services/record/gz_stream.hpp"
#include "common/tool_io.hpp"

namespace mft::rawlog {

namespace {
std::int64_t steadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
std::int64_t unixNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}
}  // namespace

std::string pieceName(const std::string& output, int piece) {
  if (piece == 0) return output;
  const std::filesystem::path p(output);
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, ".part%03d", piece);
  return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
}

std::string sidecarName(const std::string& rawlog) { return rawlog + ".yaml"; }

struct Recorder::Output {
  GzWriteStream stream;
  std::unique_ptr<mrpt::serialization::CArchive> archive;
  std::string path;
  bool metadata_written = false;
};

Recorder::Recorder(RecorderOptions options) : opt_(std::move(options)) {
  ring_.resize(opt_.queue_capacity);
  batch_.reserve(opt_.queue_capacity);
  stats_.label_objects.assign(labels().size(), 0);
  piece_label_objects_.assign(labels().size(), 0);
}

Recorder::~Recorder() { stop(); }

void Recorder::start() {
  out_ = std::make_unique<Output>();
  openPiece(opt_.first_piece);  // throws if the file cannot be created: the service then fails before READY
  started_ = true;
  writer_ = std::thread([this] { writerLoop(); });
}

void Recorder::push(const Message& m) {
  const Topic t = topicOf(m);
  std::uint64_t stamp;
  if (hasTick(t)) {
    stamp = stampOf(m);
    std::uint64_t prev = newest_stamp_.load(std::memory_order_relaxed);
    while (stamp > prev && !newest_stamp_.compare_exchange_weak(prev, stamp)) {
    }
  } else {
    stamp = newest_stamp_.load();  // events have no clock of their own: the newest simulator time seen
  }
  const std::int64_t now = steadyNs();
  last_push_ns_.store(now, std::memory_order_relaxed);
  std::lock_guard<std::mutex> lock(mutex_);
  auto& c = stats_.topics[static_cast<std::size_t>(t)];
  ++c.received;
  if (count_ == ring_.size()) {
    ++c.dropped_queue;  // the writer is behind: drop and count, never block the DDS thread
    return;
  }
  Sample& slot = ring_[(head_ + count_) % ring_.size()];
  slot.msg = m;
  slot.stamp_ns = stamp;
  slot.arrival_ns = now;
  slot.seq = push_seq_++;
  ++count_;
  stats_.max_queue_depth = std::max(stats_.max_queue_depth, count_);
}

void Recorder::stop() {
  if (!started_ || stopped_) return;
  stopped_ = true;
  stop_ = true;
  if (writer_.joinable()) writer_.join();
}

void Recorder::writerLoop() {
  // gzip calls stall for up to milliseconds (docs/reference/mrpt.md#write-stalls-and-flushing). Under SCHED_FIFO (realtime stacks) this
  // thread runs at FIFO priority 1: below every control thread (80), which it never delays, yet above the
  // machine's ordinary load, which could otherwise starve it past the flush period (crash loss). Otherwise at
  // nice 0 even if the service is niced: it needs little CPU, but promptly.
  writer_tid_ = static_cast<int>(syscall(SYS_gettid));
  if (sched_getscheduler(0) == SCHED_FIFO) {
    sched_param sp{};
    sp.sched_priority = 1;
    pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  } else {
    setpriority(PRIO_PROCESS, static_cast<id_t>(writer_tid_.load()), 0);
  }
  try {
    while (true) {
      const bool stopping = stop_.load();
      batch_.clear();
      {
        std::lock_guard<std::mutex> lock(mutex_);
        for (; count_ > 0; --count_) {
          batch_.push_back(ring_[head_]);
          head_ = (head_ + 1) % ring_.size();
        }
      }
      const std::int64_t t0 = steadyNs();
      for (auto& s : batch_) {
        if (hasTick(topicOf(s.msg))) newest_seen_ = std::max(newest_seen_, s.stamp_ns);
        pending_.emplace(Key{s.stamp_ns, static_cast<int>(s.msg.index()), s.seq}, std::move(s));
      }
      const bool had_work = !pending_.empty() || dirty_;
      release(stopping, t0);
      const std::int64_t now = steadyNs();
      // Aim 10 % early: the loop polls every 2 ms and may be descheduled on a busy machine.
      if (dirty_ && now - dirty_since_ns_ >= static_cast<std::int64_t>(opt_.flush_period_s * 0.9e9)) flush(now);
      if (had_work) {
        std::lock_guard<std::mutex> lock(stats_mutex_);
        stats_.writer_busy_s += static_cast<double>(steadyNs() - t0) * 1e-9;
      }
      if (stopping) break;
      if (batch_.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    closePiece(true);
  } catch (const std::exception& e) {
    // MRPT wraps the message in a banner and a backtrace: keep the message line only.
    std::string what = e.what(), line;
    std::istringstream lines(what);
    while (std::getline(lines, line))
      if (!line.empty() && line.rfind("====", 0) != 0) break;
    {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      stats_.error = line.empty() ? what : line;
    }
    std::fprintf(stderr, "mft-record: writer stopped: %s; what was flushed until then stays readable\n", line.c_str());
    // The stack goes on: keep emptying the queue (counted) so that nothing waits on the recorder.
    while (!stop_.load()) {
      {
        std::scoped_lock lock(mutex_, stats_mutex_);
        stats_.dropped_after_error += count_;
        head_ = (head_ + count_) % ring_.size();
        count_ = 0;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
}

void Recorder::release(bool all, std::int64_t now_ns) {
  while (!pending_.empty()) {
    auto it = pending_.begin();
    const Sample& s = it->second;
    const bool ripe = all || s.stamp_ns + static_cast<std::uint64_t>(opt_.reorder_window_ns) <= newest_seen_ ||
                      now_ns - s.arrival_ns >= opt_.max_hold_ns;
    if (!ripe) break;
    writeSample(s);
    pending_.erase(it);
  }
}

void Recorder::writeSample(const Sample& s) {
  const Topic t = topicOf(s.msg);
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    auto& c = stats_.topics[static_cast<std::size_t>(t)];
    if (hasTick(t)) {
      const std::uint64_t tick = tickOf(s.msg);
      if (c.any && tick == c.last_tick) {
        ++c.repeated;  // a re-sent tick (lockstep start-up re-sends tick 0): recorded once
        return;
      }
      if (c.any && tick < c.last_tick) {
        ++c.out_of_order;
      } else {
        if (c.any && tick > c.last_tick + 1) c.tick_gaps += tick - c.last_tick - 1;
        if (!c.any) c.first_tick = tick;
        c.last_tick = tick;
      }
    } else {
      if (!c.any) c.first_tick = tickOf(s.msg);
      c.last_tick = tickOf(s.msg);
    }
    c.any = true;
  }
  const auto stamp = static_cast<std::int64_t>(s.stamp_ns);
  if (!have_time_base_) {
    // Stamps are wall clock at the first sample + simulator time (docs/reference/mrpt.md#timestamps: never UNIX 0), whole ms.
    // From the sample's arrival, not from now: it may have waited in the reorder window.
    const std::int64_t arrival_unix = unixNs() - (steadyNs() - s.arrival_ns);
    opt_.metadata.time_base_unix_ns = (arrival_unix - stamp) / 1'000'000 * 1'000'000;
    have_time_base_ = true;
  }
  const bool split_due = (opt_.split_mb > 0 && static_cast<double>(out_->stream.compressedBytes()) >= opt_.split_mb * 1e6) ||
                         (opt_.split_s > 0 && piece_first_stamp_ >= 0 &&
                          static_cast<double>(stamp - piece_first_stamp_) * 1e-9 >= opt_.split_s);
  if (split_due && out_->metadata_written && stamp > piece_last_stamp_) {  // only between ticks
    closePiece(false);
    openPiece(piece_ + 1);
  }
  if (!out_->metadata_written) {
    mrpt::obs::CObservationComment c;
    opt_.metadata.piece = piece_;
    c.text = metadataYaml(opt_.metadata);
    c.timestamp = toMrptTime(opt_.metadata.time_base_unix_ns);
    *out_->archive << c;
    out_->metadata_written = true;
    writeSidecar(false);
  }
  const auto& idx = encoder_.encode(s.msg, opt_.metadata.time_base_unix_ns + stamp);
  for (int li : idx) *out_->archive << encoder_.observation(li);
  if (!dirty_) dirty_since_ns_ = steadyNs();
  dirty_ = true;
  if (piece_first_stamp_ < 0) piece_first_stamp_ = stamp;
  piece_last_stamp_ = std::max(piece_last_stamp_, stamp);
  std::lock_guard<std::mutex> lock(stats_mutex_);
  auto& c = stats_.topics[static_cast<std::size_t>(t)];
  ++c.written;
  for (int li : idx) {
    ++stats_.label_objects[static_cast<std::size_t>(li)];
    ++piece_label_objects_[static_cast<std::size_t>(li)];
  }
  stats_.objects += idx.size();
  if (stats_.first_stamp_ns < 0) stats_.first_stamp_ns = stamp;
  stats_.last_stamp_ns = std::max(stats_.last_stamp_ns, stamp);
  stats_.uncompressed_bytes = uncompressed_closed_ + out_->stream.uncompressedBytes();
}

void Recorder::flush(std::int64_t now_ns) {
  out_->stream.flush();
  dirty_ = false;
  std::lock_guard<std::mutex> lock(stats_mutex_);
  ++stats_.flushes;
  stats_.flushed_stamp_ns = stats_.last_stamp_ns;
  // How long the oldest written byte waited for this flush: what a crash just before it would have lost.
  stats_.max_flush_interval_s = std::max(stats_.max_flush_interval_s, static_cast<double>(now_ns - dirty_since_ns_) * 1e-9);
}

void Recorder::openPiece(int piece) {
  piece_ = piece;
  out_->path = pieceName(opt_.output, piece);
  out_->stream.open(out_->path, opt_.gzip_level);
  out_->archive = mrpt::serialization::archiveUniquePtrFrom(out_->stream);
  out_->metadata_written = false;
  piece_first_stamp_ = piece_last_stamp_ = -1;
  piece_label_objects_.assign(labels().size(), 0);
  std::lock_guard<std::mutex> lock(stats_mutex_);
  stats_.pieces.push_back(out_->path);
}

void Recorder::closePiece(bool final) {
  if (!out_->stream.isOpen()) return;
  if (!out_->metadata_written) {  // nothing arrived: still a valid (empty) mft rawlog
    if (!have_time_base_) opt_.metadata.time_base_unix_ns = unixNs() / 1'000'000 * 1'000'000;
    have_time_base_ = true;
    mrpt::obs::CObservationComment c;
    opt_.metadata.piece = piece_;
    c.text = metadataYaml(opt_.metadata);
    c.timestamp = toMrptTime(opt_.metadata.time_base_unix_ns);
    *out_->archive << c;
    out_->metadata_written = true;
  }
  const std::uint64_t uncompressed = out_->stream.uncompressedBytes();
  out_->archive.reset();
  out_->stream.close();
  std::error_code ec;
  const auto size = std::filesystem::file_size(out_->path, ec);
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    stats_.compressed_bytes += ec ? 0 : size;
    uncompressed_closed_ += uncompressed;
    stats_.uncompressed_bytes = uncompressed_closed_;
  }
  (void)final;
  writeSidecar(true);
}

void Recorder::writeSidecar(bool complete) {
  opt_.metadata.piece = piece_;
  std::ostringstream y;
  y << metadataYaml(opt_.metadata);
  y << "recording:\n";
  y << "  status: " << (complete ? "complete" : "recording") << "\n";
  y << "  file: " << std::filesystem::path(out_->path).filename().string() << "\n";
  y << "  recorder_pid: " << getpid() << "\n";
  y << "  parent_pid: " << getppid() << "\n";
  if (complete) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    y << "  first_stamp_ns: " << piece_first_stamp_ << "\n";
    y << "  last_stamp_ns: " << piece_last_stamp_ << "\n";
    y << "  objects:\n";
    for (std::size_t i = 0; i < labels().size(); ++i)
      if (piece_label_objects_[i]) y << "    " << labels()[i].label << ": " << piece_label_objects_[i] << "\n";
  }
  const std::string path = sidecarName(out_->path);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp);
    f << y.str();
  }
  std::rename(tmp.c_str(), path.c_str());
}

RecorderStats Recorder::stats() const {
  std::scoped_lock lock(mutex_, stats_mutex_);
  return stats_;
}

void Recorder::writeSummary(config::JsonWriter& w) const {
  const RecorderStats s = stats();
  std::uint64_t dropped = 0, gaps = 0;
  w.key("topics").beginObject();
  for (std::size_t i = 0; i < kNumTopics; ++i) {
    const auto& c = s.topics[i];
    dropped += c.dropped_queue;
    if (hasTick(static_cast<Topic>(i))) gaps += c.tick_gaps;
    w.key(topicName(static_cast<Topic>(i))).beginObject().field("received", c.received).field("written", c.written);
    w.field("dropped_queue", c.dropped_queue).field("repeated", c.repeated).field("tick_gaps", c.tick_gaps);
    w.field("out_of_order", c.out_of_order).field("first", c.any ? static_cast<long long>(c.first_tick) : -1LL);
    w.field("last", c.any ? static_cast<long long>(c.last_tick) : -1LL).endObject();
  }
  w.endObject().key("labels").beginObject();
  for (std::size_t i = 0; i < labels().size(); ++i) w.field(labels()[i].label, s.label_objects[i]);
  w.endObject();
  const double sim_s = s.first_stamp_ns >= 0 ? static_cast<double>(s.last_stamp_ns - s.first_stamp_ns) * 1e-9 + 1e-3 : 0.0;
  w.field("dropped_samples", dropped + gaps).field("dropped_in_queue", dropped).field("tick_gaps", gaps);
  w.field("objects", s.objects).field("uncompressed_bytes", s.uncompressed_bytes).field("file_bytes", s.compressed_bytes);
  w.fixedField("recorded_sim_s", sim_s, 3);
  w.fixedField("mb_per_sim_minute", sim_s > 0 ? static_cast<double>(s.compressed_bytes) / 1e6 / (sim_s / 60.0) : 0.0, 3);
  w.fixedField("writer_busy_s", s.writer_busy_s, 3);
  w.fixedField("writer_objects_per_busy_s", s.writer_busy_s > 0 ? static_cast<double>(s.objects) / s.writer_busy_s : 0.0, 0);
  w.fixedField("writer_ticks_per_busy_s",
               s.writer_busy_s > 0 ? static_cast<double>(s.topics[0].written) / s.writer_busy_s : 0.0, 0);
  w.field("max_queue_depth", s.max_queue_depth).field("queue_capacity", opt_.queue_capacity).field("flushes", s.flushes);
  w.fixedField("max_unflushed_ms", s.max_flush_interval_s * 1e3, 1);
  w.fixedField("flushed_sim_s", static_cast<double>(s.flushed_stamp_ns) * 1e-9, 3);
  w.field("dropped_after_error", s.dropped_after_error).field("error", s.error);
  w.key("pieces").beginArray();
  for (const auto& piece : s.pieces) w.value(piece);
  w.endArray();
}

}  // namespace mft::rawlog
