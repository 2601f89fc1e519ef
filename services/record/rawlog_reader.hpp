#pragma once
// Streaming reader of mft rawlogs: checks that the file is one (first object = mft metadata comment of a
// supported schema version) before anything else, then yields observations one by one and tells how the
// file ended: cleanly, truncated (a recorder killed mid-write: everything up to the last whole record is
// read), or corrupt (reading stops at the damage). Never loads the whole file (docs/reference/mrpt.md#reading-as-a-stream).
#include <mrpt/obs/CObservation.h>
#include <mrpt/serialization/CArchive.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "services/record/gz_stream.hpp"
#include "services/record/rawlog_format.hpp"

namespace mft::rawlog {

// The file is not an mft rawlog (or of an unsupported schema): what() is the message for the user, with the
// file's own bytes it quotes made printable.
class NotMftRawlog : public std::runtime_error {
 public:
  explicit NotMftRawlog(const std::string& message);
};

class RawlogReader {
 public:
  enum class End { None, Clean, Truncated, Corrupt };

  // Throws NotMftRawlog with a clear message.
  explicit RawlogReader(const std::string& path);
  const Metadata& metadata() const { return metadata_; }
  const std::string& path() const { return path_; }

  // The next observation (other objects are skipped and counted); false at the end of the readable data.
  bool next(mrpt::obs::CObservation::Ptr* obs);
  End end() const { return end_; }
  // One line for the user: "complete", "truncated: ...", "corrupt: ...".
  std::string endMessage() const;
  std::uint64_t objects() const { return objects_; }  // whole objects read, metadata included
  std::uint64_t skipped() const { return skipped_; }
  std::uint64_t fileSize() const { return stream_.fileSize(); }
  std::uint64_t compressedPosition() const { return stream_.compressedPosition(); }

 private:
  std::string path_;
  GzReadStream stream_;
  std::unique_ptr<mrpt::serialization::CArchive> archive_;
  Metadata metadata_;
  End end_ = End::None;
  std::string end_detail_;
  std::uint64_t objects_ = 0, skipped_ = 0;
};

const char* toString(RawlogReader::End e);

}  // namespace mft::rawlog
