// Running untrusted work (a third-party file reader) where its crash cannot take the caller down.
#pragma once

#include <functional>
#include <string>

namespace conform::io {

/// Runs `work` in a forked child process (POSIX) and waits for it. Returns an empty string when
/// the child ended normally — whether `work` returned or threw (an exception is not a crash) — or
/// when the process cannot fork; otherwise how the child died, e.g. "Segmentation fault" or
/// "Aborted". Nothing `work` does reaches the caller's memory; the child's stderr goes to
/// /dev/null (readers print assertion text there). Forking a multithreaded caller is only safe
/// when no other thread holds a lock the child needs.
std::string crash_in_child(const std::function<void()>& work);

}  // namespace conform::io
