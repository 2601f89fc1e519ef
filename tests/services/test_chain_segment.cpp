// The chain channel's segment (services/runtime/chain_channel.hpp): made whole or not at all, and checked on
// attach. A full /dev/shm is an error naming the segment at creation (it was a SIGBUS at the first write); a
// segment of the name that holds random bytes, has another size or was made under a stack that is gone is
// refused with the reason (random bytes were read as reader counts, a stale copy as an attached chain).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <random>
#include <string>
#include <vector>

#include "services/runtime/chain_channel.hpp"
#include "tests/support/child_process.hpp"

using namespace mft::services;
using mft::test::ForkedChild;
using mft::test::ShmUnlink;
using mft::test::uniqueShmName;

namespace {


void writeSegment(const std::string& name, const std::vector<unsigned char>& bytes) {
  const int fd = shm_open(name.c_str(), O_RDWR | O_CREAT | O_EXCL, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(write(fd, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
  close(fd);
}

std::string openError(const std::string& name) {
  try {
    ChainChannel channel(name);
  } catch (const ChainChannelError& e) {
    return e.what();
  }
  return "";
}

TEST(ChainSegment, RandomBytesOfTheRightSizeAreRefused) {
  const ShmUnlink u{uniqueShmName("seg-random")};
  std::vector<unsigned char> bytes(ChainChannel::segmentBytes());
  std::mt19937 rng(7);
  for (auto& b : bytes) b = static_cast<unsigned char>(rng());
  writeSegment(u.name, bytes);
  const std::string error = openError(u.name);
  EXPECT_NE(error.find("has no chain header"), std::string::npos) << error;
  EXPECT_NE(error.find("stale or foreign"), std::string::npos) << error;
}

TEST(ChainSegment, AnotherSizeIsRefused) {
  const ShmUnlink u{uniqueShmName("seg-size")};
  writeSegment(u.name, std::vector<unsigned char>(4096, 0x5a));
  const std::string error = openError(u.name);
  EXPECT_NE(error.find("has 4096 bytes, not " + std::to_string(ChainChannel::segmentBytes())), std::string::npos)
      << error;
}

// A segment made by a process whose parent (the stack's supervisor) and itself are both gone: a stale copy.
TEST(ChainSegment, SegmentOfAStackThatIsGoneIsRefused) {
  const ShmUnlink u{uniqueShmName("seg-stale")};
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const pid_t grandchild = fork();
    if (grandchild == 0) {
      { ChainChannel made(u.name); }
      _exit(0);
    }
    int st = 0;
    waitpid(grandchild, &st, 0);
    _exit(WIFEXITED(st) ? WEXITSTATUS(st) : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  const std::string error = openError(u.name);
  EXPECT_NE(error.find("was made under process " + std::to_string(child) + ", which is gone"), std::string::npos)
      << error;
}

TEST(ChainSegment, AStackSegmentIsSharedAndSized) {
  const ShmUnlink u{uniqueShmName("seg-shared")};
  ChainChannel first(u.name);
  ChainChannel second(u.name);
  first.slot(2).head.store(41);
  EXPECT_EQ(second.slot(2).head.load(), 41u);
  EXPECT_GT(ChainChannel::segmentBytes(), 3000000u);
  EXPECT_LT(ChainChannel::segmentBytes(), 3300000u);  // the supervisor's free-space check (CHAIN_SEGMENT_BYTES)
}

// In a mount namespace of its own (root only) /dev/shm is a 64 kB tmpfs: creating the segment must fail with
// the reason, in the constructor, and leave nothing behind.
TEST(ChainSegment, FullDevShmIsAnErrorNotASigbus) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root for a private mount namespace";
  ForkedChild child([] {
    std::string out = "setup";
    if (unshare(CLONE_NEWNS) == 0 && mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) == 0 &&
        mount("tmpfs", "/dev/shm", "tmpfs", 0, "size=64k") == 0) {
      out = openError("/mft-test-seg-full");
      const int fd = shm_open("/mft-test-seg-full", O_RDONLY, 0);
      if (fd >= 0) out += " [left behind]";
    }
    return out;
  });
  ASSERT_TRUE(child.started());
  int status = 0;
  const std::string out = child.output(&status);
  ASSERT_TRUE(WIFEXITED(status)) << "the child died of signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  if (out == "setup") GTEST_SKIP() << "no private tmpfs here";
  EXPECT_NE(out.find("cannot reserve 3."), std::string::npos) << out;
  EXPECT_NE(out.find("No space left on device"), std::string::npos) << out;
  EXPECT_EQ(out.find("left behind"), std::string::npos) << out;
}

}  // namespace
