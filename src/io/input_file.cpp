#include "evcorner/io/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
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
      eof_(other.eof_),
      decoder_(std::move(other.decoder_)),
      raw_(std::move(other.raw_)),
      raw_pos_(other.raw_pos_),
      raw_fill_(other.raw_fill_),
      raw_used_(other.raw_used_),
      stream_ended_(other.stream_ended_),
      decoded_end_(other.decoded_end_) {}

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
    while (ahead_.size() < n && !(decoder_ ? decoded_end_ : eof_)) {
        // Ask for a little more than needed from a file (fewer calls); a pipe returns
        // what it holds without waiting for the rest.
        const std::size_t want = std::max<std::size_t>(n - ahead_.size(), 4096);
        const std::size_t old = ahead_.size();
        ahead_.resize(old + want);
        const std::size_t got = read_source(ahead_.data() + old, want);
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
    const std::size_t n = read_source(buf.data(), buf.size());
    consumed_ += n;
    return n;
}

std::size_t InputFile::read_source(char* buf, std::size_t n) {
    return decoder_ ? read_decoded(buf, n) : read_fd(buf, n);
}

void InputFile::decompress(Compression c) {
    if (decoder_) throw std::logic_error("InputFile::decompress called twice");
    // The bytes peeked at and not yet read are the start of the compressed stream.
    raw_.assign(std::size_t{1} << 18, '\0');
    const std::size_t pending = ahead_.size() - ahead_pos_;
    if (pending > raw_.size()) raw_.resize(pending);
    std::memcpy(raw_.data(), ahead_.data() + ahead_pos_, pending);
    raw_fill_ = pending;
    raw_used_ = consumed_;
    std::string().swap(ahead_);
    ahead_pos_ = 0;
    decoder_ = Decompressor::make(c);
}

std::size_t InputFile::read_decoded(char* buf, std::size_t n) {
    const std::string_view codec = compression_name(decoder_->kind());
    char* out = buf;
    char* const out_end = buf + n;
    while (out == buf) {
        if (raw_pos_ == raw_fill_ && !eof_) {
            raw_pos_ = raw_fill_ = 0;
            raw_fill_ = read_fd(raw_.data(), raw_.size());
        }
        if (raw_pos_ == raw_fill_ && eof_) {
            if (stream_ended_) {
                decoded_end_ = true;
                return 0;
            }
            throw InputError(name_, InputError::Unit::byte, raw_used_,
                             std::string("the ") + std::string(codec) +
                                 " stream is cut short: the compressed file ends before the stream does");
        }
        if (stream_ended_) {
            // More data after a complete stream: another stream of the same kind, or damage.
            const std::string_view next(raw_.data() + raw_pos_, raw_fill_ - raw_pos_);
            const auto again = compression_from_magic(next);
            if (next.size() < 6 && !eof_ && !again) {
                // Too few bytes to tell: move them to the front and read more.
                std::memmove(raw_.data(), raw_.data() + raw_pos_, next.size());
                raw_fill_ = next.size();
                raw_pos_ = 0;
                const std::size_t got = read_fd(raw_.data() + raw_fill_, raw_.size() - raw_fill_);
                raw_fill_ += got;
                if (got > 0) continue;
            }
            if (again != decoder_->kind())
                throw InputError(name_, InputError::Unit::byte, raw_used_,
                                 std::string("data after the end of the ") + std::string(codec) +
                                     " stream that is not another " + std::string(codec) + " stream");
            decoder_ = Decompressor::make(*again);
            stream_ended_ = false;
        }
        const char* in = raw_.data() + raw_pos_;
        const char* const in_begin = in;
        try {
            stream_ended_ = decoder_->step(in, raw_.data() + raw_fill_, out, out_end);
        } catch (const std::runtime_error& e) {
            throw InputError(name_, InputError::Unit::byte, raw_used_ + static_cast<std::uint64_t>(in - in_begin),
                             std::string("damaged ") + std::string(codec) + " data: " + e.what());
        }
        raw_pos_ += static_cast<std::size_t>(in - in_begin);
        raw_used_ += static_cast<std::uint64_t>(in - in_begin);
        if (out == buf && in == in_begin && !stream_ended_ && raw_pos_ < raw_fill_ && out_end > out) {
            // No progress with input and room: should not happen; refuse to spin.
            throw InputError(name_, InputError::Unit::byte, raw_used_,
                             std::string("damaged ") + std::string(codec) + " data: the decoder made no progress");
        }
    }
    return static_cast<std::size_t>(out - buf);
}

}  // namespace evcorner::io
