#include "services/record/gz_stream.hpp"

#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace mft::rawlog {

void GzWriteStream::open(const std::string& path, int level) {
  close();
  const std::string mode = "wb" + std::to_string(level);
  file_ = gzopen(path.c_str(), mode.c_str());
  if (!file_) throw std::runtime_error("cannot create " + path);
  gzbuffer(static_cast<gzFile>(file_), 128 * 1024);
  written_ = 0;
}

void GzWriteStream::close() {
  if (file_) gzclose(static_cast<gzFile>(file_));  // writes the gzip trailer
  file_ = nullptr;
}

void GzWriteStream::flush() {
  // A failed flush (a full disk) must be an error: the recorder reports what it flushed as kept.
  if (file_ && gzflush(static_cast<gzFile>(file_), Z_SYNC_FLUSH) != Z_OK)
    throw std::runtime_error("gzflush failed (disk full?)");
}

std::uint64_t GzWriteStream::compressedBytes() const {
  return file_ ? static_cast<std::uint64_t>(gzoffset(static_cast<gzFile>(file_))) : 0;
}

size_t GzWriteStream::Read(void*, size_t) { throw std::runtime_error("GzWriteStream: Read"); }

size_t GzWriteStream::Write(const void* buf, size_t n) {
  if (!file_ || n == 0) return 0;
  const int w = gzwrite(static_cast<gzFile>(file_), buf, static_cast<unsigned>(n));
  if (w <= 0) throw std::runtime_error("gzwrite failed (disk full?)");
  written_ += static_cast<std::uint64_t>(w);
  return static_cast<size_t>(w);
}

uint64_t GzWriteStream::Seek(int64_t, mrpt::io::CStream::TSeekOrigin) { throw std::runtime_error("GzWriteStream: Seek"); }

GzReadStream::~GzReadStream() {
  if (file_) gzclose(static_cast<gzFile>(file_));
}

void GzReadStream::open(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw std::runtime_error(path + ": no such file");
  file_size_ = std::filesystem::file_size(path, ec);
  file_ = gzopen(path.c_str(), "rb");
  if (!file_) throw std::runtime_error("cannot open " + path);
  gzbuffer(static_cast<gzFile>(file_), 256 * 1024);
}

std::uint64_t GzReadStream::compressedPosition() const {
  return file_ ? static_cast<std::uint64_t>(gzoffset(static_cast<gzFile>(file_))) : 0;
}

std::size_t GzReadStream::readFromFile(void* buf, std::size_t n) {
  if (!file_ || eof_ || n == 0) return 0;
  const int r = gzread(static_cast<gzFile>(file_), buf, static_cast<unsigned>(n));
  int errnum = Z_OK;
  const char* msg = gzerror(static_cast<gzFile>(file_), &errnum);
  const bool failed = errnum != Z_OK && errnum != Z_STREAM_END;
  // zlib flags a truncated stream (Z_BUF_ERROR) as soon as its read-ahead reaches the end of the file, while
  // up to 2 x gzbuffer of decoded data is still waiting in its buffer: the end is only where gzread returns
  // short. Stopping at the flag lost the last ~0.1 s of a recording cut by a crash or a full disk.
  if (r < 0 || static_cast<std::size_t>(r) < n) {
    eof_ = true;
    if (r < 0 || failed) {
      if (errnum == Z_BUF_ERROR) truncated_ = true;  // "unexpected end of file"
      else corrupt_ = true;
      error_ = msg ? msg : "zlib error";
    }
  }
  return r > 0 ? static_cast<std::size_t>(r) : 0;
}

std::size_t GzReadStream::peek(std::size_t n, const unsigned char** data) {
  if (lookahead_pos_ > 0) {
    lookahead_.erase(0, lookahead_pos_);
    lookahead_pos_ = 0;
  }
  if (lookahead_.size() < n && !eof_) {
    const std::size_t have = lookahead_.size();
    lookahead_.resize(n);
    lookahead_.resize(have + readFromFile(&lookahead_[have], n - have));
  }
  *data = reinterpret_cast<const unsigned char*>(lookahead_.data());
  return std::min(n, lookahead_.size());
}

size_t GzReadStream::Read(void* buf, size_t n) {
  std::size_t got = 0;
  if (lookahead_pos_ < lookahead_.size()) {
    got = std::min(n, lookahead_.size() - lookahead_pos_);
    std::memcpy(buf, lookahead_.data() + lookahead_pos_, got);
    lookahead_pos_ += got;
  }
  if (got < n) got += readFromFile(static_cast<char*>(buf) + got, n - got);
  read_ += got;
  return got;
}

size_t GzReadStream::Write(const void*, size_t) { throw std::runtime_error("GzReadStream: Write"); }
uint64_t GzReadStream::Seek(int64_t, mrpt::io::CStream::TSeekOrigin) { throw std::runtime_error("GzReadStream: Seek"); }

}  // namespace mft::rawlog
