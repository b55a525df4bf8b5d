// The walk over a record container's messages, shared by the MCAP and ROS 1 containers.

#include "record_bag.hpp"

#include <fmt/format.h>

namespace evcorner::io::detail {

RecordBag::RecordBag(std::unique_ptr<ByteSource> bytes, std::string name, std::uint64_t data_start)
    : b_(std::move(bytes)), name_(std::move(name)), size_(b_->size()), data_start_(data_start), pos_(data_start) {}

bool RecordBag::next(BagMessage& m) {
    while (step()) {
        if (!msg_) continue;
        msg_ = false;
        m = std::move(current_);
        m.index = index_++;
        return true;
    }
    return false;
}

void RecordBag::restart() {
    pos_ = data_start_;
    in_chunk_ = false;
    msg_ = false;
    index_ = 0;
}

void RecordBag::count_records() {
    counting_ = true;
    restart();
    try {
        while (step()) {
        }
    } catch (const InputError&) {
        scan_error_ = std::current_exception();
    }
    counting_ = false;
}

void RecordBag::found(std::span<const unsigned char> data, std::uint64_t data_at, bool in_chunk) {
    current_.data = data;
    if (!in_chunk)
        current_.offset = data_at;
    else if (chunk_plain_)
        current_.offset = chunk_data_at_ + data_at;
    else {
        current_.offset.reset();
        current_.chunk_at = chunk_at_;
        current_.where = fmt::format("in the {} chunk at byte {}, its decompressed byte {}", chunk_method_, chunk_at_,
                                     data_at);
    }
    msg_ = true;
}

void RecordBag::fail(std::uint64_t at, const std::string& reason) const {
    throw InputError(name_, InputError::Unit::byte, at, reason);
}

void RecordBag::chunk_fail(std::size_t at, const std::string& reason) const {
    if (chunk_plain_) fail(chunk_data_at_ + at, reason);
    throw InputError(name_, InputError::Unit::byte, chunk_at_,
                     fmt::format("in the {} chunk, at its decompressed byte {}: {}", chunk_method_, at, reason));
}

}  // namespace evcorner::io::detail
