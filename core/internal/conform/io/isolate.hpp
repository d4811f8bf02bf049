// Running untrusted work (a third-party file reader) in a child process, so that its crash,
// hang or runaway allocation cannot take the caller down or corrupt its memory.
//
// The work runs in a forked child and returns its result as bytes through a pipe; the caller
// only ever sees those bytes. The child reports its own outcome (a tagged, length-prefixed
// message) and only a complete report with exit status 0 counts as success, so that a crash
// caught by a host's own handler (ASan's, an application's), which exits instead of dying by a
// signal, is still a crash. The child has a memory cap (RLIMIT_AS; under ASan, whose shadow
// memory needs terabytes of address space, the caller polls the child's resident memory every
// 20 ms instead and kills it over the cap) and a time cap after which it is killed, and it dies
// with the thread that forked it (PR_SET_PDEATHSIG), also when that thread is killed.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "conform/io/isolation_limits.hpp"

namespace conform::io {

struct Isolated {
  enum class Status {
    ok,             // `result` holds what the work returned
    failed,         // the work threw: `message` holds what()
    out_of_memory,  // the work threw std::bad_alloc (the memory cap, or the machine's)
    crashed,        // the child died (signal) or exited without its report: `message` says how
    timed_out,      // killed after IsolationLimits::seconds
    unavailable,    // no child could be started (fork or pipe failed): `message` says why
  };
  Status status = Status::unavailable;
  std::string result;
  std::string message;
};

/// Runs `work` in a child process under `limits` and returns its outcome. Nothing `work` does
/// reaches the caller's memory. The child's stderr goes to /dev/null (readers print assertion
/// text there). Forking a multithreaded caller is only safe when no other thread holds a lock
/// the child needs (glibc's malloc is fork-safe).
Isolated run_isolated(const std::function<std::string()>& work, const IsolationLimits& limits = {});

}  // namespace conform::io
