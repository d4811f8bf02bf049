// Reading a user's input file (a scene file, a scalpel CSV, a sweep's scene) whole into memory,
// bounded: a FIFO, device or socket would block the open or never end (/dev/zero grew the
// reader to gigabytes), so only regular files are read, and only up to a size cap.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace conform::scenes {

/// The cap on an input file's size when CONFORM_MAX_INPUT_MIB is not set: 16 MiB.
inline constexpr std::size_t kDefaultMaxInputBytes = std::size_t{16} << 20;

/// Thrown when `path` cannot be opened because it does not exist (callers may then try
/// another meaning of the name, e.g. a built-in scene).
class InputMissing : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The cap in bytes: CONFORM_MAX_INPUT_MIB (a positive number of MiB, at most 1048576) or
/// kDefaultMaxInputBytes. Throws std::runtime_error naming the variable for another value.
std::size_t max_input_bytes();

/// The whole file `path`, `what` naming it in errors ("scene file", "scalpel file"). Opened
/// without blocking; refused unless it is a regular file of at most max_input_bytes(). Throws
/// InputMissing when it does not exist and std::runtime_error for every other refusal.
std::string read_bounded(const std::string& path, const std::string& what);

}  // namespace conform::scenes
