// Size-limited file reading with POSIX calls: the kind of file is known before the first
// byte is read, and a FIFO or device can neither block the open nor the reads forever.
#include "common/file.hpp"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

namespace plcfi::common {

namespace {

// Closes the descriptor on every way out.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

std::string size_text(size_t bytes) {
  if (bytes >= kMiB && bytes % kMiB == 0) return std::to_string(bytes / kMiB) + " MiB";
  return std::to_string(bytes) + " bytes";
}

bool read_file(const std::string& path, size_t max_bytes, std::string* text, std::string* err, int stall_timeout_ms) {
  text->clear();
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer forever.
  Fd fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0) {
    *err = errno == EISDIR ? path + ": is a directory" : path + ": cannot open (" + std::strerror(errno) + ")";
    return false;
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) {
    *err = path + ": cannot open (" + std::strerror(errno) + ")";
    return false;
  }
  if (S_ISDIR(st.st_mode)) {
    *err = path + ": is a directory";
    return false;
  }
  const bool regular = S_ISREG(st.st_mode);
  if (regular && static_cast<unsigned long long>(st.st_size) > max_bytes) {
    *err = path + ": is larger than " + size_text(max_bytes);
    return false;
  }
  if (regular) {
    // A regular file never blocks: plain blocking reads are simplest.
    const int flags = ::fcntl(fd.get(), F_GETFL);
    if (flags >= 0) ::fcntl(fd.get(), F_SETFL, flags & ~O_NONBLOCK);
    text->reserve(static_cast<size_t>(st.st_size));
  }
  char buf[64 * 1024];
  for (;;) {
    if (!regular) {
      pollfd p{fd.get(), POLLIN, 0};
      const int r = ::poll(&p, 1, stall_timeout_ms);
      if (r < 0 && errno == EINTR) continue;
      if (r == 0) {
        const std::string wait = stall_timeout_ms % 1000 == 0 ? std::to_string(stall_timeout_ms / 1000) + " s"
                                                               : std::to_string(stall_timeout_ms) + " ms";
        *err = path + ": no data for " + wait + " (a pipe nobody writes to?)";
        return false;
      }
    }
    const ssize_t n = ::read(fd.get(), buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      *err = path + ": " + (errno == EISDIR ? std::string("is a directory") : "read error (" + std::string(std::strerror(errno)) + ")");
      return false;
    }
    if (n == 0) break;
    if (text->size() + static_cast<size_t>(n) > max_bytes) {
      text->clear();
      text->shrink_to_fit();
      *err = path + ": is larger than " + size_text(max_bytes);
      return false;
    }
    text->append(buf, static_cast<size_t>(n));
  }
  return true;
}

bool write_all(int fd, const std::string& data) {
  size_t done = 0;
  while (done < data.size()) {
    ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

}  // namespace plcfi::common
