// The caps of an import isolated in a child process (ImportOptions::isolate).
#pragma once

#include <cstddef>

namespace conform::io {

struct IsolationLimits {
  /// Address space of the child, bytes (not enforced under AddressSanitizer). A 15k-vertex,
  /// 40-bone character needs about 100 MiB.
  std::size_t memory_bytes = std::size_t{4} << 30;
  /// Wall time before the child is killed, seconds (the slowest rigged test model, 3.7k faces,
  /// imports in well under 1 s).
  double seconds = 30;
  /// Stack of the thread that reads, bytes (reserved, committed as used): readers recurse over
  /// the node hierarchy, and a 20,000-node chain overflows the usual 8 MiB.
  std::size_t stack_bytes = std::size_t{512} << 20;
};

}  // namespace conform::io
