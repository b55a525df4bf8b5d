#include "evcorner/io/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "evcorner/error.hpp"

namespace evcorner::io {

InputFile::InputFile(std::string path) {
    if (path == "-") {
        name_ = "<stdin>";
        fd_ = STDIN_FILENO;
    } else {
        name_ = std::move(path);
        fd_ = ::open(name_.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd_ < 0) throw InputError(name_, std::string("cannot open: ") + std::strerror(errno));
        owns_fd_ = true;
    }
    struct stat st {};
    if (::fstat(fd_, &st) == 0) {
        if (S_ISDIR(st.st_mode)) {
            if (owns_fd_) ::close(fd_);
            throw InputError(name_, "is a directory, not an event file");
        }
        if (S_ISREG(st.st_mode)) size_ = static_cast<std::uint64_t>(st.st_size);
    }
#ifdef POSIX_FADV_SEQUENTIAL
    if (size_) ::posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
#endif
}

InputFile::InputFile(InputFile&& other) noexcept
    : name_(std::move(other.name_)),
      fd_(std::exchange(other.fd_, -1)),
      owns_fd_(std::exchange(other.owns_fd_, false)),
      size_(other.size_),
      consumed_(other.consumed_),
      ahead_(std::move(other.ahead_)),
      ahead_pos_(std::exchange(other.ahead_pos_, 0)),
      eof_(other.eof_) {}

InputFile::~InputFile() {
    if (owns_fd_) ::close(fd_);
}

std::size_t InputFile::read_fd(char* buf, std::size_t n) {
    if (eof_) return 0;
    for (;;) {
        const ssize_t got = ::read(fd_, buf, n);
        if (got > 0) return static_cast<std::size_t>(got);
        if (got == 0) {
            eof_ = true;
            return 0;
        }
        if (errno == EINTR) continue;
        throw InputError(name_, InputError::Unit::byte, consumed_ + (ahead_.size() - ahead_pos_),
                         std::string("read failed: ") + std::strerror(errno));
    }
}

std::string_view InputFile::peek(std::size_t n) {
    if (ahead_pos_ > 0) {
        ahead_.erase(0, ahead_pos_);
        ahead_pos_ = 0;
    }
    while (ahead_.size() < n && !eof_) {
        // Ask for a little more than needed from a file (fewer calls); a pipe returns
        // what it holds without waiting for the rest.
        const std::size_t want = std::max<std::size_t>(n - ahead_.size(), 4096);
        const std::size_t old = ahead_.size();
        ahead_.resize(old + want);
        const std::size_t got = read_fd(ahead_.data() + old, want);
        ahead_.resize(old + got);
    }
    return ahead_;
}

std::size_t InputFile::read(std::span<char> buf) {
    if (ahead_pos_ < ahead_.size()) {
        const std::size_t n = std::min(buf.size(), ahead_.size() - ahead_pos_);
        std::memcpy(buf.data(), ahead_.data() + ahead_pos_, n);
        ahead_pos_ += n;
        if (ahead_pos_ == ahead_.size()) {
            std::string().swap(ahead_);
            ahead_pos_ = 0;
        }
        consumed_ += n;
        return n;
    }
    const std::size_t n = read_fd(buf.data(), buf.size());
    consumed_ += n;
    return n;
}

}  // namespace evcorner::io
