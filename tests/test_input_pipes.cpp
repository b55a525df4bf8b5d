// Inputs that can be read only once, front to back: named pipes (FIFOs), the /dev/fd/N
// paths of process substitution `<(...)`, standard input. The format is told from bytes
// the reader then reads itself, so nothing is reopened. And headers cut short are errors
// that name the byte offset, never an empty stream.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <thread>

#include "cli_test_util.hpp"
#include "evcorner/io/input_file.hpp"
#include "evcorner/io/open.hpp"
#include "io_test_util.hpp"
#include "test_util.hpp"

namespace evcorner::test {
namespace {

// Writes `bytes` into a new FIFO at `path` from a thread, in small pieces, as
// `cat file > fifo` would.
class FifoFeeder {
public:
    FifoFeeder(std::string path, std::string bytes) : path_(std::move(path)) {
        ::signal(SIGPIPE, SIG_IGN);  // a reader that stops early must not kill the tests
        if (::mkfifo(path_.c_str(), 0600) != 0)
            throw std::runtime_error("mkfifo " + path_ + ": " + std::strerror(errno));
        thread_ = std::thread([this, b = std::move(bytes)] { feed(b); });
    }
    ~FifoFeeder() {
        // A writer whose reader never opened the FIFO, or stopped reading, is unblocked by
        // a reader of our own that drains what it still writes.
        const int fd = ::open(path_.c_str(), O_RDONLY | O_NONBLOCK);
        char buf[1 << 14];
        while (!done_) {
            if (fd >= 0) (void)!::read(fd, buf, sizeof buf);
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        thread_.join();
        if (fd >= 0) ::close(fd);
    }
    FifoFeeder(const FifoFeeder&) = delete;
    FifoFeeder& operator=(const FifoFeeder&) = delete;
    [[nodiscard]] const std::string& path() const { return path_; }

private:
    void feed(const std::string& b) {
        const int fd = ::open(path_.c_str(), O_WRONLY);
        if (fd >= 0) {
            for (std::size_t at = 0; at < b.size();) {
                const ssize_t n = ::write(fd, b.data() + at, std::min<std::size_t>(b.size() - at, 3000));
                if (n < 0 && errno == EINTR) continue;
                if (n <= 0) break;
                at += static_cast<std::size_t>(n);
            }
            ::close(fd);
        }
        done_ = true;
    }
    std::string path_;
    std::atomic<bool> done_{false};
    std::thread thread_;
};

// ---- samples of every format that reads front to back

struct Sample {
    std::string name;
    std::string bytes;
    std::string format;  // what detection must say
    bool in_cli = true;  // also run through the tool (one sample per format is enough)
};

const std::string kEvt2Header = "% evt 2.0\n% format EVT2;height=480;width=640\n% end\n";
const std::string kEvt2OldHeader = "% Date 2020-09-14 09:03:25\n% plugin_name hal_plugin_gen3_fx3\n% evt 2.0\n";
const std::string kEvt3Header = "% evt 3.0\n% geometry 1280x720\n% end\n";
const std::string kEvt3OldHeader = "% Date 2020-09-25 07:48:29\n% evt 3.0\n% plugin_name hal_plugin_gen41_evk3\n";
const std::string kDatHeader = "% Data file containing Event2d events.\n% Version 2\n% Width 304\n% Height 240\n";
const std::string kAedat2Header =
    "#!AER-DAT2.0\r\n# crafted by the evcorner tests\r\n# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C\r\n";

// Crafted recordings of `n` events, larger than a pipe's buffer for n = 40 000.
std::string crafted_evt2(const std::string& header, int n) {
    std::string f = header;
    for (int i = 0; i < n; ++i) {
        if (i % 64 == 0) put_le32(f, 0x8000'0000u | std::uint32_t(i / 64));
        put_le32(f, std::uint32_t(i % 2) << 28 | std::uint32_t(i % 64) << 22 | std::uint32_t(i % 640) << 11 |
                        std::uint32_t(i % 480));
    }
    return f;
}
std::string crafted_evt3(const std::string& header, int n) {
    std::string f = header;
    for (int i = 0; i < n; ++i) {
        if (i % 100 == 0) {
            put_le16(f, static_cast<std::uint16_t>(0x8000 | ((i / 100) >> 12 & 0xFFF)));
            put_le16(f, static_cast<std::uint16_t>(0x6000 | ((i / 100) & 0xFFF)));
        }
        put_le16(f, static_cast<std::uint16_t>(0x0000 | (i % 720)));
        put_le16(f, static_cast<std::uint16_t>(0x2000 | (i % 2) << 11 | (i % 1280)));
    }
    return f;
}
std::string crafted_dat(int n) {
    std::string f = kDatHeader + std::string("\x00\x08", 2);
    for (int i = 0; i < n; ++i) {
        put_le32(f, std::uint32_t(i));
        put_le32(f, std::uint32_t(i % 2) << 28 | std::uint32_t(i % 240) << 14 | std::uint32_t(i % 304));
    }
    return f;
}
std::string crafted_aedat2(int n) {
    std::string f = kAedat2Header;
    for (int i = 0; i < n; ++i) {
        put_be32(f, std::uint32_t(i % 180) << 22 | std::uint32_t(i % 240) << 12 | std::uint32_t(i % 2) << 11);
        put_be32(f, std::uint32_t(i));
    }
    return f;
}

std::vector<Sample> front_to_back_samples() {
    std::vector<Sample> s = {
        {"text", slurp(bundled_data() / "ecd/shapes_translation/events.txt"), "ecd-text"},
        {"text seed", slurp(fs::path(EVCORNER_SOURCE_DIR) / "fuzz/seeds/seed.txt"), "ecd-text", false},
        {"csv seed", slurp(fs::path(EVCORNER_SOURCE_DIR) / "fuzz/seeds/seed.csv"), "csv"},
        {"npy seed", slurp(fs::path(EVCORNER_SOURCE_DIR) / "fuzz/seeds/seed.npy"), "npy"},
        {"aedat4 seed", slurp(fs::path(EVCORNER_SOURCE_DIR) / "fuzz/seeds/seed.aedat4"), "aedat4"},
        {"evt2", crafted_evt2(kEvt2Header, 40000), "evt2"},
        {"evt2 old header", crafted_evt2(kEvt2OldHeader, 40000), "evt2", false},
        {"evt3", crafted_evt3(kEvt3Header, 40000), "evt3"},
        {"evt3 old header", crafted_evt3(kEvt3OldHeader, 40000), "evt3", false},
        {"dat", crafted_dat(40000), "dat"},
        {"aedat2", crafted_aedat2(40000), "aedat2"},
    };
    if (have_shared_data()) {
        const fs::path real = shared_data() / "real";
        for (const auto& [rel, format] : std::vector<std::pair<std::string, std::string>>{
                 {"ecd-stppp/shapes_rotation/events.txt", "ecd-text"},
                 {"tonic-testdata/sample.aedat4", "aedat4"},
                 {"evlib-shiba/sample.aedat4", "aedat4"},
                 {"tonic-testdata/sample_ncars.dat", "dat"},
                 {"expelliarmus/evt2_sample.raw", "evt2"},
                 {"expelliarmus/evt3_sample.raw", "evt3"},
                 {"davis240c-imu-pyaedattools/IMU_translBoxes.aedat", "aedat2"},
                 {"dvs128-walking-ouyang/neal_walking.aedat", "aedat2"}})
            if (fs::exists(real / rel)) s.push_back({rel, slurp(real / rel), format,
                                                         !(rel.find("ecd") == 0 || rel.find("neal") != std::string::npos)});
    }
    return s;
}

struct Read {
    std::string format;
    std::optional<SensorSize> sensor;
    ReadResult result;
};
Read read_path(const std::string& path) {
    io::ReaderOptions o;
    o.fallback_sensor = std::nullopt;
    auto reader = io::open_event_reader(path, o);
    Read r{std::string(reader->format()), reader->sensor(), {}};
    r.result = read_all(*reader, 1 << 16);
    return r;
}

// ---- InputFile::peek

TEST(InputFilePeek, PeekedBytesAreReadOnceFromAFifo) {
    TempDir tmp;
    std::string bytes;
    for (int i = 0; i < 200000; ++i) bytes.push_back(static_cast<char>(i * 7 + i / 256));
    FifoFeeder fifo(tmp.path("f"), bytes);
    io::InputFile in(fifo.path());
    EXPECT_FALSE(in.size());  // a FIFO has no size
    EXPECT_EQ(in.peek(16), bytes.substr(0, in.peek(16).size()));
    const std::string_view more = in.peek(70000);
    ASSERT_GE(more.size(), 70000u);
    EXPECT_EQ(more, std::string_view(bytes).substr(0, more.size()));
    EXPECT_EQ(in.consumed(), 0u);
    std::string got;
    char buf[5000];
    while (const std::size_t n = in.read(buf)) got.append(buf, n);
    EXPECT_EQ(got.size(), bytes.size());
    EXPECT_TRUE(got == bytes);
    EXPECT_EQ(in.consumed(), bytes.size());
}

TEST(InputFilePeek, PeekPastTheEndOfARegularFile) {
    TempDir tmp;
    io::InputFile in(tmp.write("f", "abcdef"));
    EXPECT_EQ(in.peek(3).substr(0, 3), "abc");
    EXPECT_EQ(in.peek(100), "abcdef");  // fewer than asked: the end
    char buf[4];
    ASSERT_EQ(in.read(buf), 4u);
    EXPECT_EQ(std::string(buf, 4), "abcd");
    EXPECT_EQ(in.peek(100), "ef");  // peeking after reading shows the unread bytes only
    ASSERT_EQ(in.read(buf), 2u);
    EXPECT_EQ(in.read(buf), 0u);
    EXPECT_EQ(in.consumed(), 6u);
}

// ---- every format through a FIFO reads as from the file

TEST(PipeInput, EveryFormatFromAFifoReadsAsFromTheFile) {
    TempDir tmp;
    int k = 0;
    for (const Sample& s : front_to_back_samples()) {
        SCOPED_TRACE(s.name);
        const std::string file = tmp.write("file" + std::to_string(k), s.bytes);
        const Read from_file = read_path(file);
        ASSERT_FALSE(from_file.result.failed) << from_file.result.error;
        ASSERT_FALSE(from_file.result.events.empty());
        EXPECT_EQ(from_file.format, s.format);

        FifoFeeder fifo(tmp.path("fifo" + std::to_string(k++)), s.bytes);
        const Read from_fifo = read_path(fifo.path());
        ASSERT_FALSE(from_fifo.result.failed) << from_fifo.result.error;
        EXPECT_EQ(from_fifo.format, s.format);
        EXPECT_EQ(from_fifo.sensor, from_file.sensor);
        EXPECT_EQ(from_fifo.result.events.size(), from_file.result.events.size());
        EXPECT_TRUE(from_fifo.result.events == from_file.result.events);
    }
}

// bash's <(cat FILE) hands the program /dev/fd/N, an inherited pipe.
TEST(PipeInput, DevFdPathAsProcessSubstitutionGivesIt) {
    if (!fs::exists("/dev/fd")) GTEST_SKIP() << "no /dev/fd on this system";
    for (const char* seed : {"seed.aedat4", "seed.npy", "seed.txt"}) {
        SCOPED_TRACE(seed);
        const fs::path path = fs::path(EVCORNER_SOURCE_DIR) / "fuzz/seeds" / seed;
        const std::string bytes = slurp(path);
        ASSERT_LT(bytes.size(), 60000u);  // fits a pipe's buffer: written before it is read
        int fds[2];
        ASSERT_EQ(::pipe(fds), 0);
        ASSERT_EQ(::write(fds[1], bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
        ::close(fds[1]);
        const Read from_pipe = read_path("/dev/fd/" + std::to_string(fds[0]));
        ::close(fds[0]);
        const Read from_file = read_path(path.string());
        ASSERT_FALSE(from_pipe.result.failed) << from_pipe.result.error;
        EXPECT_EQ(from_pipe.format, from_file.format);
        EXPECT_TRUE(from_pipe.result.events == from_file.result.events);
        EXPECT_FALSE(from_file.result.events.empty());
    }
}

TEST(PipeInput, Hdf5FromAFifoIsAClearError) {
    TempDir tmp;
    FifoFeeder fifo(tmp.path("h"), slurp(fs::path(EVCORNER_SOURCE_DIR) / "fuzz/seeds/seed.h5"));
    try {
        io::open_event_reader(fifo.path());
        ADD_FAILURE() << "HDF5 from a FIFO must be an error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(fifo.path()), std::string::npos) << what;
        EXPECT_NE(what.find("regular file"), std::string::npos) << what;
    }
}

// ---- headers cut short

struct Cuttable {
    std::string name;
    std::string bytes;
    std::string format;
    std::size_t header;        // bytes of header: every shorter prefix is an error
    bool header_alone_is_cut;  // the header without data is an error too (no end mark)
};

std::vector<Cuttable> cuttables() {
    const auto npy = slurp(fs::path(EVCORNER_SOURCE_DIR) / "fuzz/seeds/seed.npy");
    const auto aedat4 = slurp(fs::path(EVCORNER_SOURCE_DIR) / "fuzz/seeds/seed.aedat4");
    const auto u16 = [](const std::string& s, std::size_t at) {
        return std::size_t(static_cast<unsigned char>(s[at])) | std::size_t(static_cast<unsigned char>(s[at + 1])) << 8;
    };
    const auto u32 = [&](const std::string& s, std::size_t at) { return u16(s, at) | u16(s, at + 2) << 16; };
    std::vector<Cuttable> c = {
        {"evt2", crafted_evt2(kEvt2Header, 10), "evt2", kEvt2Header.size(), false},
        {"evt2 old header", crafted_evt2(kEvt2OldHeader, 10), "evt2", kEvt2OldHeader.size(), true},
        {"evt3", crafted_evt3(kEvt3Header, 10), "evt3", kEvt3Header.size(), false},
        {"evt3 old header", crafted_evt3(kEvt3OldHeader, 10), "evt3", kEvt3OldHeader.size(), true},
        {"dat", crafted_dat(10), "dat", kDatHeader.size() + 2, false},
        {"aedat2", crafted_aedat2(10), "aedat2", kAedat2Header.size(), true},
        {"npy seed", npy, "npy", 10 + u16(npy, 8), false},
        {"aedat4 seed", aedat4, "aedat4", 14 + 4 + u32(aedat4, 14), false},
    };
    if (have_shared_data()) {
        for (const char* rel : {"expelliarmus/evt3_sample.raw", "expelliarmus/evt2_sample.raw"}) {
            const fs::path p = shared_data() / "real" / rel;
            if (!fs::exists(p)) continue;
            const std::string b = slurp(p);
            std::size_t h = 0;
            while (h < b.size() && b[h] == '%') h = b.find('\n', h) + 1;
            c.push_back({rel, b, std::string(rel).find("evt3") != std::string::npos ? "evt3" : "evt2", h, true});
        }
    }
    return c;
}

// Opening and reading `path` must end in an InputError naming a byte offset within the file.
void expect_cut_error(const std::string& path, std::string_view format, std::size_t size) {
    try {
        auto reader = io::open_event_reader(path, {}, format);
        const ReadResult r = read_all(*reader);
        ASSERT_TRUE(r.failed) << "read " << r.events.size() << " events without an error";
        EXPECT_EQ(r.error_unit, InputError::Unit::byte) << r.error;
        EXPECT_LE(r.error_position, size) << r.error;
        EXPECT_NE(r.error.find(path), std::string::npos) << r.error;
    } catch (const InputError& e) {
        EXPECT_EQ(e.unit(), InputError::Unit::byte) << e.what();
        EXPECT_LE(e.position(), size) << e.what();
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
}

TEST(HeaderCutShort, EveryCutInsideAHeaderIsAnErrorWithItsOffset) {
    TempDir tmp;
    for (const Cuttable& c : cuttables()) {
        ASSERT_LE(c.header, c.bytes.size()) << c.name;
        const std::size_t last = c.header_alone_is_cut ? c.header : c.header - 1;
        // Every cut in the first 100 bytes and the last 8, every 13th between (long headers).
        const auto step = [&](std::size_t cut) {
            return cut < 100 || cut + 8 >= last ? 1 : std::min<std::size_t>(13, last - 8 - cut);
        };
        for (std::size_t cut = 0; cut <= last; cut += step(cut)) {
            SCOPED_TRACE(c.name + " cut at byte " + std::to_string(cut));
            const std::string path = tmp.write("cut", c.bytes.substr(0, cut));
            expect_cut_error(path, c.format, cut);
            // Detected: two bytes at least ("#" alone is a text file's comment).
            if (cut >= 2) expect_cut_error(path, "auto", cut);
        }
        // The whole file reads.
        SCOPED_TRACE(c.name);
        auto reader = io::open_event_reader(tmp.write("whole", c.bytes));
        EXPECT_EQ(reader->format(), c.format);
        const ReadResult r = read_all(*reader);
        EXPECT_FALSE(r.failed) << r.error;
        EXPECT_FALSE(r.events.empty());
    }
}

TEST(HeaderCutShort, ACompleteHeaderWithAnEndMarkAndNoDataIsEmpty) {
    TempDir tmp;
    for (const auto& [header, format] : std::vector<std::pair<std::string, std::string>>{
             {kEvt2Header, "evt2"}, {kEvt3Header, "evt3"}, {kDatHeader + std::string("\x00\x08", 2), "dat"}}) {
        SCOPED_TRACE(format);
        auto reader = io::open_event_reader(tmp.write("h", header));
        EXPECT_EQ(reader->format(), format);
        const ReadResult r = read_all(*reader);
        EXPECT_FALSE(r.failed) << r.error;
        EXPECT_TRUE(r.events.empty());
    }
}

TEST(HeaderCutShort, RealEvt3CutInsideItsHeaderNamesTheOffset) {
    EVCORNER_REQUIRE_SHARED_DATA();
    TempDir tmp;
    const std::string b = slurp(shared_data() / "real/expelliarmus/evt3_sample.raw");
    const std::string path = tmp.write("cut.raw", b.substr(0, 60));  // inside "% firmware_version ..."
    try {
        auto reader = io::open_event_reader(path);
        read_all(*reader);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_EQ(e.position(), 60u) << e.what();
        EXPECT_NE(std::string(e.what()).find("cut short"), std::string::npos) << e.what();
    }
}

// ---- the command line: process substitution and standard input

class PipeCli : public CliTest {
protected:
    /// Runs a bash command line in the test's folder; E is the evcorner tool.
    CliResult bash(const std::string& line) {
        const std::string script = "cd '" + dir_.string() + "' && E='" EVCORNER_CLI "' && " + line +
                                   " >out.stdout 2>out.stderr";
        std::ofstream(dir_ / "cmd.sh") << script << "\n";
        const int raw = std::system(("bash '" + (dir_ / "cmd.sh").string() + "'").c_str());
        return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(dir_ / "out.stdout"), slurp(dir_ / "out.stderr")};
    }
    // `info` output without its first line (the file name differs).
    static std::string figures(const std::string& info) { return info.substr(info.find('\n') + 1); }
};

TEST_F(PipeCli, DetectFromProcessSubstitutionMatchesTheFile) {
    if (std::system("bash -c true") != 0) GTEST_SKIP() << "no bash";
    const CliResult from_file = run("detect '" + sample_.string() + "' -q");
    ASSERT_EQ(from_file.status, 0) << from_file.err;
    const CliResult piped = bash("\"$E\" detect <(cat '" + sample_.string() + "') -q");
    ASSERT_EQ(piped.status, 0) << piped.err;
    EXPECT_FALSE(piped.out.empty());
    EXPECT_TRUE(piped.out == from_file.out);
}

TEST_F(PipeCli, InfoFromProcessSubstitutionAndStandardInput) {
    const bool have_bash = std::system("bash -c true") == 0;
    int k = 0;
    for (const Sample& s : front_to_back_samples()) {
        if (!s.in_cli) continue;
        SCOPED_TRACE(s.name);
        const std::string file = write("in" + std::to_string(k++), s.bytes);
        const CliResult from_file = run("info '" + file + "'");
        ASSERT_EQ(from_file.status, 0) << from_file.err;
        EXPECT_NE(from_file.out.find("format       " + s.format), std::string::npos) << from_file.out;
        const CliResult from_stdin = run("info -", file);
        ASSERT_EQ(from_stdin.status, 0) << from_stdin.err;
        EXPECT_EQ(figures(from_stdin.out), figures(from_file.out));
        if (!have_bash) continue;
        const CliResult substituted = bash("\"$E\" info <(cat '" + file + "')");
        ASSERT_EQ(substituted.status, 0) << substituted.err;
        EXPECT_EQ(figures(substituted.out), figures(from_file.out));
    }
}

TEST_F(PipeCli, Hdf5FromStandardInputIsAClearError) {
    const CliResult r = run("info -", (fs::path(EVCORNER_SOURCE_DIR) / "fuzz/seeds/seed.h5").string());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("<stdin>"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("regular file"), std::string::npos) << r.err;
}

TEST_F(PipeCli, WrongAEChipLineNamesChipAndSize) {
    EVCORNER_REQUIRE_SHARED_DATA();
    std::string b = slurp(shared_data() / "real/davis240c-imu-pyaedattools/IMU_translBoxes.aedat");
    const std::string from = "eu.seebetter.ini.chips.davis.DAVIS240C";
    b.replace(b.find(from), from.size(), "ch.unizh.ini.jaer.chip.retina.DVS128");
    write("boxes.aedat", b);
    const CliResult r = run("info boxes.aedat");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("--chip"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("events"), std::string::npos) << r.out;
    for (const char* fix : {"--chip DAVIS240C", "--size 240x180"}) {
        const CliResult ok = run(std::string("info boxes.aedat ") + fix);
        ASSERT_EQ(ok.status, 0) << fix << ": " << ok.err;
        EXPECT_NE(ok.out.find("events       162771\n"), std::string::npos) << fix << ": " << ok.out;
    }
    const CliResult detect = run("detect boxes.aedat --chip DAVIS240C -q -o c.txt");
    EXPECT_EQ(detect.status, 0) << detect.err;
    const CliResult bad = run("info boxes.aedat --chip DAVIS999");
    EXPECT_EQ(bad.status, 2);
    EXPECT_NE(bad.err.find("unknown chip"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace evcorner::test
