// The caps of an import isolated in a child process (ImportOptions::isolate).
#pragma once

#include <cstddef>
#include <cstdint>

namespace conform::io {

struct IsolationLimits {
  /// Address space of the child, bytes (not enforced under AddressSanitizer). A 15k-vertex,
  /// 40-bone character needs about 100 MiB.
  std::size_t memory_bytes = std::size_t{4} << 30;
  /// Wall time before the child is killed, seconds. For an import this is the fixed part of
  /// the budget, to which `seconds_per_mib` is added for every MiB of the file (import_seconds):
  /// a tiny corrupt file on which a reader spins is refused in about 2 s, a large model still
  /// has the time it needs (the slowest rigged test model, 3.7k faces, imports in well under
  /// 1 s; the largest model of assimp-testmodels, a 3.9 MiB IFC, in 1.5 s of its 41 s).
  double seconds = 2;
  /// Seconds of an import's budget per MiB of the file read (and of the files beside it that
  /// the reader may read too: import_seconds).
  double seconds_per_mib = 10;
  /// Stack of the thread that reads, bytes (reserved, committed as used): readers recurse over
  /// the node hierarchy, and a 20,000-node chain overflows the usual 8 MiB.
  std::size_t stack_bytes = std::size_t{512} << 20;
};

/// The wall-time budget of an isolated import that reads `file_bytes` bytes: limits.seconds +
/// limits.seconds_per_mib per MiB.
double import_seconds(const IsolationLimits& limits, std::uintmax_t file_bytes);

}  // namespace conform::io
