#include "services/record/rawlog_reader.hpp"

#include <mrpt/obs/CObservationComment.h>
#include <mrpt/serialization/CSerializable.h>
#include <zlib.h>

#include <mrpt/obs/CObservationIMU.h>

#include "common/json_writer.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace mft::rawlog {

namespace {

std::string sizeText(std::uint64_t bytes) {
  char buf[48];
  if (bytes >= (1u << 20)) std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(bytes) / (1u << 20));
  else std::snprintf(buf, sizeof buf, "%llu bytes", static_cast<unsigned long long>(bytes));
  return buf;
}

// Looks at the file and its first bytes before handing it to MRPT: its deserializer trusts length fields, so
// an arbitrary file could make it allocate wildly. An MRPT object starts with 0x80 | strlen(class name) and
// the class name; ours must be the metadata comment. Each refusal says what the file is.
void checkHeader(const std::string& path) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(st)) throw NotMftRawlog(path + ": no such file");
  if (std::filesystem::is_directory(st)) throw NotMftRawlog(path + ": is a directory, not a rawlog");
  if (!std::filesystem::is_regular_file(st)) throw NotMftRawlog(path + ": not a regular file (a device, pipe or socket)");
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size == 0) throw NotMftRawlog(path + ": empty file (0 bytes), not a rawlog");
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw NotMftRawlog(path + ": cannot open: " + std::strerror(errno));
  unsigned char buf[64] = {};
  const int n = gzread(f, buf, sizeof buf);
  int errnum = Z_OK;
  const char* zmsg = gzerror(f, &errnum);
  const std::string zlib_error = (errnum != Z_OK && errnum != Z_STREAM_END && zmsg) ? zmsg : "";
  gzclose(f);
  static const std::string expected = "mrpt::obs::CObservationComment";
  const std::string file_bytes = std::to_string(static_cast<unsigned long long>(size)) + "-byte file";
  if (n <= 0)
    throw NotMftRawlog(path + ": truncated header: the " + file_bytes + " decompresses to no data" +
                       (zlib_error.empty() ? "" : " (zlib: " + zlib_error + ")"));
  const unsigned len = buf[0] & 0x7fu;
  const bool mrpt_object = (buf[0] & 0x80u) && len > 0 &&
                           std::all_of(buf + 1, buf + 1 + std::min<int>(static_cast<int>(len), n - 1),
                                       [](unsigned char c) { return std::isgraph(c); });
  if (!mrpt_object)
    throw NotMftRawlog(path + ": not an MFT rawlog: not an MRPT rawlog either (it does not start with a serialized MRPT object)");
  if (static_cast<int>(len) + 2 > n)
    throw NotMftRawlog(path + ": truncated header: the " + file_bytes + " ends inside its first object's header (" +
                       std::to_string(n) + " bytes decompressed)");
  const std::string cls(reinterpret_cast<const char*>(buf + 1), len);
  if (cls != expected)
    throw NotMftRawlog(path + ": not an MFT rawlog: an MRPT rawlog whose first object is " + cls +
                       ", not the mft metadata comment (rawlog-edit --info -i FILE shows what it holds)");
}

// Walks the next serialized object in the stream's lookahead and checks every length it declares against
// what an mft rawlog object can hold, before MRPT allocates anything for it. Knows the classes (and
// serialization versions) that mft-record writes; any other object is refused, since its lengths cannot be
// bounded. An object cut by the end of the data is left to MRPT, which reports the truncation.
class ObjectBounds {
 public:
  // The metadata comment (every configuration file as text) is the largest object, tens of kB; an
  // observation is a few hundred bytes. 16 MiB leaves room and bounds any allocation a file can cause.
  static constexpr std::size_t kMaxObjectBytes = 16u << 20;

  explicit ObjectBounds(GzReadStream& stream) : stream_(stream) {}

  // "" if the next object is within bounds (or the data ends inside it: then endsEarly()); else why it is
  // refused.
  std::string check() {
    pos_ = have_ = 0;
    ends_early_ = false;
    try {
      object(0);
    } catch (const EndOfData&) {
      ends_early_ = true;
      return "";
    } catch (const Refused& r) {
      return r.what;
    }
    return "";
  }
  bool endsEarly() const { return ends_early_; }
  std::size_t bytesSeen() const { return have_; }

 private:
  struct EndOfData {};
  struct Refused {
    std::string what;
  };

  void need(std::size_t n) {
    if (pos_ + n > kMaxObjectBytes)
      throw Refused{"an object larger than " + sizeText(kMaxObjectBytes) + " (no mft rawlog object is)"};
    if (pos_ + n <= have_) return;
    // Peek in chunks: one gzread per few objects, not per field.
    const std::size_t want = std::min(kMaxObjectBytes, std::max<std::size_t>(pos_ + n, 2 * have_ + 4096));
    have_ = stream_.peek(want, &data_);
    if (pos_ + n > have_) throw EndOfData{};
  }
  std::uint64_t unsignedLE(std::size_t bytes) {
    need(bytes);
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(data_[pos_ + i]) << (8 * i);
    pos_ += bytes;
    return v;
  }
  void skip(std::size_t bytes) {
    need(bytes);
    pos_ += bytes;
  }
  // A length-prefixed array (std::string, std::vector<T> of the old MRPT format: uint32 count, then the data).
  void array(const std::string& cls, const char* field, std::size_t element_bytes) {
    const std::uint64_t count = unsignedLE(4);
    const std::uint64_t bytes = count * element_bytes;
    if (bytes > kMaxObjectBytes - pos_)
      throw Refused{cls + " declares " + std::to_string(count) + " elements (" + sizeText(bytes) + ") in '" + field +
                    "': more than an mft rawlog object holds (" + sizeText(kMaxObjectBytes) + " at most)"};
    skip(static_cast<std::size_t>(bytes));
  }
  void object(int depth) {
    const std::uint64_t head = unsignedLE(1);
    const std::size_t name_len = head & 0x7fu;
    if (!(head & 0x80u) || name_len == 0)
      throw Refused{"not an MRPT object (its first byte is 0x" + hex(head) + ")"};
    need(name_len);
    const std::string cls(reinterpret_cast<const char*>(data_ + pos_), name_len);
    pos_ += name_len;
    if (cls == "nullptr") throw Refused{"a null object, which an mft rawlog never holds"};
    const auto version = static_cast<unsigned>(unsignedLE(1));
    const std::string what = "a " + cls + " (serialization version " + std::to_string(version) + ")";
    auto refuseVersion = [&] {
      throw Refused{what + ", a version mft-record does not write: its lengths cannot be checked, not read"};
    };
    if (cls == "mrpt::obs::CObservationComment" && depth == 0) {
      if (version > 1) refuseVersion();
      array(what, "text", 1);
      skip(8);                                      // timestamp
      if (version >= 1) array(what, "sensorLabel", 1);
    } else if (cls == "mrpt::obs::CObservationRawDAQ" && depth == 0) {
      if (version != 0) refuseVersion();
      array(what, "sensorLabel", 1);
      skip(8 + 8);                                  // timestamp, sample_rate
      array(what, "AIN_8bits", 1);
      array(what, "AIN_16bits", 2);
      array(what, "AIN_32bits", 4);
      array(what, "AIN_float", 4);
      array(what, "AIN_double", 8);
      skip(2 + 1);                                  // AIN_channel_count (uint16), AIN_interleaved (bool)
      array(what, "AOUT_8bits", 1);
      array(what, "AOUT_16bits", 2);
      array(what, "AOUT_float", 4);
      array(what, "AOUT_double", 8);
      array(what, "DIN", 1);
      array(what, "DOUT", 1);
      array(what, "CNTRIN_32bits", 4);
      array(what, "CNTRIN_double", 8);
    } else if (cls == "mrpt::obs::CObservationIMU" && depth == 0) {
      if (version != 4) refuseVersion();
      object(depth + 1);                            // sensorPose
      skip(mrpt::obs::COUNT_IMU_DATA_FIELDS * sizeof(bool) + 8 + mrpt::obs::COUNT_IMU_DATA_FIELDS * 8);
      array(what, "sensorLabel", 1);
    } else if (cls == "mrpt::poses::CPose3D" && depth == 1) {
      if (version != 3) refuseVersion();
      skip(12 * 8);                                 // x, y, z and the 3x3 rotation matrix (MRPT 2.5)
    } else {
      throw Refused{what + ", which an mft rawlog never holds: not read (its lengths cannot be checked)"};
    }
    const std::uint64_t end_flag = unsignedLE(1);
    if (end_flag != 0x88u) throw Refused{what + " without MRPT's end marker (byte 0x" + hex(end_flag) + ")"};
  }
  static std::string hex(std::uint64_t v) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "%02x", static_cast<unsigned>(v & 0xffu));
    return buf;
  }

  GzReadStream& stream_;
  const unsigned char* data_ = nullptr;
  std::size_t pos_ = 0, have_ = 0;
  bool ends_early_ = false;
};

}  // namespace

NotMftRawlog::NotMftRawlog(const std::string& message) : std::runtime_error(config::printableText(message)) {}

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
  ObjectBounds first_bounds(stream_);
  const std::string refused = first_bounds.check();
  if (!refused.empty()) throw NotMftRawlog(path + ": refused: its first object is " + refused);
  if (first_bounds.endsEarly())
    throw NotMftRawlog(path + ": truncated header: the file ends inside the metadata comment (" +
                       std::to_string(first_bounds.bytesSeen()) + " bytes decompressed" +
                       (stream_.error().empty() ? "" : ", zlib: " + stream_.error()) + ")");
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
    const std::string refused = ObjectBounds(stream_).check();
    if (!refused.empty()) {
      end_ = End::Corrupt;
      end_detail_ = "object " + std::to_string(objects_ + 1) + ": " + refused;
      return false;
    }
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
    case End::Corrupt:  // the detail may quote the file's bytes
      return "corrupt after " + n + " (" + std::to_string(stream_.getPosition()) +
             " bytes decompressed): " + config::printableText(end_detail_);
  }
  return "";
}

}  // namespace mft::rawlog
