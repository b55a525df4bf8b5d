// HDF5: DSEC-layout round trips (plain, deflate, Blosc/ZSTD when the plugin is there),
// an event_utils-layout file (xs/ys/ts/ps, ts in seconds) built here with the C API,
// and bad files.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <random>

#include "evcorner/error.hpp"
#include "evcorner/io/dynamic_library.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/hdf5_events.hpp"
#include "evcorner/io/open.hpp"
#include "io_test_util.hpp"

namespace evcorner::test {
namespace {

using io::Hdf5Reader;
using io::Hdf5Writer;

std::vector<Event> random_events(std::size_t n, int w, int h, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::vector<Event> ev(n);
    std::int64_t t = 1'500'000'000;
    for (auto& e : ev) {
        t += static_cast<std::int64_t>(rng() % 4);
        e = Event{t, static_cast<std::uint16_t>(rng() % static_cast<unsigned>(w)),
                  static_cast<std::uint16_t>(rng() % static_cast<unsigned>(h)), static_cast<std::uint8_t>(rng() & 1)};
    }
    return ev;
}

void write_in_pieces(Hdf5Writer& w, const std::vector<Event>& ev) {
    std::size_t i = 0, step = 1;
    while (i < ev.size()) {
        const std::size_t k = std::min(step, ev.size() - i);
        w.write(std::span<const Event>(ev.data() + i, k));
        i += k;
        step = step * 2 + 3;
    }
    w.close();
}

TEST(Hdf5RoundTrip, DsecLayoutGivesBackTheEvents) {
    TempDir dir;
    // More than Hdf5Reader::kChunk events, and a writer chunk that does not divide it.
    const auto ev = random_events(Hdf5Reader::kChunk * 2 + 1234, 640, 480, 1);
    const std::string path = dir.path("e.h5");
    Hdf5Writer w(path, {SensorSize{640, 480}, 0, 10000});
    write_in_pieces(w, ev);
    auto r = io::open_event_reader(path);
    EXPECT_EQ(r->format(), "hdf5");
    ASSERT_TRUE(r->sensor());
    EXPECT_EQ(*r->sensor(), (SensorSize{640, 480}));
    const ReadResult res = read_all(*r, 5000);
    ASSERT_FALSE(res.failed) << res.error;
    EXPECT_EQ(res.events, ev);
}

TEST(Hdf5RoundTrip, DeflateAndByExtension) {
    TempDir dir;
    const auto ev = random_events(3000, 346, 260, 2);
    const std::string path = dir.path("d.hdf5");
    {
        Hdf5Writer w(path, {SensorSize{346, 260}, 1, 512});
        write_in_pieces(w, ev);
    }
    Hdf5Reader r(path);
    EXPECT_EQ(r.layout(), Hdf5Reader::Layout::dsec);
    EXPECT_EQ(read_all(r).events, ev);
    // By extension through the factory, sensor size from the caller.
    const std::string p2 = dir.path("f.h5");
    auto w = io::open_event_writer(p2, "auto", SensorSize{346, 260});
    w->write(ev);
    w->close();
    Hdf5Reader r2(p2);
    EXPECT_EQ(r2.sensor(), (SensorSize{346, 260}));
    EXPECT_EQ(read_all(r2).events, ev);
}

TEST(Hdf5RoundTrip, BloscZstdWhenThePluginIsInstalled) {
    if (!Hdf5Writer::filter_available(32001))
        GTEST_SKIP() << "the HDF5 Blosc filter plugin is not installed (Debian: hdf5-filter-plugin-blosc-serial)";
    TempDir dir;
    const auto ev = random_events(100'000, 640, 480, 3);
    const std::string path = dir.path("b.h5");
    {
        Hdf5Writer w(path, {SensorSize{640, 480}, 32001, 8192});
        write_in_pieces(w, ev);
    }
    Hdf5Reader r(path);
    const ReadResult res = read_all(r);
    ASSERT_FALSE(res.failed) << res.error;
    EXPECT_EQ(res.events, ev);
}

TEST(Hdf5RoundTrip, EmptyFile) {
    TempDir dir;
    const std::string path = dir.path("empty.h5");
    {
        Hdf5Writer w(path, {SensorSize{10, 10}, 0, 100});
        w.close();
    }
    Hdf5Reader r(path);
    EXPECT_EQ(r.declared_events(), 0u);
    const ReadResult res = read_all(r);
    EXPECT_FALSE(res.failed) << res.error;
    EXPECT_TRUE(res.events.empty());
}

// An event_utils file: events/xs int16, ys int16, ts float64 seconds, ps bool-like int8.
template <class T>
void dataset(hid_t g, const char* name, hid_t ftype, hid_t mtype, const std::vector<T>& v) {
    const hsize_t n = v.size();
    const hid_t s = H5Screate_simple(1, &n, nullptr);
    const hid_t d = H5Dcreate2(g, name, ftype, s, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Dclose(d);
    H5Sclose(s);
}

std::string event_utils_file(const TempDir& dir, const std::string& name, const std::vector<double>& ts,
                             const std::vector<std::int16_t>& xs, const std::vector<std::int16_t>& ys,
                             const std::vector<std::int8_t>& ps) {
    const std::string path = dir.path(name);
    const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    const hid_t g = H5Gcreate2(f, "events", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    dataset(g, "xs", H5T_STD_I16LE, H5T_NATIVE_INT16, xs);
    dataset(g, "ys", H5T_STD_I16LE, H5T_NATIVE_INT16, ys);
    dataset(g, "ts", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, ts);
    dataset(g, "ps", H5T_STD_I8LE, H5T_NATIVE_INT8, ps);
    const int res[2] = {180, 240};  // (height, width)
    const hsize_t two = 2;
    const hid_t s = H5Screate_simple(1, &two, nullptr);
    const hid_t a = H5Acreate2(f, "sensor_resolution", H5T_STD_I32LE, s, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_INT, res);
    H5Aclose(a);
    H5Sclose(s);
    H5Gclose(g);
    H5Fclose(f);
    return path;
}

TEST(Hdf5EventUtils, SecondsAsFloatAndSignedPolarity) {
    TempDir dir;
    const std::string path = event_utils_file(dir, "eu.h5", {0.0000005, 1.25, 1.2500014, 3600.000001},
                                              {0, 239, 5, 17}, {0, 179, 6, 18}, {-1, 1, 0, 1});
    Hdf5Reader r(path);
    EXPECT_EQ(r.layout(), Hdf5Reader::Layout::event_utils);
    ASSERT_TRUE(r.sensor());
    EXPECT_EQ(*r.sensor(), (SensorSize{240, 180}));
    const ReadResult res = read_all(r);
    ASSERT_FALSE(res.failed) << res.error;
    const std::vector<Event> want = {{1, 0, 0, 0}, {1'250'000, 239, 179, 1}, {1'250'001, 5, 6, 0},
                                     {3'600'000'001, 17, 18, 1}};
    EXPECT_EQ(res.events, want);
}

TEST(Hdf5EventUtils, NegativeCoordinateNaNTimeAndBackwardsTimeAreErrorsAfterTheGoodEvents) {
    TempDir dir;
    {
        Hdf5Reader r(event_utils_file(dir, "neg.h5", {0.1, 0.2, 0.3}, {1, -2, 3}, {1, 1, 1}, {1, 1, 1}));
        const ReadResult res = read_all(r);
        EXPECT_TRUE(res.failed);
        EXPECT_EQ(res.events.size(), 1u);
        EXPECT_NE(res.error.find("event 1 (events/xs)"), std::string::npos) << res.error;
        EXPECT_NE(res.error.find("outside the 240x180 sensor"), std::string::npos) << res.error;
        EXPECT_EQ(res.error_unit, InputError::Unit::byte);  // contiguous data: HDF5 gives the address
    }
    {
        Hdf5Reader r(event_utils_file(dir, "nan.h5", {0.1, NAN}, {1, 2}, {1, 1}, {1, 1}));
        const ReadResult res = read_all(r);
        EXPECT_TRUE(res.failed);
        EXPECT_NE(res.error.find("event 1 (events/ts)"), std::string::npos) << res.error;
    }
    {
        Hdf5Reader r(event_utils_file(dir, "back.h5", {0.1, 0.3, 0.2}, {1, 2, 3}, {1, 1, 1}, {1, 1, 1}));
        const ReadResult res = read_all(r);
        EXPECT_TRUE(res.failed);
        EXPECT_EQ(res.events.size(), 2u);
        EXPECT_NE(res.error.find("backwards"), std::string::npos) << res.error;
    }
    {
        io::ReaderOptions o;
        o.skip_invalid = true;
        Hdf5Reader r(event_utils_file(dir, "skip.h5", {0.1, 0.2, 0.3}, {1, 400, 3}, {1, 1, 1}, {1, 1, 1}), o);
        const ReadResult res = read_all(r);
        EXPECT_FALSE(res.failed) << res.error;
        EXPECT_EQ(res.events.size(), 2u);
        EXPECT_EQ(res.skipped, 1u);
    }
}

TEST(Hdf5Bad, MismatchedLengthsMissingDatasetsAndNotHdf5) {
    TempDir dir;
    EXPECT_THROW(Hdf5Reader(event_utils_file(dir, "len.h5", {0.1, 0.2}, {1}, {1, 1}, {1, 1})), InputError);
    const std::string text = dir.write("t.h5", "not an hdf5 file\n");
    EXPECT_THROW(Hdf5Reader{text}, InputError);
    const std::string path = dir.path("nog.h5");
    const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    H5Fclose(f);
    try {
        Hdf5Reader r(path);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no 'events' group"), std::string::npos) << e.what();
    }
}

TEST(Hdf5Bad, CutFileIsAnErrorNotACrash) {
    TempDir dir;
    const auto ev = random_events(50'000, 64, 64, 9);
    const std::string path = dir.path("c.h5");
    {
        Hdf5Writer w(path, {SensorSize{64, 64}, 0, 4096});
        write_in_pieces(w, ev);
    }
    std::ifstream in(path, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const std::string cut = dir.write("cut.h5", bytes.substr(0, bytes.size() * 2 / 3));
    bool failed = false;
    try {
        Hdf5Reader r(cut);
        failed = read_all(r).failed;
    } catch (const InputError&) {
        failed = true;
    }
    EXPECT_TRUE(failed);
}

// The loader behind the lazily opened libhdf5 and libmatio: a library that does not load, or
// lacks a name, is an error that names it (never a null pointer called later).
TEST(DynamicLibrary, ErrorsNameTheLibraryAndTheSymbol) {
    try {
        io::DynamicLibrary lib("libnothing, for a test", {"libevcorner-no-such-library.so.0", "/no/such/path.so"});
        FAIL() << "loaded " << lib.loaded_name();
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("cannot load libnothing, for a test"), std::string::npos) << what;
        EXPECT_NE(what.find("libevcorner-no-such-library.so.0"), std::string::npos) << what;
        EXPECT_NE(what.find("/no/such/path.so"), std::string::npos) << what;
    }
    const io::DynamicLibrary libm("libm", {"libevcorner-no-such-library.so.0", "libm.so.6"});
    EXPECT_EQ(libm.loaded_name(), "libm.so.6");
    double (*fabs_fn)(double) = nullptr;
    libm.symbol(fabs_fn, "fabs");
    ASSERT_NE(fabs_fn, nullptr);
    EXPECT_EQ(fabs_fn(-2.5), 2.5);
    EXPECT_THROW((void)libm.address("evcorner_no_such_symbol"), std::runtime_error);
}

}  // namespace
}  // namespace evcorner::test
