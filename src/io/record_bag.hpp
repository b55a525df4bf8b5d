#pragma once
// What the MCAP and ROS 1 containers share: a file of records read by seeking, records
// that may lie in (compressed) chunks, and the walk over the chosen topic's messages one
// record at a time. A container says how to read one record (step()) and where its
// channels are; select(), next() and the accessors are written here once.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "bag_source.hpp"

namespace evcorner::io::detail {

class RecordBag : public BagSource {
public:
    [[nodiscard]] const std::vector<BagTopic>& topics() const noexcept override { return topics_; }
    bool next(BagMessage& m) override;
    [[nodiscard]] const std::string& name() const noexcept override { return name_; }
    [[nodiscard]] std::uint64_t bytes_consumed() const noexcept override { return pos_; }
    [[nodiscard]] std::optional<std::uint64_t> bytes_total() const noexcept override { return size_; }

protected:
    /// `data_start`: the offset of the first record (restart() goes back there).
    RecordBag(std::unique_ptr<ByteSource> bytes, std::string name, std::uint64_t data_start);

    /// One record of a chunk, or of the file; true while there are records. Sets msg_
    /// (and current_, through found()) when the record is a message of a selected channel.
    virtual bool step() = 0;
    /// Back to the first record, nothing read.
    virtual void restart();

    /// select() for a container whose `channels` map an id to a channel with a `topic`.
    template <class Channels>
    void select_channels(const Channels& channels, const std::string& topic) {
        selected_.clear();
        for (const auto& [id, c] : channels)
            if (c.topic == topic) selected_.insert(id);
        restart();
    }
    /// A pass over all records with counting_ set; damage it meets stops it quietly
    /// (kept in scan_error_: reading the events reports it where it lies).
    void count_records();
    /// A selected message: `data` at `data_at` (a file offset, or one in the chunk).
    void found(std::span<const unsigned char> data, std::uint64_t data_at, bool in_chunk);

    [[noreturn]] void fail(std::uint64_t at, const std::string& reason) const;
    /// Damage at byte `at` of the current chunk (decompressed when it was compressed).
    [[noreturn]] void chunk_fail(std::size_t at, const std::string& reason) const;

    std::unique_ptr<ByteSource> b_;
    std::string name_;
    std::uint64_t size_ = 0;
    std::uint64_t data_start_ = 0;
    std::vector<BagTopic> topics_;
    std::set<std::uint32_t> selected_;
    bool counting_ = false;
    std::exception_ptr scan_error_;  // damage the pass over the file met

    std::uint64_t pos_ = 0;
    std::vector<unsigned char> rec_;
    std::vector<unsigned char> raw_;
    std::vector<unsigned char> chunk_;
    std::size_t chunk_pos_ = 0;
    bool in_chunk_ = false;
    bool chunk_plain_ = false;
    std::string chunk_method_;
    std::uint64_t chunk_at_ = 0;
    std::uint64_t chunk_data_at_ = 0;

    BagMessage current_;
    bool msg_ = false;
    std::uint64_t index_ = 0;
};

}  // namespace evcorner::io::detail
