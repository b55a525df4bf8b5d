#include "evcorner/io/output_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "evcorner/error.hpp"

namespace evcorner::io {

namespace {
constexpr std::size_t kBufferSize = 1 << 20;
}

OutputFile::OutputFile(std::string path) : buf_(kBufferSize) {
    if (path == "-") {
        name_ = "<stdout>";
        fd_ = STDOUT_FILENO;
    } else {
        name_ = std::move(path);
        fd_ = ::open(name_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
        if (fd_ < 0)
            throw OutputError(name_, std::string("cannot create: ") + std::strerror(errno));
        owns_fd_ = true;
    }
}

OutputFile::~OutputFile() {
    try {
        close();
    } catch (...) {
    }
}

void OutputFile::write(std::string_view bytes) {
    if (bytes.size() > buf_.size() - used_) {
        flush();
        if (bytes.size() > buf_.size()) buf_.resize(bytes.size());
    }
    if (!bytes.empty()) std::memcpy(buf_.data() + used_, bytes.data(), bytes.size());  // data() may be null
    used_ += bytes.size();
}

char* OutputFile::reserve(std::size_t n) {
    if (n > buf_.size() - used_) {
        flush();
        if (n > buf_.size()) buf_.resize(n);
    }
    return buf_.data() + used_;
}

void OutputFile::flush() {
    if (fd_ < 0) return;
    std::size_t done = 0;
    while (done < used_) {
        const ssize_t n = ::write(fd_, buf_.data() + done, used_ - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            const int err = errno;
            used_ = 0;
            throw OutputError(name_, std::string("write failed: ") + std::strerror(err));
        }
        done += static_cast<std::size_t>(n);
    }
    used_ = 0;
}

void OutputFile::close() {
    if (fd_ < 0) return;
    flush();
    const int fd = fd_;
    fd_ = -1;
    if (owns_fd_ && ::close(fd) != 0)
        throw OutputError(name_, std::string("close failed: ") + std::strerror(errno));
}

}  // namespace evcorner::io
