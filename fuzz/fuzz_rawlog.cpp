// Fuzz target: a rawlog file as mft-export, mft-replay and mft-record's readers take it (services/record): the
// reader's checks of the file and of every object's declared lengths, MRPT's deserialization, the metadata's
// YAML, then every observation as the export reads it (reassembled into messages, values and CSV cells). The
// reader either refuses the file (NotMftRawlog naming it) or reads it to an end it names: complete, truncated
// or corrupt. The bytes live in an anonymous in-memory file, named by its /proc/self/fd path.
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

#include "fuzz/fuzz_target.hpp"
#include "services/record/rawlog_reader.hpp"

namespace mft::fuzz {

namespace {

// The bytes as a file: an anonymous memory file, closed when this goes.
class MemoryFile {
 public:
  MemoryFile(const std::uint8_t* data, std::size_t size) : fd_(memfd_create("fuzz-rawlog", 0)) {
    if (fd_ < 0) throw std::system_error(errno, std::generic_category(), "memfd_create");
    for (std::size_t done = 0; done < size;) {
      const ssize_t n = write(fd_, data + done, size - done);
      if (n <= 0) throw std::system_error(errno, std::generic_category(), "write to the memory file");
      done += static_cast<std::size_t>(n);
    }
  }
  ~MemoryFile() { close(fd_); }
  MemoryFile(const MemoryFile&) = delete;
  MemoryFile& operator=(const MemoryFile&) = delete;
  std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

 private:
  int fd_;
};

}  // namespace

Outcome runOne(const std::uint8_t* data, std::size_t size) {
  const MemoryFile file(data, size);
  const std::string origin = file.path();
  std::unique_ptr<rawlog::RawlogReader> reader;
  try {
    reader = std::make_unique<rawlog::RawlogReader>(origin);
  } catch (const rawlog::NotMftRawlog& e) {
    return refusedWith(e.what(), origin);
  }
  rawlog::MessageAssembler assembler(reader->metadata().time_base_unix_ns);
  mrpt::obs::CObservation::Ptr obs;
  std::vector<double> values;
  std::string cells;
  std::size_t messages = 0;
  while (reader->next(&obs)) {
    rawlog::Message m;
    std::int64_t unix_ns = 0;
    if (assembler.add(*obs, &m, &unix_ns)) ++messages;
    const int label = rawlog::labelIndex(obs->sensorLabel);
    if (label < 0) continue;
    rawlog::observationValues(*obs, label, &values);
    rawlog::observationCells(*obs, label, &cells);
  }
  return acceptedAs(std::to_string(messages) + " messages, " + reader->endMessage());
}

}  // namespace mft::fuzz
