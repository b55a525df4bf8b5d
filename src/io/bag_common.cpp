// The pieces the bag containers share: byte sources (a file read by seeking, or memory),
// checked little-endian fields, escaping for messages, and a chain of split files.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstring>
#include <fmt/format.h>
#include <map>

#include "bag_source.hpp"
#include "evcorner/io/byte_order.hpp"

namespace evcorner::io::detail {

std::uint16_t FieldReader::u16() { return load_le16(take(2)); }
std::uint32_t FieldReader::u32() { return load_le32(take(4)); }
std::uint64_t FieldReader::u64() { return load_le64(take(8)); }
std::string_view FieldReader::str32() {
    const std::uint32_t n = u32();
    const unsigned char* b = take(n);
    return {reinterpret_cast<const char*>(b), n};
}

std::string escaped(std::string_view s) {
    std::string out;
    for (const char c : s) {
        const auto u = static_cast<unsigned char>(c);
        if (u >= 0x20 && u < 0x7F && c != '\\')
            out += c;
        else
            out += fmt::format("\\x{:02x}", u);
    }
    return out;
}

namespace {

class FileBytes final : public ByteSource {
public:
    FileBytes(int fd, std::uint64_t size, std::string name) : fd_(fd), size_(size), name_(std::move(name)) {}
    ~FileBytes() override { ::close(fd_); }
    FileBytes(const FileBytes&) = delete;
    FileBytes& operator=(const FileBytes&) = delete;
    [[nodiscard]] std::uint64_t size() const noexcept override { return size_; }
    void read_at(std::uint64_t offset, std::size_t n, unsigned char* dst) override {
        while (n > 0) {
            const ssize_t got = ::pread(fd_, dst, n, static_cast<off_t>(offset));
            if (got < 0) {
                if (errno == EINTR) continue;
                throw InputError(name_, InputError::Unit::byte, offset, std::string("read failed: ") + std::strerror(errno));
            }
            if (got == 0)
                throw InputError(name_, InputError::Unit::byte, offset, "the file ended while it was read (did it shrink?)");
            dst += got;
            offset += static_cast<std::uint64_t>(got);
            n -= static_cast<std::size_t>(got);
        }
    }

private:
    int fd_;
    std::uint64_t size_;
    std::string name_;
};

class MemoryBytes final : public ByteSource {
public:
    explicit MemoryBytes(std::span<const unsigned char> b) : b_(b) {}
    [[nodiscard]] std::uint64_t size() const noexcept override { return b_.size(); }
    void read_at(std::uint64_t offset, std::size_t n, unsigned char* dst) override {
        std::memcpy(dst, b_.data() + offset, n);
    }
    [[nodiscard]] std::span<const unsigned char> memory() const noexcept override { return b_; }

private:
    std::span<const unsigned char> b_;
};

class ChainSource final : public BagSource {
public:
    ChainSource(std::vector<std::unique_ptr<BagSource>> parts, std::string name, std::string_view format)
        : parts_(std::move(parts)), name_(std::move(name)), format_(format) {
        merge(false);
        for (const auto& p : parts_)
            if (p->bytes_total()) total_ += *p->bytes_total();
    }
    [[nodiscard]] const std::vector<BagTopic>& topics() const noexcept override {
        if (!counted_) merge(true);
        return topics_;
    }
    [[nodiscard]] const std::vector<BagTopic>& topic_types() const noexcept override { return topics_; }
    void select(const std::string& topic) override {
        active_.clear();
        for (std::size_t i = 0; i < parts_.size(); ++i)
            for (const BagTopic& t : parts_[i]->topic_types())
                if (t.name == topic) {
                    parts_[i]->select(topic);
                    active_.push_back(i);
                    break;
                }
        cur_ = 0;
        done_bytes_ = 0;
        index_ = 0;
    }
    bool next(BagMessage& m) override {
        while (cur_ < active_.size()) {
            BagSource& p = *parts_[active_[cur_]];
            if (p.next(m)) {
                m.index = index_++;
                return true;
            }
            if (p.bytes_total()) done_bytes_ += *p.bytes_total();
            ++cur_;
        }
        return false;
    }
    [[nodiscard]] std::string_view format() const noexcept override { return format_; }
    [[nodiscard]] const std::string& name() const noexcept override { return name_; }
    [[nodiscard]] std::uint64_t bytes_consumed() const noexcept override {
        return done_bytes_ + (cur_ < active_.size() ? parts_[active_[cur_]]->bytes_consumed() : 0);
    }
    [[nodiscard]] std::optional<std::uint64_t> bytes_total() const noexcept override { return total_; }

private:
    // The parts' topics merged by name; with their counts summed when `counts`.
    void merge(bool counts) const {
        topics_.clear();
        std::map<std::string, std::size_t> at;
        for (const auto& p : parts_)
            for (const BagTopic& t : counts ? p->topics() : p->topic_types()) {
                const auto [it, fresh] = at.emplace(t.name, topics_.size());
                if (fresh)
                    topics_.push_back(t);
                else
                    topics_[it->second].messages += t.messages;
            }
        counted_ = counts;
    }

    std::vector<std::unique_ptr<BagSource>> parts_;
    std::string name_;
    std::string_view format_;
    mutable std::vector<BagTopic> topics_;
    mutable bool counted_ = false;
    std::vector<std::size_t> active_;
    std::size_t cur_ = 0;
    std::uint64_t total_ = 0;
    std::uint64_t done_bytes_ = 0;
    std::uint64_t index_ = 0;
};

}  // namespace

std::unique_ptr<ByteSource> open_file_bytes(const std::string& path, std::string_view what) {
    const std::string name = path == "-" ? "<stdin>" : path;
    if (path == "-")
        throw InputError(name, fmt::format("{} is read by seeking in a regular file; standard input cannot be read "
                                           "(save it to a file first)", what));
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw InputError(name, std::string("cannot open: ") + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd);
        throw InputError(name, fmt::format("{} is read by seeking in a regular file; a pipe or device cannot be "
                                           "read (save it to a file first)", what));
    }
    return std::make_unique<FileBytes>(fd, static_cast<std::uint64_t>(st.st_size), name);
}

std::unique_ptr<ByteSource> memory_bytes(std::span<const unsigned char> bytes) {
    return std::make_unique<MemoryBytes>(bytes);
}

std::unique_ptr<BagSource> chain_bags(std::vector<std::unique_ptr<BagSource>> parts, std::string name,
                                      std::string_view format) {
    return std::make_unique<ChainSource>(std::move(parts), std::move(name), format);
}

}  // namespace evcorner::io::detail

#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

namespace evcorner::io::detail {

std::string decompress(std::string_view method, std::span<const unsigned char> src, std::vector<unsigned char>& dst,
                       std::size_t size) {
    dst.resize(size);
    if (method == "zstd") {
        const std::size_t r = ZSTD_decompress(dst.data(), size, src.data(), src.size());
        if (ZSTD_isError(r)) return fmt::format("ZSTD: {}", ZSTD_getErrorName(r));
        if (r != size) return fmt::format("ZSTD data holds {} bytes, not the {} declared", r, size);
        return {};
    }
    if (method == "lz4") {
        LZ4F_dctx* ctx = nullptr;
        if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) throw std::bad_alloc();
        std::size_t in = 0, out = 0;
        std::string err;
        for (;;) {
            std::size_t src_left = src.size() - in, dst_left = size - out;
            const std::size_t r = LZ4F_decompress(ctx, dst.data() + out, &dst_left, src.data() + in, &src_left, nullptr);
            in += src_left;
            out += dst_left;
            if (LZ4F_isError(r)) {
                err = fmt::format("LZ4: {}", LZ4F_getErrorName(r));
                break;
            }
            if (r == 0) break;  // the frame is complete
            if (src_left == 0 && dst_left == 0) {
                err = in == src.size() ? "the LZ4 frame is cut short" : fmt::format("LZ4 data holds more than the {} bytes declared", size);
                break;
            }
        }
        LZ4F_freeDecompressionContext(ctx);
        if (err.empty() && out != size) err = fmt::format("LZ4 data holds {} bytes, not the {} declared", out, size);
        return err;
    }
    if (method == "bz2") {
        if (src.size() > UINT_MAX || size > UINT_MAX) return "bz2 data larger than 4 GiB";
        auto dst_len = static_cast<unsigned int>(size);
        // bzlib's prototype takes non-const input it does not write.
        const int r = BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(dst.data()), &dst_len,
                                                 const_cast<char*>(reinterpret_cast<const char*>(src.data())),
                                                 static_cast<unsigned int>(src.size()), 0, 0);
        if (r == BZ_OUTBUFF_FULL) return fmt::format("bz2 data holds more than the {} bytes declared", size);
        if (r != BZ_OK) return fmt::format("bz2 data is corrupt (bzlib error {})", r);
        if (dst_len != size) return fmt::format("bz2 data holds {} bytes, not the {} declared", dst_len, size);
        return {};
    }
    return fmt::format("unknown compression '{}'", escaped(method));
}

}  // namespace evcorner::io::detail
