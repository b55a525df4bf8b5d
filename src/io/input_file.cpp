#include "evcorner/io/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "evcorner/error.hpp"

namespace evcorner::io {

namespace {
// Bytes peeked from standard input and not yet handed to a reader.
std::string& stdin_stash() {
    static std::string stash;
    return stash;
}
std::size_t& stdin_stash_pos() {
    static std::size_t pos = 0;
    return pos;
}
}  // namespace

std::string_view peek_stdin(std::size_t max_bytes) {
    std::string& stash = stdin_stash();
    while (stash.size() < max_bytes) {
        char buf[4096];
        const ssize_t n = ::read(STDIN_FILENO, buf, std::min(sizeof buf, max_bytes - stash.size()));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        stash.append(buf, static_cast<std::size_t>(n));
    }
    return std::string_view(stash).substr(stdin_stash_pos());
}

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

InputFile::~InputFile() {
    if (owns_fd_) ::close(fd_);
}

std::size_t InputFile::read(std::span<char> buf) {
    if (fd_ == STDIN_FILENO && stdin_stash_pos() < stdin_stash().size()) {
        const std::size_t n = std::min(buf.size(), stdin_stash().size() - stdin_stash_pos());
        std::memcpy(buf.data(), stdin_stash().data() + stdin_stash_pos(), n);
        stdin_stash_pos() += n;
        consumed_ += n;
        return n;
    }
    for (;;) {
        const ssize_t n = ::read(fd_, buf.data(), buf.size());
        if (n >= 0) {
            consumed_ += static_cast<std::uint64_t>(n);
            return static_cast<std::size_t>(n);
        }
        if (errno == EINTR) continue;
        throw InputError(name_, InputError::Unit::byte, consumed_,
                         std::string("read failed: ") + std::strerror(errno));
    }
}

}  // namespace evcorner::io
