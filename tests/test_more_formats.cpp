// ATIS .bin (N-MNIST, N-Caltech101), MATLAB .mat, gzip / zstd / bzip2 /
// xz compressed text and CSV, UTF-8 BOMs, .npy with fields found by name and plain (N, 4)
// arrays, and the "unsupported format" messages of the detection. The real recordings'
// figures come from the data READMEs; the rest are crafted files.

#include <bzlib.h>
#include <gtest/gtest.h>
#include <lzma.h>
#include <matio.h>
#include <zlib.h>
#include <zstd.h>

#include <cstring>
#include <fstream>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_test_util.hpp"
#include "evcorner/io/atis_reader.hpp"
#include "evcorner/io/mat_reader.hpp"
#include "evcorner/io/npy.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/text_reader.hpp"
#include "io_test_util.hpp"
#include "test_util.hpp"

namespace evcorner::test {
namespace {

struct RealFile {
    const char* path;  // under data/real
    const char* format;
    Figures fig;
};

// tonic-testdata, evlib-shiba and rpg-event-lifetime READMEs ("Verified contents").
const RealFile kRealFiles[] = {
    {"tonic-testdata/sample_nmnist.bin", "atis-bin", {4325, 654, 311175, 0, 33, 0, 33, 2145, 2180}},
    {"evlib-shiba/faces_easy_0001.bin", "atis-bin", {67445, 6, 299364, 0, 150, 0, 172, 33770, 33675}},
    {"rpg-event-lifetime/building.mat", "mat", {115839, 0, 1100005, 0, 127, 0, 127, 58068, 57771}},
    {"rpg-event-lifetime/flip.mat", "mat", {175136, 0, 2026984, 0, 127, 0, 127, 104472, 70664}},
    {"rpg-event-lifetime/garfield.mat", "mat", {202235, 0, 738000, 0, 127, 0, 127, 110725, 91510}},
    {"rpg-event-lifetime/stripes.mat", "mat", {340394, 0, 1197752, 0, 127, 0, 127, 230210, 110184}},
};

std::string real(const char* p) { return (shared_data() / "real" / p).string(); }

TEST(MoreFormatsReal, FiguresMatchReadme) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const RealFile& f : kRealFiles) {
        auto reader = io::open_event_reader(real(f.path));  // told by content (and .bin)
        EXPECT_EQ(reader->format(), f.format) << f.path;
        const ReadResult r = read_all(*reader);
        ASSERT_FALSE(r.failed) << r.error;
        expect_figures(r.events, f.fig, f.path);
        // Forced by name too, and in small batches (ATIS runs cross batch edges).
        auto forced = io::open_event_reader(real(f.path), {}, f.format);
        const ReadResult b = read_all(*forced, 7);
        ASSERT_FALSE(b.failed) << b.error;
        EXPECT_EQ(b.events, r.events) << f.path;
    }
}

TEST(MoreFormatsReal, AtisReadsThroughAPipe) {
    EVCORNER_REQUIRE_SHARED_DATA();
    // A pipe has no name to tell ATIS by: --format atis-bin reads it.
    const std::string p = real("tonic-testdata/sample_nmnist.bin");
    io::AtisReader direct(p);
    const ReadResult a = read_all(direct);
    ASSERT_FALSE(a.failed) << a.error;
    EXPECT_EQ(a.events.size(), 4325u);
    EXPECT_THROW(io::open_event_reader("/dev/stdin", {}, "mat"), InputError);  // .mat needs a regular file
}

class MoreFormatsCli : public CliTest {};

TEST_F(MoreFormatsCli, InfoAndConvertGiveTheFigures) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const RealFile& f : kRealFiles) {
        SCOPED_TRACE(f.path);
        const CliResult r = run("info --no-progress --json info.json '" + real(f.path) + "'");
        ASSERT_EQ(r.status, 0) << r.err;
        const auto j = nlohmann::json::parse(slurp(dir_ / "info.json"));
        EXPECT_EQ(j["format"], f.format);
        EXPECT_EQ(j["events"], f.fig.events);
        EXPECT_EQ(j["t_first_us"], f.fig.t_min);
        EXPECT_EQ(j["t_last_us"], f.fig.t_max);
        EXPECT_EQ(j["x_min"], f.fig.x_min);
        EXPECT_EQ(j["x_max"], f.fig.x_max);
        EXPECT_EQ(j["y_min"], f.fig.y_min);
        EXPECT_EQ(j["y_max"], f.fig.y_max);
        EXPECT_EQ(j["on"], f.fig.on);
        EXPECT_EQ(j["off"], f.fig.off);
        const CliResult c = run("convert -q '" + real(f.path) + "' out.txt");
        ASSERT_EQ(c.status, 0) << c.err;
        io::ReaderOptions o;
        o.fallback_sensor = std::nullopt;
        expect_figures(io::read_text_file((dir_ / "out.txt").string(), o), f.fig, std::string(f.path) + " -> txt");
    }
}

// ---------------------------------------------------------------- compressed text

std::string gzip_bytes(const std::string& s) {
    z_stream z{};
    EXPECT_EQ(deflateInit2(&z, 6, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY), Z_OK);
    std::string out(deflateBound(&z, s.size()) + 64, '\0');
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(s.data()));
    z.avail_in = static_cast<uInt>(s.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = static_cast<uInt>(out.size());
    EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
    out.resize(z.total_out);
    deflateEnd(&z);
    return out;
}
std::string zstd_bytes(const std::string& s) {
    std::string out(ZSTD_compressBound(s.size()), '\0');
    const std::size_t n = ZSTD_compress(out.data(), out.size(), s.data(), s.size(), 3);
    EXPECT_FALSE(ZSTD_isError(n));
    out.resize(n);
    return out;
}
std::string bzip2_bytes(const std::string& s) {
    std::string out(s.size() + s.size() / 100 + 1024, '\0');
    auto n = static_cast<unsigned>(out.size());
    EXPECT_EQ(BZ2_bzBuffToBuffCompress(out.data(), &n, const_cast<char*>(s.data()), static_cast<unsigned>(s.size()), 9,
                                       0, 0),
              BZ_OK);
    out.resize(n);
    return out;
}
std::string xz_bytes(const std::string& s) {
    std::string out(lzma_stream_buffer_bound(s.size()), '\0');
    std::size_t pos = 0;
    EXPECT_EQ(lzma_easy_buffer_encode(6, LZMA_CHECK_CRC64, nullptr, reinterpret_cast<const std::uint8_t*>(s.data()),
                                      s.size(), reinterpret_cast<std::uint8_t*>(out.data()), &pos, out.size()),
              LZMA_OK);
    out.resize(pos);
    return out;
}

struct Codec {
    const char* name;
    std::string (*compress)(const std::string&);
};
const Codec kCodecs[] = {{"gzip", gzip_bytes}, {"zstd", zstd_bytes}, {"bzip2", bzip2_bytes}, {"xz", xz_bytes}};

// The first `lines` lines of the bundled ECD recording.
std::string ecd_cut(std::size_t lines) {
    const std::string all = slurp(bundled_data() / "ecd/shapes_translation/events.txt");
    std::size_t pos = 0;
    for (std::size_t i = 0; i < lines && pos != std::string::npos; ++i) pos = all.find('\n', pos + 1);
    return all.substr(0, pos + 1);
}

std::vector<Event> read_path(const std::string& path, io::ReaderOptions o = {}, std::string_view format = "auto") {
    auto r = io::open_event_reader(path, std::move(o), format);
    return io::read_all_events(*r);
}

TEST(Compressed, EveryCodecGivesThePlainFilesEvents) {
    TempDir tmp;
    const std::string text = ecd_cut(30000);
    const auto plain = read_path(tmp.write("cut.txt", text));
    ASSERT_EQ(plain.size(), 30000u);
    // The same events as CSV.
    std::string csv = "x,y,p,t\n";
    for (const Event& e : plain) csv += fmt::format("{},{},{},{}\n", e.x, e.y, int{e.p}, e.t);
    for (const Codec& c : kCodecs) {
        SCOPED_TRACE(c.name);
        // Named without a telling extension: the magic bytes decide.
        const std::string path = tmp.write(std::string("cut-") + c.name + ".data", c.compress(text));
        auto r = io::open_event_reader(path);
        EXPECT_EQ(r->format(), std::string("ecd-text+") + c.name);
        EXPECT_EQ(io::read_all_events(*r), plain);
        // Forced text format still decompresses; CSV likewise.
        EXPECT_EQ(read_path(path, {}, "ecd-text"), plain);
        const std::string cpath = tmp.write(std::string("cut-") + c.name + ".csv.z", c.compress(csv));
        auto cr = io::open_event_reader(cpath);
        EXPECT_EQ(cr->format(), std::string("csv+") + c.name);
        EXPECT_EQ(io::read_all_events(*cr), plain);
        // Two streams one after the other are one file (cat a.gz b.gz).
        const std::string half1 = ecd_cut(100), half2 = text.substr(half1.size());
        const auto two = read_path(tmp.write(std::string("two-") + c.name, c.compress(half1) + c.compress(half2)));
        EXPECT_EQ(two, plain);
    }
}

TEST(Compressed, CutShortOrDamagedStreamIsAnErrorAtTheLine) {
    TempDir tmp;
    const std::string text = ecd_cut(30000);
    for (const Codec& c : kCodecs) {
        SCOPED_TRACE(c.name);
        const std::string z = c.compress(text);
        const std::string path = tmp.write(std::string("cut.") + c.name, z.substr(0, z.size() / 2));
        std::unique_ptr<io::EventReader> r;
        try {
            r = io::open_event_reader(path);
        } catch (const InputError& e) {
            // bzip2 decodes 900 kB blocks whole: cut inside the first block, nothing comes
            // out, and detection itself meets the end of the data.
            EXPECT_STREQ(c.name, "bzip2") << e.what();
            EXPECT_NE(std::string(e.what()).find("the bzip2 stream is cut short"), std::string::npos) << e.what();
            continue;
        }
        const ReadResult res = read_all(*r);
        ASSERT_TRUE(res.failed);
        EXPECT_GT(res.events.size(), 1000u);  // the lines before the cut come first
        EXPECT_LT(res.events.size(), 30000u);
        EXPECT_EQ(res.error_unit, InputError::Unit::line);
        EXPECT_EQ(res.error_position, res.events.size() + 1) << res.error;  // the line it stopped in
        EXPECT_NE(res.error.find(std::string("the ") + c.name + " stream is cut short"), std::string::npos) << res.error;
        EXPECT_NE(res.error.find("compressed byte"), std::string::npos) << res.error;
    }
    // Damage in the middle of a gzip stream: the decoder's reason.
    std::string z = gzip_bytes(text);
    for (std::size_t i = z.size() / 2; i < z.size() / 2 + 64; ++i) z[i] = static_cast<char>(z[i] ^ 0x5a);
    auto r = io::open_event_reader(tmp.write("bad.gz", z));
    const ReadResult res = read_all(*r);
    ASSERT_TRUE(res.failed);
    EXPECT_NE(res.error.find("damaged gzip data"), std::string::npos) << res.error;
    // Junk after a complete stream is not silently ignored.
    const ReadResult tail = [&] {
        auto t = io::open_event_reader(tmp.write("tail.gz", gzip_bytes(text) + "garbage!"));
        return read_all(*t);
    }();
    ASSERT_TRUE(tail.failed);
    EXPECT_NE(tail.error.find("data after the end of the gzip stream"), std::string::npos) << tail.error;
}

TEST_F(MoreFormatsCli, CompressedTextThroughInfoAndStandardInput) {
    const std::string text = ecd_cut(2000);
    write("cut.txt", text);
    write("cut.txt.zst", zstd_bytes(text));
    const CliResult plain = run("info --no-progress --json a.json cut.txt");
    ASSERT_EQ(plain.status, 0) << plain.err;
    const CliResult z = run("info --no-progress --json b.json -", "cut.txt.zst");
    ASSERT_EQ(z.status, 0) << z.err;
    auto a = nlohmann::json::parse(slurp(dir_ / "a.json")), b = nlohmann::json::parse(slurp(dir_ / "b.json"));
    EXPECT_EQ(b["format"], "ecd-text+zstd");
    for (const char* k : {"events", "t_first_us", "t_last_us", "x_min", "x_max", "y_min", "y_max", "on"})
        EXPECT_EQ(a[k], b[k]) << k;
    // convert: the compressed copy gives the plain file's events.
    write("cut.csv.gz", gzip_bytes(text));  // ECD text inside, whatever the name says
    ASSERT_EQ(run("convert -q cut.csv.gz back.txt").status, 0);
    EXPECT_EQ(read_path((dir_ / "back.txt").string()), read_path((dir_ / "cut.txt").string()));
}

TEST_F(MoreFormatsCli, AtisFromStandardInputWithFormat) {
    EVCORNER_REQUIRE_SHARED_DATA();
    const std::string nmnist = real("tonic-testdata/sample_nmnist.bin");
    const CliResult r = run("info --no-progress --format atis-bin --json a.json -", nmnist);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(slurp(dir_ / "a.json"));
    EXPECT_EQ(j["events"], 4325);
    EXPECT_EQ(j["t_last_us"], 311175);
    // Without --format a pipe has no name to tell ATIS by: refused, naming the option.
    const CliResult n = run("info --no-progress -", nmnist);
    EXPECT_EQ(n.status, 1);
    EXPECT_NE(n.err.find("unsupported format"), std::string::npos) << n.err;
    EXPECT_NE(n.err.find("--format atis-bin"), std::string::npos) << n.err;
}

// ---------------------------------------------------------------- BOM

TEST(Bom, TextAndCsvAcceptAUtf8ByteOrderMark) {
    TempDir tmp;
    const std::string bom = "\xEF\xBB\xBF";
    const std::vector<Event> want = {{1, 2, 3, 1}, {5, 6, 7, 0}};
    auto t = io::open_event_reader(tmp.write("b.txt", bom + "0.000001 2 3 1\n0.000005 6 7 0\n"));
    EXPECT_EQ(t->format(), "ecd-text");
    EXPECT_EQ(io::read_all_events(*t), want);
    auto c = io::open_event_reader(tmp.write("b.csv", bom + "x,y,p,t\n2,3,1,1\n6,7,0,5\n"));
    EXPECT_EQ(c->format(), "csv");
    EXPECT_EQ(io::read_all_events(*c), want);
    auto c2 = io::open_event_reader(tmp.write("b2.csv", bom + "1,2,3,1\n5,6,7,0\n"));
    EXPECT_EQ(io::read_all_events(*c2), want);
    // Compressed, with a BOM inside.
    EXPECT_EQ(read_path(tmp.write("b.gz", gzip_bytes(bom + "x,y,p,t\n2,3,1,1\n6,7,0,5\n"))), want);
    // A BOM anywhere but the start is still an error (escaped in the message), at its line.
    auto bad = io::open_event_reader(tmp.write("m.txt", "0.000001 2 3 1\n" + bom + "0.000005 6 7 0\n"));
    const ReadResult r = read_all(*bad);
    ASSERT_TRUE(r.failed);
    EXPECT_EQ(r.error_position, 2u);
    EXPECT_NE(r.error.find("\\xef\\xbb\\xbf"), std::string::npos) << r.error;
}

// ---------------------------------------------------------------- .npy

using test::npy_file;

// Appends v as `size` bytes, little- or big-endian.
template <class T>
void put(std::string& s, T v, bool big = false) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (big) std::reverse(b, b + sizeof(T));
    s.append(b, sizeof(T));
}

const std::vector<Event> kNpyEvents = {{10, 1, 2, 1}, {20, 300, 4, 0}, {20, 5, 65535, 1}, {1000000, 7, 8, 0}};

TEST(NpyGeneral, StructuredFieldsByNameAnyOrderWidthAndByteOrder) {
    TempDir tmp;
    // u4 coordinates, i4 time, bool polarity, other fields between, fields out of order.
    {
        std::string d;
        for (const Event& e : kNpyEvents) {
            put<std::uint32_t>(d, e.x);
            put<double>(d, 3.5);  // not an event field
            put<std::uint32_t>(d, e.y);
            put<std::uint8_t>(d, e.p);
            put<std::int32_t>(d, static_cast<std::int32_t>(e.t));
        }
        const auto f = npy_file("{'descr': [('x', '<u4'), ('extra', '<f8'), ('y', '<u4'), ('polarity', '|b1'), "
                                "('timestamp', '<i4')], 'fortran_order': False, 'shape': (4,), }",
                                d);
        io::ReaderOptions o;
        o.fallback_sensor = std::nullopt;
        EXPECT_EQ(read_path(tmp.write("a.npy", f), o), kNpyEvents);
    }
    // Big-endian i2 / u8 fields, polarity -1/+1 as i1, time u8 big-endian.
    {
        std::string d;
        for (const Event& e : kNpyEvents) {
            put<std::uint64_t>(d, static_cast<std::uint64_t>(e.t), true);
            put<std::int8_t>(d, e.p ? 1 : -1);
            put<std::uint16_t>(d, e.y, true);
            put<std::uint16_t>(d, e.x, true);
        }
        const auto f = npy_file("{'descr': [('t', '>u8'), ('p', '|i1'), ('y', '>u2'), ('x', '>u2')], "
                                "'fortran_order': False, 'shape': (4,), }",
                                d);
        io::ReaderOptions o;
        o.fallback_sensor = std::nullopt;
        EXPECT_EQ(read_path(tmp.write("b.npy", f), o), kNpyEvents);
    }
    // Float time in seconds (the default for floats), float coordinates; --time-unit us too.
    {
        std::string d, d_us;
        for (const Event& e : kNpyEvents) {
            for (std::string* s : {&d, &d_us}) {
                put<double>(*s, s == &d ? static_cast<double>(e.t) * 1e-6 : static_cast<double>(e.t));
                put<float>(*s, static_cast<float>(e.x));
                put<float>(*s, static_cast<float>(e.y));
                put<float>(*s, e.p ? 1.0f : -1.0f);
            }
        }
        const std::string dict = "{'descr': [('t', '<f8'), ('x', '<f4'), ('y', '<f4'), ('on', '<f4')], "
                                 "'fortran_order': False, 'shape': (4,), }";
        io::ReaderOptions o;
        o.fallback_sensor = std::nullopt;
        EXPECT_EQ(read_path(tmp.write("c.npy", npy_file(dict, d)), o), kNpyEvents);
        o.csv_time_unit = "us";
        EXPECT_EQ(read_path(tmp.write("d.npy", npy_file(dict, d_us)), o), kNpyEvents);
    }
    // Integer time in nanoseconds when told.
    {
        std::string d;
        for (const Event& e : kNpyEvents) {
            put<std::int64_t>(d, e.t * 1000 + 499);  // rounds down to e.t
            put<std::uint16_t>(d, e.x);
            put<std::uint16_t>(d, e.y);
            put<std::uint8_t>(d, e.p);
        }
        io::ReaderOptions o;
        o.fallback_sensor = std::nullopt;
        o.csv_time_unit = "ns";
        const auto f = npy_file("{'descr': [('t', '<i8'), ('x', '<u2'), ('y', '<u2'), ('p', '|u1')], "
                                "'fortran_order': False, 'shape': (4,), }",
                                d);
        EXPECT_EQ(read_path(tmp.write("e.npy", f), o), kNpyEvents);
    }
}

// A float time read in a unit of whole numbers (us, ns, given) with a fraction is an
// error at the record, not a rounding: a fraction there means the times are in another unit.
TEST(NpyGeneral, FractionalTimeInWholeUnitIsAnError) {
    TempDir tmp;
    std::string d;
    for (const double t : {2.0, 3.0, 3.5}) {
        put<double>(d, t);
        put<double>(d, 1.0);
        put<double>(d, 1.0);
        put<double>(d, 1.0);
    }
    const std::string path = tmp.write("f.npy", npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }", d));
    for (const std::string unit : {"us", "ns"}) {
        io::ReaderOptions o;
        o.csv_time_unit = unit;
        auto r = io::open_event_reader(path, o);
        const ReadResult res = read_all(*r);
        ASSERT_TRUE(res.failed) << unit;
        EXPECT_EQ(res.events.size(), 2u);
        EXPECT_EQ(res.error_unit, InputError::Unit::byte);
        EXPECT_NE(res.error.find("time 3.5 has a fraction, but --time-unit is " + unit), std::string::npos) << res.error;
    }
    io::ReaderOptions ms;
    ms.csv_time_unit = "ms";  // a fraction of a millisecond is microseconds: read
    auto r = io::open_event_reader(path, ms);
    const ReadResult res = read_all(*r);
    ASSERT_FALSE(res.failed) << res.error;
    ASSERT_EQ(res.events.size(), 3u);
    EXPECT_EQ(res.events[2].t, 3500);
}

TEST(NpyGeneral, PlainNBy4ArraysWithColumnNames) {
    TempDir tmp;
    std::string tx, xy;  // t,x,y,p (the default) and x,y,p,t orders
    for (const Event& e : kNpyEvents) {
        for (double v : {static_cast<double>(e.t) * 1e-6, static_cast<double>(e.x), static_cast<double>(e.y), static_cast<double>(e.p)}) put<double>(tx, v);
        for (std::int64_t v : {std::int64_t{e.x}, std::int64_t{e.y}, std::int64_t{e.p}, e.t}) put<std::int64_t>(xy, v);
    }
    io::ReaderOptions o;
    o.fallback_sensor = std::nullopt;
    EXPECT_EQ(read_path(tmp.write("a.npy", npy_file("{'descr': '<f8', 'fortran_order': False, 'shape': (4, 4), }", tx)), o),
              kNpyEvents);
    const std::string b = tmp.write("b.npy", npy_file("{'descr': '<i8', 'fortran_order': False, 'shape': (4, 4), }", xy));
    o.npy_columns = "x,y,p,t";
    EXPECT_EQ(read_path(b, o), kNpyEvents);
    // Read as the default t,x,y,p those columns are not events: an error naming the offset.
    o.npy_columns.clear();
    auto r = io::open_event_reader(b, o);
    const ReadResult res = read_all(*r);
    ASSERT_TRUE(res.failed);
    EXPECT_EQ(res.error_unit, InputError::Unit::byte);
    o.npy_columns = "x,y,t";
    EXPECT_THROW(io::open_event_reader(b, o), InputError);
}

TEST(NpyGeneral, RefusalsNameTheFileAndTheReason) {
    TempDir tmp;
    const auto refused = [&](const std::string& dict, const std::string& want) {
        const std::string path = tmp.write("r.npy", npy_file(dict, std::string(64, '\0')));
        try {
            io::open_event_reader(path);
            ADD_FAILURE() << "accepted: " << dict;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
        }
    };
    refused("{'descr': '<f8', 'fortran_order': True, 'shape': (4, 4), }", "Fortran-order arrays are not supported");
    refused("{'descr': '<c16', 'fortran_order': False, 'shape': (2, 4), }", "unsupported dtype '<c16'");
    refused("{'descr': '|O', 'fortran_order': False, 'shape': (2, 4), }", "unsupported dtype '|O'");
    refused("{'descr': '<f8', 'fortran_order': False, 'shape': (8,), }", "must have the shape (N, 4)");
    refused("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 4, 1), }", "must have the shape (N, 4)");
    refused("{'descr': [('t', '<i8'), ('x', '<u2'), ('y', '<u2')], 'fortran_order': False, 'shape': (2,), }",
            "has no p field");
    refused("{'descr': [('t', '<M8[us]'), ('x', '<u2'), ('y', '<u2'), ('p', '|u1')], 'fortran_order': False, "
            "'shape': (2,), }",
            "field 't' has the unsupported type '<M8[us]'");
    refused("{'descr': [('t', '<c8'), ('x', '<u2'), ('y', '<u2'), ('p', '|u1')], 'fortran_order': False, "
            "'shape': (2,), }",
            "field 't' has the unsupported type '<c8'");
    refused("{'descr': [('t', '<i8'), ('ts', '<i8'), ('x', '<u2'), ('y', '<u2'), ('p', '|u1')], "
            "'fortran_order': False, 'shape': (2,), }",
            "two fields give t");
    refused("{'descr': [('t', '<i8'), ('x', '<u2'), ('y', '<u2'), ('p', '|u1')], 'fortran_order': False, "
            "'shape': (2, 2), }",
            "one-dimensional");
    refused("{'descr': \x01\x02, 'fortran_order': False}", "\\x01\\x02");  // escaped, never raw
    // A value that is no event: x fractional, polarity 5, at their byte offsets.
    std::string d;
    put<double>(d, 0.0);
    put<double>(d, 1.5);
    put<double>(d, 0.0);
    put<double>(d, 1.0);
    const std::string dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 4), }";
    const std::string frac = tmp.write("frac.npy", npy_file(dict, d));
    auto r = io::open_event_reader(frac);
    const ReadResult res = read_all(*r);
    ASSERT_TRUE(res.failed);
    EXPECT_NE(res.error.find("x = 1.5 is not an integer"), std::string::npos) << res.error;
    EXPECT_EQ(res.error_position, npy_file(dict, "").size() + 8u);  // x of record 0
}

// ---------------------------------------------------------------- ATIS

std::string atis(std::uint8_t x, std::uint8_t y, bool on, std::uint32_t t) {
    std::string r(5, '\0');
    r[0] = static_cast<char>(x);
    r[1] = static_cast<char>(y);
    r[2] = static_cast<char>((on ? 0x80 : 0) | ((t >> 16) & 0x7f));
    r[3] = static_cast<char>((t >> 8) & 0xff);
    r[4] = static_cast<char>(t & 0xff);
    return r;
}

TEST(Atis, DecodesRecordsAndUnwrapsThe23BitTime) {
    TempDir tmp;
    const std::uint32_t top = (1u << 23) - 10;
    const std::string f = atis(1, 2, true, 5) + atis(255, 255, false, top) + atis(3, 4, true, 7) + atis(5, 6, false, 9);
    io::ReaderOptions o;
    o.fallback_sensor = std::nullopt;
    const std::vector<Event> want = {{5, 1, 2, 1},
                                     {top, 255, 255, 0},
                                     {(std::int64_t{1} << 23) + 7, 3, 4, 1},
                                     {(std::int64_t{1} << 23) + 9, 5, 6, 0}};
    EXPECT_EQ(read_path(tmp.write("a.bin", f), o), want);
    for (std::size_t batch : {1u, 2u, 3u}) {
        io::AtisReader r(tmp.write("a.bin", f), o);
        EXPECT_EQ(read_all(r, batch).events, want) << batch;
    }
    // Without a .bin name it is not guessed; --format atis-bin reads it anyway.
    const std::string other = tmp.write("a.dat5", f);
    EXPECT_THROW(io::open_event_reader(other, o), InputError);  // binary data of no known kind
    EXPECT_EQ(read_path(other, o, "atis-bin"), want);
    // A small step back is damage, not a wrap: an error at the record's offset.
    auto back = io::open_event_reader(tmp.write("b.bin", atis(1, 1, true, 100) + atis(1, 1, true, 50)), o, "atis-bin");
    const ReadResult rb = read_all(*back);
    ASSERT_TRUE(rb.failed);
    EXPECT_EQ(rb.error_position, 5u);
    // A record cut short.
    auto cut = io::open_event_reader(tmp.write("c.bin", atis(1, 1, true, 100) + "\x01\x02"), o, "atis-bin");
    const ReadResult rc = read_all(*cut);
    ASSERT_TRUE(rc.failed);
    EXPECT_EQ(rc.events.size(), 1u);
    EXPECT_NE(rc.error.find("ends inside an ATIS record"), std::string::npos) << rc.error;
    // A .bin of text is no ATIS file: detection falls through to text.
    EXPECT_EQ(io::detect_format(tmp.write("t.bin", "0.1 1 2 1\n0.2 1 2 0\n0.3 1 1 1\n")), "ecd-text");
    // Default sensor checks as for every format without metadata.
    io::ReaderOptions small;
    small.sensor = SensorSize{100, 100};
    auto outside = io::open_event_reader(tmp.write("a.bin", f), small);
    EXPECT_TRUE(read_all(*outside).failed);
}

// ---------------------------------------------------------------- MATLAB

// Writes a MAT 5 file with the given double / int32 N x 4 variables (column-major data).
struct MatVar {
    std::string name;
    std::vector<double> values;  // column-major
    std::size_t rows, cols;
    bool int32 = false;
};
std::string write_mat(const std::string& path, const std::vector<MatVar>& vars, mat_ft version = MAT_FT_MAT5) {
    mat_t* m = Mat_CreateVer(path.c_str(), nullptr, version);
    EXPECT_NE(m, nullptr);
    for (const MatVar& v : vars) {
        std::size_t dims[2] = {v.rows, v.cols};
        std::vector<std::int32_t> ints(v.values.begin(), v.values.end());
        matvar_t* mv = v.int32 ? Mat_VarCreate(v.name.c_str(), MAT_C_INT32, MAT_T_INT32, 2, dims, ints.data(), 0)
                               : Mat_VarCreate(v.name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                                               const_cast<double*>(v.values.data()), 0);
        Mat_VarWrite(m, mv, MAT_COMPRESSION_ZLIB);
        Mat_VarFree(mv);
    }
    Mat_Close(m);
    return path;
}
// kNpyEvents as columns in the order `order` (indices into t, x, y, p), scaled time.
std::vector<double> columns(const std::array<int, 4>& order, double time_scale = 1) {
    std::vector<double> v;
    for (int c : order)
        for (const Event& e : kNpyEvents)
            v.push_back(c == 0 ? static_cast<double>(e.t) * time_scale : c == 1 ? e.x : c == 2 ? e.y : (e.p ? 1 : -1));
    return v;
}

TEST(Mat, VariableAndColumnsByOption) {
    TempDir tmp;
    io::ReaderOptions o;
    o.fallback_sensor = std::nullopt;
    const std::string one = write_mat(tmp.path("one.mat"), {{"ev", columns({1, 2, 3, 0}), 4, 4, true},
                                                           {"label", {1, 2, 3}, 1, 3}});
    auto r = io::open_event_reader(one, o);
    EXPECT_EQ(r->format(), "mat");
    EXPECT_EQ(io::read_all_events(*r), kNpyEvents);
    // Two candidates: an error naming both and --mat-var; --mat-var picks; --mat-columns orders.
    const std::string two = write_mat(tmp.path("two.mat"), {{"a", columns({1, 2, 3, 0}), 4, 4},
                                                           {"b", columns({0, 1, 2, 3}), 4, 4}});
    try {
        io::open_event_reader(two, o);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        const std::string w = e.what();
        EXPECT_NE(w.find("'a' (4x4 double)"), std::string::npos) << w;
        EXPECT_NE(w.find("'b' (4x4 double)"), std::string::npos) << w;
        EXPECT_NE(w.find("--mat-var"), std::string::npos) << w;
    }
    o.mat_var = "a";
    EXPECT_EQ(read_path(two, o), kNpyEvents);
    o.mat_var = "b";
    o.mat_columns = "t,x,y,p";
    EXPECT_EQ(read_path(two, o), kNpyEvents);
    o.mat_var = "nope";
    EXPECT_THROW(io::open_event_reader(two, o), InputError);
    // Double times in seconds: a fraction with the default unit (us) is an error naming
    // --time-unit; with --time-unit s they read.
    o.mat_var.clear();
    o.mat_columns.clear();
    const std::string sec = write_mat(tmp.path("sec.mat"), {{"events", columns({1, 2, 3, 0}, 1e-6), 4, 4}});
    auto rs = io::open_event_reader(sec, o);
    const ReadResult res = read_all(*rs);
    ASSERT_TRUE(res.failed);
    EXPECT_NE(res.error.find("--time-unit"), std::string::npos) << res.error;
    EXPECT_NE(res.error.find("row 1"), std::string::npos) << res.error;
    o.csv_time_unit = "s";
    EXPECT_EQ(read_path(sec, o), kNpyEvents);
    // MAT 7.3 (HDF5 inside, a text header first): told as .mat, not HDF5.
    const std::string v73 = write_mat(tmp.path("v73.mat"), {{"events", columns({1, 2, 3, 0}), 4, 4}}, MAT_FT_MAT73);
    io::ReaderOptions plain;
    plain.fallback_sensor = std::nullopt;
    EXPECT_EQ(io::detect_format(v73), "mat");
    EXPECT_EQ(read_path(v73, plain), kNpyEvents);
    // No N x 4 variable at all.
    const std::string none = write_mat(tmp.path("none.mat"), {{"m", {1, 2, 3, 4, 5, 6}, 2, 3}});
    try {
        io::open_event_reader(none);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no N x 4 real numeric variable"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("'m' (2x3 double)"), std::string::npos) << e.what();
    }
}

// A MAT 5 file written byte by byte (little-endian): the 128-byte header, then `elements`.
std::string mat5_file(const std::string& elements) {
    std::string head(128, ' ');
    const std::string text = "MATLAB 5.0 MAT-file, written by test_more_formats";
    head.replace(0, text.size(), text);
    std::fill(head.begin() + 116, head.begin() + 124, '\0');  // no subsystem data
    head[124] = '\0';
    head[125] = '\1';  // version 0x0100
    head[126] = 'I';
    head[127] = 'M';  // written little-endian
    return head + elements;
}
std::string le32(std::uint32_t v) {
    std::string b(4, '\0');
    for (int i = 0; i < 4; ++i) b[i] = static_cast<char>(v >> (8 * i));
    return b;
}
// A 1 x 4 double matrix "ev" holding x, y, p, t = 1, 2, 1, 5; its dimensions tag declares
// `dims_bytes` (8: the true two dimensions).
std::string mat5_matrix(std::uint32_t dims_bytes) {
    std::string body = le32(6) + le32(8) + le32(6) + le32(0);              // array flags: double
    body += le32(5) + le32(dims_bytes) + le32(1) + le32(4);                 // dimensions 1 x 4
    body += le32(1 | 2u << 16) + std::string("ev\0\0", 4);               // name, small element
    body += le32(9) + le32(32);                                             // real part: 4 doubles
    for (const double v : {1.0, 2.0, 1.0, 5.0}) body += std::string(reinterpret_cast<const char*>(&v), 8);
    return le32(14) + le32(static_cast<std::uint32_t>(body.size())) + body;  // miMATRIX
}
std::string deflated(const std::string& raw) {
    uLongf n = compressBound(raw.size());
    std::string z(n, '\0');
    EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(z.data()), &n, reinterpret_cast<const Bytef*>(raw.data()), raw.size(), 6),
              Z_OK);
    z.resize(n);
    return le32(15) + le32(static_cast<std::uint32_t>(n)) + z;  // miCOMPRESSED
}
// A compressed element holding the first `keep` bytes of `raw`, flushed, then bytes that
// are no deflate data: a stream damaged after its start.
std::string deflated_then_damaged(const std::string& raw, std::size_t keep) {
    z_stream zs{};
    EXPECT_EQ(deflateInit(&zs, 6), Z_OK);
    std::string z(compressBound(keep) + 64, '\0');
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(raw.data()));
    zs.avail_in = static_cast<uInt>(keep);
    zs.next_out = reinterpret_cast<Bytef*>(z.data());
    zs.avail_out = static_cast<uInt>(z.size());
    EXPECT_EQ(deflate(&zs, Z_FULL_FLUSH), Z_OK);
    z.resize(z.size() - zs.avail_out);
    deflateEnd(&zs);
    z += std::string(16, '\xff');
    return le32(15) + le32(static_cast<std::uint32_t>(z.size())) + z;
}
std::string refusal(const std::string& path, std::string_view format = "auto") {
    try {
        io::open_event_reader(path, {}, format);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

// libmatio allocates a variable's dimensions array by the byte count of its tag before it
// reads it (fuzz_mat: 4 GiB declared in a 420-byte file, an 8 GiB allocation): the tags are
// checked first, and damage is an error at its byte offset.
TEST(Mat, DamagedTagsAreRefusedAtTheirByteOffset) {
    TempDir tmp;
    const auto write = [&](const std::string& name, const std::string& bytes) {
        const std::string path = tmp.path(name);
        std::ofstream(path, std::ios::binary) << bytes;
        return path;
    };
    io::ReaderOptions o;
    o.fallback_sensor = std::nullopt;
    // The same bytes with true tags read (uncompressed and compressed): the layout is sound.
    const std::vector<Event> one{{5, 1, 2, 1}};
    EXPECT_EQ(read_path(write("good.mat", mat5_file(mat5_matrix(8))), o), one);
    EXPECT_EQ(read_path(write("good-z.mat", mat5_file(deflated(mat5_matrix(8)))), o), one);

    // Dimensions declaring 4 GiB: the tag at byte 128 + 8 + 16.
    std::string w = refusal(write("dims.mat", mat5_file(mat5_matrix(0xFFFF0008u))));
    EXPECT_NE(w.find("dims.mat"), std::string::npos) << w;
    EXPECT_NE(w.find("byte offset 152: the dimensions of a variable declare 4294901768 bytes"), std::string::npos) << w;
    EXPECT_NE(w.find("damaged"), std::string::npos) << w;
    // The same inside a compressed element.
    w = refusal(write("dims-z.mat", mat5_file(deflated(mat5_matrix(0xFFFF0008u)))));
    EXPECT_NE(w.find("byte offset 128 (a compressed variable, byte 24 of its decompressed data): the dimensions"),
              std::string::npos)
        << w;
    // The same in a stream damaged after the dimensions (fuzz_mat: libmatio read the header
    // before it met the damage).
    w = refusal(write("dims-zbad.mat", mat5_file(deflated_then_damaged(mat5_matrix(0xFFFF0008u), 48))));
    EXPECT_NE(w.find("byte offset 128 (a compressed variable, byte 24 of its decompressed data): the dimensions"),
              std::string::npos)
        << w;
    // A compressed element declaring fewer bytes than its stream: libmatio inflates on past
    // its end, so the header is checked there too.
    std::string overrun = deflated(mat5_matrix(0xFFFF0008u));
    overrun.replace(4, 4, le32(5));
    w = refusal(write("overrun-z.mat", mat5_file(overrun)));
    EXPECT_NE(w.find("byte offset 128 (a compressed variable, byte 24 of its decompressed data): the dimensions"),
              std::string::npos)
        << w;
    // A compressed element whose matrix declares more than its compressed bytes can hold.
    std::string big = mat5_matrix(8);
    big.replace(4, 4, le32(0x7FFFFFF0u));
    w = refusal(write("big-z.mat", mat5_file(deflated(big))));
    EXPECT_NE(w.find("byte offset 128: a compressed variable declares 2147483632 bytes"), std::string::npos) << w;
    // One word of the true matrix replaced: each a damage fuzz_mat found.
    struct Damage {
        const char* file;
        std::uint32_t dims_bytes;  // for mat5_matrix()
        std::size_t at;            // byte of the element replaced
        std::uint32_t word;
        const char* says;
    };
    const Damage damages[] = {
        // Array flags with a damaged tag: libmatio read them as 16 bytes all the same, then
        // a name tag declaring 3.3 GB, and filled 3.3 GB of memory.
        {"flags.mat", 8, 8, 0x000E0000u,
         "byte offset 136: the array flags of a variable have a damaged tag (type 0, 14 bytes"},
        // Dimensions of a foreign type, one dimension: libmatio then took its name tag from
        // the wrong place, a name of 2.6 GB.
        {"foreign.mat", 4, 24, 69, "byte offset 152: the dimensions of a variable have a damaged tag (type 69, 4 bytes"},
        // More elements than the matrix element has bytes (4 x 687 865 860 in 320 bytes),
        // which libmatio sized allocations by.
        {"rows.mat", 8, 32, 1000000000u,
         "byte offset 152: the dimensions of a variable hold 4000000000 elements, more than the 80 bytes"},
        // An object (class 17, laid out otherwise) whose "dimensions" declare 4 GiB, which
        // libmatio reads there all the same (a 2 GB allocation).
        {"object.mat", 0xFFFF0008u, 16, 17, "byte offset 152: the dimensions of a variable declare 4294901768 bytes"},
    };
    for (const Damage& d : damages) {
        std::string m = mat5_matrix(d.dims_bytes);
        m.replace(d.at, 4, le32(d.word));
        w = refusal(write(d.file, mat5_file(m)));
        EXPECT_NE(w.find(d.says), std::string::npos) << d.file << ": " << w;
    }
    // A file cut short inside its element.
    const std::string whole = mat5_file(mat5_matrix(8));
    w = refusal(write("cut.mat", whole.substr(0, whole.size() - 8)));
    EXPECT_NE(w.find("byte offset 128: a data element declares 80 bytes, but only 72 follow its tag"), std::string::npos)
        << w;
    // Level 4 (no 128-byte header: libmatio allocated the name length of its header, 1.7 GB
    // for a damaged 357-byte file) and files shorter than the header are refused.
    // (Nothing tells a Level 4 file by its content: only --format mat reads it as one.)
    w = refusal(write_mat(tmp.path("v4.mat"), {{"events", columns({1, 2, 3, 0}), 4, 4}}, MAT_FT_MAT4), "mat");
    EXPECT_NE(w.find("v4.mat: bytes 124-127 hold no MAT-file version"), std::string::npos) << w;
    EXPECT_NE(w.find("Level 4 MAT-files are not read"), std::string::npos) << w;
    w = refusal(write("short.mat", mat5_file("").substr(0, 100)));
    EXPECT_NE(w.find("short.mat: 100 bytes, shorter than the 128-byte header of a MAT-file"), std::string::npos) << w;
    // Read before this check, that file gave its one event with t = 0 instead of 5. A
    // compressed one cut short is refused the same way.
    const std::string whole_z = mat5_file(deflated(mat5_matrix(8)));
    w = refusal(write("cut-z.mat", whole_z.substr(0, whole_z.size() - 3)));
    EXPECT_NE(w.find("byte offset 128: a data element declares"), std::string::npos) << w;
    EXPECT_NE(w.find("cut short"), std::string::npos) << w;
}

// ---------------------------------------------------------------- unsupported kinds

struct Kind {
    const char* name;
    std::string bytes;
    const char* says;
};

TEST(Unsupported, EachKindIsNamedWithoutRawBytes) {
    TempDir tmp;
    std::string tar(512, '\0');
    tar.replace(0, 8, "file.txt");
    tar.replace(257, 6, std::string("ustar\0", 6));
    const std::vector<Kind> kinds = {
        // (SQLite, MCAP and ROS 1 bags are read: their damage is the bag readers', test_ros_bags.cpp.)
        {"old.bag", "#ROSBAG V1.2\n\x01\x02", "a ROS bag of an unknown version"},
        {"junk.gz", gzip_bytes(std::string(4000, '\0') + "\x01\x02\x03"), "gzip-compressed data holding binary data"},
        {"junk.zst", zstd_bytes(std::string("\x89PNG\r\n\x1a\n", 8) + std::string(100, '\0')),
         "zstd-compressed data holding a PNG image"},
        {"junk.bz2", bzip2_bytes(std::string(300, '\x07')), "bzip2-compressed data holding binary data"},
        {"junk.xz", xz_bytes(std::string(300, '\0')), "xz-compressed data holding binary data"},
        {"a.npz", std::string("PK\x03\x04\x14\x00\x00\x00", 8) + std::string(40, '\0'), "a zip archive"},
        {"a.png", std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16), "a PNG image"},
        {"a.jpg", std::string("\xff\xd8\xff\xe0\0\x10JFIF\0", 11), "a JPEG image"},
        {"a.pdf", "%PDF-1.7\n%\xe2\xe3\xcf\xd3\n", "a PDF document"},
        {"a.elf", std::string("\x7f" "ELF\x02\x01\x01\0", 8) + std::string(56, '\0'), "an ELF executable"},
        {"a.tar", tar, "a tar archive"},
        {"a.aedat", "#!AER-DAT3.1\r\n", "an AEDAT 3.x file"},
        {"u16.txt", std::string("\xff\xfe" "0\0.\0001\0 \0", 10), "UTF-16 text"},
        {"a.raw", std::string("\x01\x00\x02\x00\x03\x00\x04", 7) + std::string(64, '\x01'), "binary data of no known kind"},
    };
    for (const Kind& k : kinds) {
        SCOPED_TRACE(k.name);
        const std::string path = tmp.write(k.name, k.bytes);
        try {
            io::open_event_reader(path);
            ADD_FAILURE() << "accepted";
        } catch (const InputError& e) {
            const std::string w = e.what();
            EXPECT_EQ(w.rfind(path + ": unsupported format: this looks like ", 0), 0u) << w;
            EXPECT_NE(w.find(k.says), std::string::npos) << w;
            for (const char c : w)
                EXPECT_TRUE(c >= 0x20 && c < 0x7f) << "raw byte " << int{static_cast<unsigned char>(c)} << " in " << w;
        }
    }
}

TEST_F(MoreFormatsCli, UnsupportedFormatExitsOneAndPrintsNoRawBytes) {
    write("a.png", std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16) + std::string(64, '\x01'));
    const CliResult r = run("info --no-progress a.png");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("a.png: unsupported format: this looks like a PNG image"), std::string::npos) << r.err;
    for (const char c : r.err) EXPECT_TRUE(c == '\n' || (c >= 0x20 && c < 0x7f)) << r.err;
    // A CSV whose header row holds control bytes: quoted escaped.
    write("ctl.csv", "t,x\x1b[31m,y,p\n1,2,3,1\n");
    const CliResult c = run("info --no-progress ctl.csv");
    EXPECT_EQ(c.status, 1);
    EXPECT_NE(c.err.find("\\x1b[31m"), std::string::npos) << c.err;
    for (const char ch : c.err) EXPECT_TRUE(ch == '\n' || (ch >= 0x20 && ch < 0x7f)) << c.err;
}

}  // namespace
}  // namespace evcorner::test
