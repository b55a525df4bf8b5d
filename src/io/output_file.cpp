#include "evcorner/io/output_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "evcorner/error.hpp"
#include "evcorner/io/pending_file.hpp"

namespace evcorner::io {

namespace {
constexpr std::size_t kBufferSize = 1 << 20;

std::string write_failed(int err) { return std::string("write failed: ") + std::strerror(err); }
}  // namespace

OutputFile::OutputFile(std::string path) {
    grow(kBufferSize);
    if (path == "-") {
        name_ = "<stdout>";
        fd_ = STDOUT_FILENO;
        // What went through stdio before comes first.
        std::fflush(stdout);
    } else {
        name_ = std::move(path);
        file_ = std::make_unique<PendingFile>(name_);
        fd_ = file_->fd();
    }
}

OutputFile::~OutputFile() {
    if (fd_ < 0) return;
    if (file_ && !file_->direct()) return;  // file_'s destructor removes the unfinished file
    try {
        flush();
    } catch (...) {
    }
}

void OutputFile::write(std::string_view bytes) {
    if (bytes.size() > cap_ - used_) {
        flush();
        if (bytes.size() > cap_) grow(bytes.size());
    }
    if (!bytes.empty()) std::memcpy(buf_.get() + used_, bytes.data(), bytes.size());  // data() may be null
    used_ += bytes.size();
}

char* OutputFile::reserve(std::size_t n) {
    if (n > cap_ - used_) {
        flush();
        if (n > cap_) grow(n);
    }
    return buf_.get() + used_;
}

void OutputFile::grow(std::size_t n) {
    buf_ = std::make_unique_for_overwrite<char[]>(n);  // empty: flush() came first
    cap_ = n;
}

void OutputFile::flush() {
    if (fd_ < 0) return;
    std::size_t done = 0;
    while (done < used_) {
        const ssize_t n = ::write(fd_, buf_.get() + done, used_ - done);
        if (n <= 0) {
            if (n < 0 && errno == EINTR) continue;
            const int err = n < 0 ? errno : EIO;
            used_ = 0;
            throw OutputError(name_, write_failed(err));
        }
        done += static_cast<std::size_t>(n);
    }
    used_ = 0;
}

void OutputFile::write_at(std::uint64_t offset, std::string_view bytes) {
    flush();
    if (fd_ < 0) throw OutputError(name_, "write after close");
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done, static_cast<off_t>(offset + done));
        if (n <= 0) {
            if (n < 0 && errno == EINTR) continue;
            throw OutputError(name_, write_failed(n < 0 ? errno : EIO));
        }
        done += static_cast<std::size_t>(n);
    }
}

void OutputFile::close() {
    if (fd_ < 0) return;
    flush();
    fd_ = -1;
    if (file_) file_->commit();
}

}  // namespace evcorner::io
