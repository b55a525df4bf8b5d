#pragma once
// Standard output as the commands write it (tables, help, JSON through stdio and
// std::cout): every write checked, so that a full disk or a closed pipe fails the run
// with "<stdout>: write failed: REASON" (exit status 1) instead of passing unnoticed.

#include <cstdio>

namespace evcorner::cli {

/// Flushes `f`; for stdout, throws OutputError ("<stdout>: write failed: REASON") when
/// this or an earlier write failed (stderr, the diagnostics, is flushed as best it can).
void flush_checked(std::FILE* f);

/// For main(), once the command (or help, or version) is done: flushes std::cout and
/// stdout; on failure prints "evcorner: error: <stdout>: write failed: REASON" and
/// returns 1, else returns `status`.
int finish_stdout(int status);

}  // namespace evcorner::cli
