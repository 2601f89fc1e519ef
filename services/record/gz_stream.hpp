#pragma once
// gzip streams for rawlogs on zlib directly, as mrpt::io::CStream subclasses so CArchive can use them.
//  * GzWriteStream: CFileGZOutputStream has no flush(), so a crash loses up to one zlib buffer, unbounded in
//    time (docs/reference/mrpt.md#write-stalls-and-flushing). This one calls gzflush(Z_SYNC_FLUSH) on request: the file is then readable
//    up to that point by MRPT's own reader and rawlog-edit even without the gzip trailer.
//  * GzReadStream: CFileGZInputStream hides zlib's errors; this one keeps them, so a reader can tell a clean
//    end from a truncated file (no gzip trailer) and from corrupt data.
#include <mrpt/io/CStream.h>

#include <cstdint>
#include <string>

namespace mft::rawlog {

class GzWriteStream : public mrpt::io::CStream {
 public:
  GzWriteStream() = default;
  ~GzWriteStream() override { close(); }
  // Throws std::runtime_error if the file cannot be created. level: 0 (stored) .. 9.
  void open(const std::string& path, int level);
  void close();
  bool isOpen() const { return file_ != nullptr; }
  // Z_SYNC_FLUSH: everything written so far reaches the file in a decodable form.
  void flush();
  std::uint64_t uncompressedBytes() const { return written_; }
  std::uint64_t compressedBytes() const;  // bytes in the file so far (up to the last flush)

  size_t Read(void*, size_t) override;
  size_t Write(const void* buf, size_t n) override;
  uint64_t Seek(int64_t, mrpt::io::CStream::TSeekOrigin) override;
  uint64_t getTotalBytesCount() const override { return written_; }
  uint64_t getPosition() const override { return written_; }

 private:
  void* file_ = nullptr;  // gzFile
  std::uint64_t written_ = 0;
};

class GzReadStream : public mrpt::io::CStream {
 public:
  GzReadStream() = default;
  ~GzReadStream() override;
  // Throws std::runtime_error if the file cannot be opened. Plain (uncompressed) files pass through.
  void open(const std::string& path);
  // The decompressed data is exhausted (nothing left peeked either).
  bool eof() const { return eof_ && lookahead_pos_ >= lookahead_.size(); }
  // zlib's complaint, if any: "unexpected end of file" for a missing trailer, a data error for corruption.
  bool truncated() const { return truncated_; }
  bool corrupt() const { return corrupt_; }
  const std::string& error() const { return error_; }
  std::uint64_t compressedPosition() const;
  std::uint64_t fileSize() const { return file_size_; }
  // The next `n` decompressed bytes without consuming them (fewer at the end of the data): the reader bounds
  // every length of the next object with them before MRPT allocates what the lengths declare.
  std::size_t peek(std::size_t n, const unsigned char** data);

  size_t Read(void* buf, size_t n) override;
  size_t Write(const void*, size_t) override;
  uint64_t Seek(int64_t, mrpt::io::CStream::TSeekOrigin) override;
  uint64_t getTotalBytesCount() const override { return file_size_; }
  uint64_t getPosition() const override { return read_; }

 private:
  std::size_t readFromFile(void* buf, std::size_t n);

  void* file_ = nullptr;
  std::uint64_t read_ = 0, file_size_ = 0;
  std::string lookahead_;       // decompressed bytes peeked but not yet read
  std::size_t lookahead_pos_ = 0;
  bool eof_ = false, truncated_ = false, corrupt_ = false;
  std::string error_;
};

}  // namespace mft::rawlog
