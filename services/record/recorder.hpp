#pragma once
// The recorder's engine, independent of DDS: DDS callbacks push() messages into a bounded, preallocated
// queue (a copy under a short lock; a full queue drops and counts, never blocks), and one writer thread
// (docs/reference/mrpt.md#writing-from-one-thread: a CArchive is not thread-safe) sorts them by simulator time in a small reorder window,
// drops repeated ticks, encodes them as MRPT observations and writes the rawlog through a gzip stream that
// is flushed at least every flush period, so a crash loses at most that much. Optional split by size or
// duration into self-contained pieces (metadata repeated); a sidecar YAML per piece.
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "common/json_writer.hpp"
#include "services/record/rawlog_format.hpp"

namespace mft::rawlog {

struct RecorderOptions {
  std::string output;             // first piece; later pieces are <stem>.partNNN<ext>
  int first_piece = 0;            // > 0 after a restart: never overwrite what a crashed recorder left
  int gzip_level = 1;             // docs/reference/mrpt.md#compression-level
  double flush_period_s = 0.1;
  std::size_t queue_capacity = 1 << 16;
  double split_mb = 0.0;          // 0 = no split by size (compressed MB)
  double split_s = 0.0;           // 0 = no split by duration (simulated seconds)
  std::int64_t reorder_window_ns = 5'000'000;  // simulated time a sample waits for older ones
  std::int64_t max_hold_ns = 20'000'000;       // wall time a sample waits at most (the clock may pause)
  Metadata metadata;              // everything but time_base and piece
};

struct TopicCounters {
  std::uint64_t received = 0, written = 0, dropped_queue = 0, repeated = 0, tick_gaps = 0, out_of_order = 0;
  std::uint64_t first_tick = 0, last_tick = 0;
  bool any = false;
};

struct RecorderStats {
  std::array<TopicCounters, kNumTopics> topics{};
  std::vector<std::uint64_t> label_objects;  // per label
  std::uint64_t objects = 0, uncompressed_bytes = 0, compressed_bytes = 0, flushes = 0;
  std::size_t max_queue_depth = 0;
  double writer_busy_s = 0.0, max_flush_interval_s = 0.0;
  std::vector<std::string> pieces;
  std::int64_t first_stamp_ns = -1, last_stamp_ns = -1;
  std::int64_t flushed_stamp_ns = -1;          // newest stamp on disk at the last successful flush
  std::uint64_t dropped_after_error = 0;       // samples that arrived after the writer failed (e.g. disk full)
  std::string error;
};

// Name of piece n of `output` (piece 0 is `output` itself).
std::string pieceName(const std::string& output, int piece);
std::string sidecarName(const std::string& rawlog);

class Recorder {
 public:
  explicit Recorder(RecorderOptions options);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Creates the first piece (throws std::runtime_error if it cannot) and starts the writer thread.
  void start();
  // From any thread; never blocks on I/O.
  void push(const Message& m);
  // Drains the queue, closes the file (gzip trailer), completes the sidecar. Idempotent.
  void stop();
  RecorderStats stats() const;
  std::int64_t lastPushWallNs() const { return last_push_ns_.load(); }
  int writerThreadId() const { return writer_tid_.load(); }
  std::uint64_t newestStampNs() const { return newest_stamp_.load(); }
  // JSON object with the counters (for the service summary).
  void writeSummary(config::JsonWriter& w) const;

 private:
  struct Sample {
    Message msg;
    std::uint64_t stamp_ns = 0;
    std::int64_t arrival_ns = 0;
    std::uint64_t seq = 0;
  };
  using Key = std::tuple<std::uint64_t, int, std::uint64_t>;  // stamp, topic, arrival order

  void writerLoop();
  void release(bool all, std::int64_t now_ns);
  void writeSample(const Sample& s);
  void openPiece(int piece);
  void closePiece(bool final);
  void writeSidecar(bool complete);
  void flush(std::int64_t now_ns);

  RecorderOptions opt_;
  // queue (DDS threads -> writer)
  mutable std::mutex mutex_;
  std::vector<Sample> ring_;
  std::size_t head_ = 0, count_ = 0;
  std::uint64_t push_seq_ = 0;
  std::atomic<std::uint64_t> newest_stamp_{0};
  std::atomic<std::int64_t> last_push_ns_{0};
  std::atomic<bool> stop_{false};
  std::atomic<int> writer_tid_{0};
  std::thread writer_;
  bool started_ = false, stopped_ = false;

  // writer thread state
  std::map<Key, Sample> pending_;
  std::vector<Sample> batch_;
  std::uint64_t newest_seen_ = 0;
  ObservationEncoder encoder_;
  struct Output;
  std::unique_ptr<Output> out_;
  int piece_ = 0;
  bool have_time_base_ = false;
  std::int64_t piece_first_stamp_ = -1, piece_last_stamp_ = -1;
  std::int64_t dirty_since_ns_ = 0;  // when the first byte not yet flushed was written
  bool dirty_ = false;
  std::array<bool, kNumTopics> piece_has_{};
  std::vector<std::uint64_t> piece_label_objects_;
  std::uint64_t uncompressed_closed_ = 0;  // bytes of the pieces already closed

  mutable std::mutex stats_mutex_;  // guards stats_ between the writer and stats()
  RecorderStats stats_;
};

}  // namespace mft::rawlog
