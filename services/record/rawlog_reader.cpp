#include "services/record/rawlog_reader.hpp"

#include <mrpt/obs/CObservationComment.h>
#include <mrpt/serialization/CSerializable.h>
#include <zlib.h>

#include <cctype>

namespace mft::rawlog {

namespace {

// Looks at the first bytes before handing the file to MRPT: its deserializer trusts length fields, so an
// arbitrary file could make it allocate wildly. An MRPT object starts with 0x80 | strlen(class name) and the
// class name; ours must be the metadata comment.
void checkHeader(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw NotMftRawlog(path + ": cannot open");
  unsigned char buf[64] = {};
  const int n = gzread(f, buf, sizeof buf);
  gzclose(f);
  static const std::string expected = "mrpt::obs::CObservationComment";
  if (n <= 0) throw NotMftRawlog(path + ": empty file, not a rawlog");
  const unsigned len = buf[0] & 0x7fu;
  const bool mrpt_object = (buf[0] & 0x80u) && len > 0 && static_cast<int>(len) < n &&
                           std::all_of(buf + 1, buf + 1 + len, [](unsigned char c) { return std::isgraph(c); });
  if (!mrpt_object)
    throw NotMftRawlog(path + ": not an MRPT rawlog (it does not start with a serialized MRPT object)");
  const std::string cls(reinterpret_cast<const char*>(buf + 1), len);
  if (cls != expected)
    throw NotMftRawlog(path + ": an MRPT rawlog, but not an mft rawlog: its first object is " + cls +
                       ", not the metadata comment (rawlog-edit --info -i FILE shows what it holds)");
}

}  // namespace

const char* toString(RawlogReader::End e) {
  switch (e) {
    case RawlogReader::End::None: return "none";
    case RawlogReader::End::Clean: return "complete";
    case RawlogReader::End::Truncated: return "truncated";
    case RawlogReader::End::Corrupt: return "corrupt";
  }
  return "?";
}

RawlogReader::RawlogReader(const std::string& path) : path_(path) {
  checkHeader(path);
  try {
    stream_.open(path);
  } catch (const std::exception& e) {
    throw NotMftRawlog(e.what());
  }
  archive_ = mrpt::serialization::archiveUniquePtrFrom(stream_);
  mrpt::serialization::CSerializable::Ptr first;
  try {
    *archive_ >> first;
  } catch (const std::exception& e) {
    throw NotMftRawlog(path + ": cannot read the metadata comment: " + std::string(e.what()).substr(0, 200));
  }
  const auto comment = std::dynamic_pointer_cast<mrpt::obs::CObservationComment>(first);
  if (!comment) throw NotMftRawlog(path + ": the first object is not the metadata comment");
  try {
    metadata_ = parseMetadata(comment->text);
  } catch (const std::exception& e) {
    throw NotMftRawlog(path + ": " + e.what());
  }
  ++objects_;
}

bool RawlogReader::next(mrpt::obs::CObservation::Ptr* obs) {
  while (end_ == End::None) {
    const std::uint64_t before = stream_.getPosition();
    mrpt::serialization::CSerializable::Ptr o;
    try {
      *archive_ >> o;
    } catch (const std::exception& e) {
      const bool partial = stream_.getPosition() != before;
      if (stream_.corrupt()) {
        end_ = End::Corrupt;
        end_detail_ = "zlib: " + stream_.error();
      } else if (stream_.eof() && !partial && !stream_.truncated()) {
        end_ = End::Clean;
      } else if (stream_.eof()) {
        end_ = End::Truncated;
        end_detail_ = partial ? "the last record is incomplete" : "the gzip stream has no end (the recorder did not close it)";
      } else {
        end_ = End::Corrupt;
        std::string what = e.what();
        const auto nl = what.find('\n');
        end_detail_ = what.substr(0, std::min<std::size_t>(nl == std::string::npos ? what.size() : nl, 160));
      }
      return false;
    }
    ++objects_;
    auto ob = std::dynamic_pointer_cast<mrpt::obs::CObservation>(o);
    if (!ob || std::dynamic_pointer_cast<mrpt::obs::CObservationComment>(o)) {
      ++skipped_;
      continue;
    }
    *obs = std::move(ob);
    return true;
  }
  return false;
}

std::string RawlogReader::endMessage() const {
  const std::string n = std::to_string(objects_) + " whole objects read";
  switch (end_) {
    case End::None: return "not read to the end";
    case End::Clean: return "complete (" + n + ")";
    case End::Truncated: return "truncated: " + end_detail_ + "; " + n + " (everything up to the last whole record)";
    case End::Corrupt:
      return "corrupt after " + n + " (" + std::to_string(stream_.getPosition()) +
             " bytes decompressed): " + end_detail_;
  }
  return "";
}

}  // namespace mft::rawlog
