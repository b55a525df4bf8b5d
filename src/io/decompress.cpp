#include "evcorner/io/decompress.hpp"

#include <bzlib.h>
#include <lzma.h>
#include <zlib.h>
#include <zstd.h>

#include <stdexcept>
#include <string>

namespace evcorner::io {

std::optional<Compression> compression_from_magic(std::string_view h) noexcept {
    if (h.size() >= 2 && h[0] == '\x1f' && h[1] == '\x8b') return Compression::gzip;
    if (h.size() >= 4 && h.substr(0, 4) == std::string_view("\x28\xb5\x2f\xfd", 4)) return Compression::zstd;
    if (h.size() >= 4 && h.substr(0, 3) == "BZh" && h[3] >= '1' && h[3] <= '9') return Compression::bzip2;
    if (h.size() >= 6 && h.substr(0, 6) == std::string_view("\xfd" "7zXZ\0", 6)) return Compression::xz;
    return std::nullopt;
}

std::string_view compression_name(Compression c) noexcept {
    switch (c) {
        case Compression::gzip: return "gzip";
        case Compression::zstd: return "zstd";
        case Compression::bzip2: return "bzip2";
        case Compression::xz: return "xz";
    }
    return "?";
}

namespace {

class Gzip final : public Decompressor {
public:
    Gzip() {
        if (inflateInit2(&z_, 16 + MAX_WBITS) != Z_OK) throw std::runtime_error("zlib: cannot initialise");
    }
    ~Gzip() override { inflateEnd(&z_); }
    bool step(const char*& in, const char* in_end, char*& out, char* out_end) override {
        z_.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in));
        z_.avail_in = static_cast<uInt>(in_end - in);
        z_.next_out = reinterpret_cast<Bytef*>(out);
        z_.avail_out = static_cast<uInt>(out_end - out);
        const int r = inflate(&z_, Z_NO_FLUSH);
        in = reinterpret_cast<const char*>(z_.next_in);
        out = reinterpret_cast<char*>(z_.next_out);
        if (r == Z_STREAM_END) return true;
        if (r == Z_OK || r == Z_BUF_ERROR) return false;
        throw std::runtime_error(z_.msg != nullptr ? z_.msg : "inflate error " + std::to_string(r));
    }
    [[nodiscard]] Compression kind() const noexcept override { return Compression::gzip; }

private:
    z_stream z_{};
};

class Zstd final : public Decompressor {
public:
    Zstd() : d_(ZSTD_createDStream()) {
        if (d_ == nullptr) throw std::runtime_error("zstd: cannot initialise");
    }
    ~Zstd() override { ZSTD_freeDStream(d_); }
    bool step(const char*& in, const char* in_end, char*& out, char* out_end) override {
        ZSTD_inBuffer i{in, static_cast<std::size_t>(in_end - in), 0};
        ZSTD_outBuffer o{out, static_cast<std::size_t>(out_end - out), 0};
        const std::size_t r = ZSTD_decompressStream(d_, &o, &i);
        in += i.pos;
        out += o.pos;
        if (ZSTD_isError(r)) throw std::runtime_error(ZSTD_getErrorName(r));
        return r == 0;  // a frame ended and was flushed completely
    }
    [[nodiscard]] Compression kind() const noexcept override { return Compression::zstd; }

private:
    ZSTD_DStream* d_;
};

class Bzip2 final : public Decompressor {
public:
    Bzip2() {
        if (BZ2_bzDecompressInit(&s_, 0, 0) != BZ_OK) throw std::runtime_error("bzip2: cannot initialise");
    }
    ~Bzip2() override { BZ2_bzDecompressEnd(&s_); }
    bool step(const char*& in, const char* in_end, char*& out, char* out_end) override {
        s_.next_in = const_cast<char*>(in);
        s_.avail_in = static_cast<unsigned>(in_end - in);
        s_.next_out = out;
        s_.avail_out = static_cast<unsigned>(out_end - out);
        const int r = BZ2_bzDecompress(&s_);
        in = s_.next_in;
        out = s_.next_out;
        if (r == BZ_STREAM_END) return true;
        if (r == BZ_OK) return false;
        throw std::runtime_error(r == BZ_DATA_ERROR_MAGIC ? "not bzip2 data"
                                 : r == BZ_DATA_ERROR    ? "data integrity error (bad CRC or block)"
                                                         : "bzip2 error " + std::to_string(r));
    }
    [[nodiscard]] Compression kind() const noexcept override { return Compression::bzip2; }

private:
    bz_stream s_{};
};

class Xz final : public Decompressor {
public:
    Xz() {
        if (lzma_stream_decoder(&s_, UINT64_MAX, 0) != LZMA_OK) throw std::runtime_error("xz: cannot initialise");
    }
    ~Xz() override { lzma_end(&s_); }
    bool step(const char*& in, const char* in_end, char*& out, char* out_end) override {
        s_.next_in = reinterpret_cast<const std::uint8_t*>(in);
        s_.avail_in = static_cast<std::size_t>(in_end - in);
        s_.next_out = reinterpret_cast<std::uint8_t*>(out);
        s_.avail_out = static_cast<std::size_t>(out_end - out);
        const lzma_ret r = lzma_code(&s_, LZMA_RUN);
        in = reinterpret_cast<const char*>(s_.next_in);
        out = reinterpret_cast<char*>(s_.next_out);
        if (r == LZMA_STREAM_END) return true;
        if (r == LZMA_OK || r == LZMA_BUF_ERROR) return false;
        throw std::runtime_error(r == LZMA_DATA_ERROR      ? "corrupt data"
                                 : r == LZMA_FORMAT_ERROR  ? "not xz data"
                                 : r == LZMA_OPTIONS_ERROR ? "unsupported xz options"
                                 : r == LZMA_MEM_ERROR     ? "out of memory"
                                                           : "xz error " + std::to_string(static_cast<int>(r)));
    }
    [[nodiscard]] Compression kind() const noexcept override { return Compression::xz; }

private:
    lzma_stream s_ = LZMA_STREAM_INIT;
};

}  // namespace

std::unique_ptr<Decompressor> Decompressor::make(Compression c) {
    switch (c) {
        case Compression::gzip: return std::make_unique<Gzip>();
        case Compression::zstd: return std::make_unique<Zstd>();
        case Compression::bzip2: return std::make_unique<Bzip2>();
        case Compression::xz: return std::make_unique<Xz>();
    }
    throw std::logic_error("unknown compression");
}

}  // namespace evcorner::io
