#include "sweep/sweep_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>

namespace conform::scenes {

SweepLock::SweepLock(const std::filesystem::path& dir) {
  fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0)
    throw std::runtime_error("cannot open " + dir.string() + ": " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) == 0) return;
  const int error = errno;
  ::close(fd_);
  fd_ = -1;
  if (error == EWOULDBLOCK)
    throw SweepBusy("another sweep is running in " + dir.string() +
                    " (or the point runs of a killed one are still ending): wait for it to end");
  // Some network file systems refuse flock: the sweep still runs, unguarded.
  std::cerr << "conform sweep: warning: cannot lock " << dir.string() << " ("
            << std::strerror(error) << "): nothing keeps a second sweep out of it\n";
}

SweepLock::~SweepLock() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace conform::scenes
