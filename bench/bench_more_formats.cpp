// Reader throughput (events/s), one core, from the page cache in 64 Ki-event batches:
// ATIS .bin, .npy (the evcorner layout's copying path, a structured array with other
// widths and field order, a plain (N, 4) float array), MATLAB .mat
// (the real rpg_event_lifetime file and a large synthetic one), and ECD text compressed
// with gzip, zstd, bzip2 and xz against the plain text. Synthetic files are written once
// to a temporary folder (4 M events; text 1 M lines) before the first benchmark.

#include <benchmark/benchmark.h>
#include <bzlib.h>
#include <fmt/format.h>
#include <lzma.h>
#include <matio.h>
#include <unistd.h>
#include <zlib.h>
#include <zstd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "npy_bytes.hpp"
#include "read_throughput.hpp"

namespace {

namespace fs = std::filesystem;
constexpr std::size_t kEvents = std::size_t{4} << 20;
constexpr std::size_t kLines = std::size_t{1} << 20;

const fs::path& dir() {
    static const fs::path d = [] {
        auto p = fs::temp_directory_path() / ("evcorner-bench-more-" + std::to_string(::getpid()));
        fs::create_directories(p);
        return p;
    }();
    return d;
}
struct Cleanup {
    ~Cleanup() {
        std::error_code ec;
        fs::remove_all(dir(), ec);
    }
} cleanup;

void save(const std::string& name, const std::string& bytes) {
    std::ofstream(dir() / name, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}
template <class T>
void put(std::string& s, T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    s.append(b, sizeof(T));
}
using evcorner::test::npy_file;

// Event i of the synthetic stream: 240x180, time rising 1 us every 3 events.
inline std::int64_t ti(std::size_t i) { return static_cast<std::int64_t>(i / 3); }
inline unsigned xi(std::size_t i) { return static_cast<unsigned>((i * 7) % 240); }
inline unsigned yi(std::size_t i) { return static_cast<unsigned>((i * 13) % 180); }
inline unsigned pi(std::size_t i) { return static_cast<unsigned>((i >> 2) & 1); }

void make_files() {
    static bool done = false;
    if (done) return;
    done = true;
    std::string atis, fast, fields, n4;
    atis.reserve(kEvents * 5);
    for (std::size_t i = 0; i < kEvents; ++i) {
        const auto t = static_cast<std::uint32_t>(ti(i)) & 0x7fffff;
        atis += static_cast<char>(xi(i));
        atis += static_cast<char>(yi(i));
        atis += static_cast<char>(pi(i) << 7 | t >> 16);
        atis += static_cast<char>(t >> 8);
        atis += static_cast<char>(t);
        put<std::int64_t>(fast, ti(i));
        put<std::uint16_t>(fast, static_cast<std::uint16_t>(xi(i)));
        put<std::uint16_t>(fast, static_cast<std::uint16_t>(yi(i)));
        put<std::uint8_t>(fast, static_cast<std::uint8_t>(pi(i)));
        fast.append(3, '\0');
        put<std::uint32_t>(fields, xi(i));
        put<std::uint32_t>(fields, yi(i));
        put<std::int8_t>(fields, static_cast<std::int8_t>(pi(i) ? 1 : -1));
        put<std::int64_t>(fields, ti(i));
        for (double v : {static_cast<double>(ti(i)) * 1e-6, double(xi(i)), double(yi(i)), double(pi(i))}) put<double>(n4, v);
    }
    save("a.bin", atis);
    save("fast.npy", npy_file(fmt::format("{{'descr': [('t', '<i8'), ('x', '<u2'), ('y', '<u2'), ('p', '|u1'), ('_', '|V3')], "
                                     "'fortran_order': False, 'shape': ({},), }}", kEvents), fast));
    save("fields.npy", npy_file(fmt::format("{{'descr': [('x', '<u4'), ('y', '<u4'), ('p', '|i1'), ('ts', '<i8')], "
                                       "'fortran_order': False, 'shape': ({},), }}", kEvents), fields));
    save("n4.npy", npy_file(fmt::format("{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, 4), }}", kEvents), n4));
    {
        std::vector<double> m(kEvents * 4);
        for (std::size_t i = 0; i < kEvents; ++i) {
            m[i] = xi(i);
            m[kEvents + i] = yi(i);
            m[2 * kEvents + i] = pi(i) ? 1 : -1;
            m[3 * kEvents + i] = static_cast<double>(ti(i));
        }
        std::size_t dims[2] = {kEvents, 4};
        mat_t* f = Mat_CreateVer((dir() / "big.mat").c_str(), nullptr, MAT_FT_MAT5);
        matvar_t* v = Mat_VarCreate("events", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, m.data(), 0);
        Mat_VarWrite(f, v, MAT_COMPRESSION_ZLIB);
        Mat_VarFree(v);
        Mat_Close(f);
    }
    std::string text;
    for (std::size_t i = 0; i < kLines; ++i)
        text += fmt::format("{}.{:06} {} {} {}\n", ti(i) / 1000000, ti(i) % 1000000, xi(i), yi(i), pi(i));
    save("t.txt", text);
    {
        uLongf n = compressBound(static_cast<uLong>(text.size())) + 64;
        std::string out(n, '\0');
        z_stream z{};
        deflateInit2(&z, 6, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY);
        z.next_in = reinterpret_cast<Bytef*>(text.data());
        z.avail_in = static_cast<uInt>(text.size());
        z.next_out = reinterpret_cast<Bytef*>(out.data());
        z.avail_out = static_cast<uInt>(out.size());
        deflate(&z, Z_FINISH);
        out.resize(z.total_out);
        deflateEnd(&z);
        save("t.gz", out);
    }
    {
        std::string out(ZSTD_compressBound(text.size()), '\0');
        out.resize(ZSTD_compress(out.data(), out.size(), text.data(), text.size(), 3));
        save("t.zst", out);
    }
    {
        std::string out(text.size() + text.size() / 100 + 1024, '\0');
        auto n = static_cast<unsigned>(out.size());
        BZ2_bzBuffToBuffCompress(out.data(), &n, text.data(), static_cast<unsigned>(text.size()), 9, 0, 0);
        out.resize(n);
        save("t.bz2", out);
    }
    {
        std::string out(lzma_stream_buffer_bound(text.size()), '\0');
        std::size_t pos = 0;
        lzma_easy_buffer_encode(6, LZMA_CHECK_CRC64, nullptr, reinterpret_cast<const std::uint8_t*>(text.data()),
                                text.size(), reinterpret_cast<std::uint8_t*>(out.data()), &pos, out.size());
        out.resize(pos);
        save("t.xz", out);
    }
}

void synthetic(benchmark::State& state, const std::string& name, const char* format) {
    make_files();
    evcorner::bench::read_throughput(state, (dir() / name).string(), format);
}
void real(benchmark::State& state, const std::string& rel) {
    evcorner::bench::read_throughput(state, evcorner::bench::real_data_file(rel));
}

BENCHMARK_CAPTURE(synthetic, atis_bin, std::string("a.bin"), "atis-bin")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(real, atis_bin_ncaltech101, std::string("evlib-shiba/faces_easy_0001.bin"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(synthetic, npy_evcorner_layout, std::string("fast.npy"), "auto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(synthetic, npy_fields_u4_i1_i8, std::string("fields.npy"), "auto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(synthetic, npy_n_by_4_f8, std::string("n4.npy"), "auto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(synthetic, mat_double_zlib, std::string("big.mat"), "auto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(real, mat_rpg_stripes, std::string("rpg-event-lifetime/stripes.mat"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(synthetic, text_plain, std::string("t.txt"), "auto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(synthetic, text_gzip, std::string("t.gz"), "auto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(synthetic, text_zstd, std::string("t.zst"), "auto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(synthetic, text_bzip2, std::string("t.bz2"), "auto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(synthetic, text_xz, std::string("t.xz"), "auto")->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
