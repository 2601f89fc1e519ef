#pragma once
// Test helpers for work in another process: a forked child whose result comes back through a pipe, and
// POSIX shared-memory names unique to the test process (removed when the test ends).
#include <sys/mman.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <functional>
#include <string>

namespace mft::test {

// Runs `body` in a forked child; the bytes it returns reach the parent through a pipe (the child exits 0, or 2
// when the write failed). Meanwhile the parent may act on pid() (signals); output() then reads until the child
// closes the pipe and waits for it.
class ForkedChild {
 public:
  explicit ForkedChild(const std::function<std::string()>& body) {
    int fds[2];
    if (pipe(fds) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      close(fds[0]);
      const std::string out = body();
      _exit(write(fds[1], out.data(), out.size()) == static_cast<ssize_t>(out.size()) ? 0 : 2);
    }
    close(fds[1]);
    fd_ = fds[0];
  }
  ~ForkedChild() {
    if (fd_ >= 0) close(fd_);
  }
  ForkedChild(const ForkedChild&) = delete;
  ForkedChild& operator=(const ForkedChild&) = delete;

  bool started() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  // What the child wrote; `status` gets its wait status.
  std::string output(int* status) {
    std::string out;
    char buf[512];
    for (ssize_t n; fd_ >= 0 && (n = read(fd_, buf, sizeof buf)) > 0;) out.append(buf, static_cast<std::size_t>(n));
    *status = 0;
    if (pid_ > 0) waitpid(pid_, status, 0);
    return out;
  }

 private:
  pid_t pid_ = -1;
  int fd_ = -1;
};

// "/mft-test-<what>-<pid>-<n>": a shared-memory name no other test process uses.
inline std::string uniqueShmName(const std::string& what) {
  static int counter = 0;
  return "/mft-test-" + what + "-" + std::to_string(getpid()) + "-" + std::to_string(counter++);
}

// Removes the shared-memory object `name` when the test ends.
struct ShmUnlink {
  std::string name;
  ~ShmUnlink() { shm_unlink(name.c_str()); }
};

}  // namespace mft::test
