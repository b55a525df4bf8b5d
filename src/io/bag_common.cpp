// The pieces the bag containers share: byte sources (a file read by seeking, or memory),
// checked little-endian fields, escaping for messages, and a chain of split files.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
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
        if (n > 0) std::memcpy(dst, b_.data() + offset, n);
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

// The output grows as it is produced (doubling, up to `size`): a chunk that declares more
// than it holds costs no more memory than what it holds.
std::string decompress(std::string_view method, std::span<const unsigned char> src, std::vector<unsigned char>& dst,
                       std::size_t size) {
    std::size_t cap = std::min(size, std::max<std::size_t>(std::size_t{1} << 16, src.size() * 4));
    dst.resize(cap);
    std::size_t in = 0, out = 0;
    // Room for more output: false when `size` bytes are out already.
    auto grow = [&] {
        if (out < cap) return true;
        if (cap == size) return false;
        cap = std::min(size, cap * 2);
        dst.resize(cap);
        return true;
    };
    auto more = [&] { return fmt::format("{} data holds more than the {} bytes declared", method, size); };
    std::string err;
    int stalls = 0;  // calls in a row that neither read nor wrote: never loop forever
    const char* stalled = "the compressed data stops decoding (damaged)";
    if (method == "zstd") {
        ZSTD_DCtx* ctx = ZSTD_createDCtx();
        if (!ctx) throw std::bad_alloc();
        for (;;) {
            ZSTD_inBuffer ib{src.data(), src.size(), in};
            ZSTD_outBuffer ob{dst.data(), cap, out};
            const std::size_t r = ZSTD_decompressStream(ctx, &ob, &ib);
            const bool progress = ib.pos != in || ob.pos != out;
            in = ib.pos;
            out = ob.pos;
            if (ZSTD_isError(r)) {
                err = fmt::format("ZSTD: {}", ZSTD_getErrorName(r));
                break;
            }
            if (r == 0 && in == src.size()) break;  // every frame complete
            // With the output full, trailing input (a checksum) may still be consumed.
            if (out == cap && !grow() && !progress) {
                err = more();
                break;
            }
            if (!progress && out < cap && in == src.size()) {
                err = "the ZSTD data is cut short";
                break;
            }
            if (!progress && ++stalls > 4) {
                err = stalled;
                break;
            }
        }
        ZSTD_freeDCtx(ctx);
    } else if (method == "lz4") {
        LZ4F_dctx* ctx = nullptr;
        if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) throw std::bad_alloc();
        for (;;) {
            std::size_t src_left = src.size() - in, dst_left = cap - out;
            const std::size_t r = LZ4F_decompress(ctx, dst.data() + out, &dst_left, src.data() + in, &src_left, nullptr);
            in += src_left;
            out += dst_left;
            if (LZ4F_isError(r)) {
                err = fmt::format("LZ4: {}", LZ4F_getErrorName(r));
                break;
            }
            if (r == 0) {
                if (in == src.size()) break;  // the frame is complete
                LZ4F_resetDecompressionContext(ctx);  // another frame follows
                continue;
            }
            const bool progress = src_left != 0 || dst_left != 0;
            if (out == cap && !grow() && !progress) {
                err = more();
                break;
            }
            if (!progress && out < cap && in == src.size()) {
                err = "the LZ4 frame is cut short";
                break;
            }
            if (!progress && ++stalls > 4) {
                err = stalled;
                break;
            }
        }
        LZ4F_freeDecompressionContext(ctx);
    } else if (method == "bz2") {
        bz_stream bz{};
        if (BZ2_bzDecompressInit(&bz, 0, 0) != BZ_OK) throw std::bad_alloc();
        for (;;) {
            // bzlib counts in unsigned int: feed at most 1 GiB at a time.
            const std::size_t feed = std::min<std::size_t>(src.size() - in, std::size_t{1} << 30);
            const std::size_t room = std::min<std::size_t>(cap - out, std::size_t{1} << 30);
            bz.next_in = const_cast<char*>(reinterpret_cast<const char*>(src.data() + in));
            bz.avail_in = static_cast<unsigned int>(feed);
            bz.next_out = reinterpret_cast<char*>(dst.data() + out);
            bz.avail_out = static_cast<unsigned int>(room);
            const int r = BZ2_bzDecompress(&bz);
            const std::size_t used = feed - bz.avail_in, made = room - bz.avail_out;
            in += used;
            out += made;
            if (r == BZ_STREAM_END) break;
            if (r != BZ_OK) {
                err = fmt::format("bz2 data is corrupt (bzlib error {})", r);
                break;
            }
            if (out == cap && !grow() && used == 0 && made == 0) {
                err = more();
                break;
            }
            if (used == 0 && made == 0 && out < cap && in == src.size()) {
                err = "the bz2 data is cut short";
                break;
            }
            if (used == 0 && made == 0 && ++stalls > 4) {
                err = stalled;
                break;
            }
        }
        BZ2_bzDecompressEnd(&bz);
    } else {
        return fmt::format("unknown compression '{}'", escaped(method));
    }
    if (err.empty() && out != size) err = fmt::format("{} data holds {} bytes, not the {} declared", method, out, size);
    dst.resize(out);
    return err;
}

}  // namespace evcorner::io::detail
