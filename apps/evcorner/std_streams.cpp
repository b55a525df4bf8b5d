#include "std_streams.hpp"

#include <cerrno>
#include <cstring>
#include <iostream>
#include <string>

#include "evcorner/error.hpp"

namespace evcorner::cli {

namespace {

// errno of the failed flush; an error flag set by an earlier write (whose errno is gone)
// has no reason left to give.
bool g_reported = false;  // a failure flush_checked() threw, reported by main() already

std::string reason(int err) { return err != 0 ? std::strerror(err) : "an earlier write to it failed"; }

}  // namespace

void flush_checked(std::FILE* f) {
    errno = 0;
    if (f == stderr) {  // diagnostics: best effort, as everywhere
        std::fflush(f);
        return;
    }
    if (std::fflush(f) != 0 || std::ferror(f)) {
        const int err = errno;
        g_reported = true;
        throw OutputError("<stdout>", "write failed: " + reason(err));
    }
}

int finish_stdout(int status) {
    errno = 0;
    std::cout.flush();
    int err = errno;
    const bool cout_failed = std::cout.fail();
    errno = 0;
    const bool failed = std::fflush(stdout) != 0 || std::ferror(stdout) || cout_failed;
    if (errno != 0) err = errno;
    if (!failed) return status;
    if (g_reported) return 1;
    std::fprintf(stderr, "evcorner: error: <stdout>: write failed: %s\n", reason(err).c_str());
    return 1;
}

}  // namespace evcorner::cli
