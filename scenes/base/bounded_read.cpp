#include "base/bounded_read.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace conform::scenes {
namespace {

constexpr double kMaxInputMib = 1048576;  // 1 TiB: a typo's guard, not a real limit

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// Closes the descriptor however the read ends.
struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) close(fd);
  }
};

}  // namespace

std::size_t max_input_bytes() {
  const char* text = std::getenv("CONFORM_MAX_INPUT_MIB");
  if (!text || !*text) return kDefaultMaxInputBytes;
  char* end = nullptr;
  const double m = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(m) || m <= 0 || m > kMaxInputMib)
    throw std::runtime_error("CONFORM_MAX_INPUT_MIB='" + std::string(text) +
                             "' must be a positive number of MiB, at most 1048576");
  return static_cast<std::size_t>(std::max(1.0, m * 1048576.0));
}

std::string read_bounded(const std::string& path, const std::string& what) {
  const std::size_t cap = max_input_bytes();
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer.
  Descriptor file{open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY)};
  if (file.fd < 0) {
    const int error = errno;
    const std::string why = what + " " + path + ": cannot open: " + std::strerror(error);
    if (error == ENOENT || error == ENOTDIR) throw InputMissing(why);
    throw std::runtime_error(why);
  }
  struct stat st {};
  if (fstat(file.fd, &st) != 0)
    throw std::runtime_error(what + " " + path + ": cannot stat: " + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    throw std::runtime_error(what + " " + path + " is " + kind_of(st.st_mode) +
                             ", not a regular file");
  const auto too_large = [&](const std::string& size) {
    return std::runtime_error(what + " " + path + " is " + size + ", more than the cap of " +
                              std::to_string(cap) +
                              " bytes (16 MiB by default; CONFORM_MAX_INPUT_MIB sets it)");
  };
  if (static_cast<std::uintmax_t>(st.st_size) > cap)
    throw too_large(std::to_string(st.st_size) + " bytes");
  // The file may grow while it is read: never more than cap + 1 bytes.
  std::string text(static_cast<std::size_t>(st.st_size) + 1, '\0');
  std::size_t used = 0;
  for (;;) {
    if (used == text.size()) {
      if (text.size() > cap) throw too_large("growing while it is read");
      text.resize(std::min(cap + 1, 2 * text.size()));
    }
    const ssize_t n = read(file.fd, text.data() + used, text.size() - used);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0)
      throw std::runtime_error(what + " " + path + ": cannot read: " + std::strerror(errno));
    if (n == 0) break;
    used += static_cast<std::size_t>(n);
  }
  if (used > cap) throw too_large("growing while it is read");
  text.resize(used);
  return text;
}

}  // namespace conform::scenes
