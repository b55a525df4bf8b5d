#pragma once
// The body of every reader fuzz target: the input bytes go to a temporary file (the
// readers take paths), which is read to the end in small batches. InputError is the
// only exception a reader may throw on bad bytes; anything else (another exception, a
// crash, a sanitizer report, a hang, an oversized allocation) is a bug.

#include <fcntl.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "evcorner/error.hpp"
#include "evcorner/io/open.hpp"

namespace evcorner::fuzz {

inline const std::string& temp_path() {
    static const std::string path = [] {
        const char* dir = ::access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
        return std::string(dir) + "/evcorner-fuzz-" + std::to_string(::getpid());
    }();
    return path;
}

inline void write_file(const std::string& path, const std::uint8_t* data, std::size_t size) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd < 0) std::abort();
    std::size_t done = 0;
    while (done < size) {
        const ssize_t n = ::write(fd, data + done, size - done);
        if (n <= 0) std::abort();
        done += static_cast<std::size_t>(n);
    }
    ::close(fd);
}

/// Reads `data` as a file of `format`; the first byte's low bit picks skip_invalid.
inline int run(const std::uint8_t* data, std::size_t size, const char* format) {
    write_file(temp_path(), data, size);
    io::ReaderOptions options;
    options.fallback_sensor = std::nullopt;
    options.skip_invalid = size > 0 && (data[0] & 1) != 0;
    std::vector<Event> buf(1024);
    try {
        const auto reader = io::open_event_reader(temp_path(), options, format);
        for (int calls = 0;; ++calls) {
            const std::size_t n = reader->read(buf);
            if (n == 0 && reader->skipped_in_batch().empty()) break;
        }
        // After an error, every later read() must throw it again (never crash).
    } catch (const InputError&) {
    }
    return 0;
}

}  // namespace evcorner::fuzz
