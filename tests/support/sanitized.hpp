// The sanitized stage of scripts/test.sh (ASan+UBSan, several times slower) sets
// CONFORM_SANITIZED=1. A test whose cost is a count of random trials runs fewer of them there,
// never none: the same checks on a shorter sequence.
#pragma once

#include <cstdlib>
#include <cstring>

namespace conform::test {

inline bool sanitized_run() {
  const char* s = std::getenv("CONFORM_SANITIZED");
  return s && std::strcmp(s, "1") == 0;
}

/// `full` normally, `sanitized` in the sanitized stage.
inline int trial_count(int full, int sanitized) {
  return sanitized_run() ? sanitized : full;
}

}  // namespace conform::test
