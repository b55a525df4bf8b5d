// The evcorner tool's outputs as a user meets them: never onto an input, never
// two on one file or stream, complete or absent (atomic), every write checked, the
// sensor size kept, the output format told or refused, JSON on standard output alone.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cli_test_util.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/text_reader.hpp"

namespace evcorner {
namespace {

namespace fs = std::filesystem;

using Result = test::CliResult;
using test::count_lines;
using test::slurp;

class CliOutputs : public test::CliTest {
protected:
    /// Runs a shell script in the test's folder with $E = the evcorner tool; both streams
    /// captured (the script may redirect them itself).
    Result sh(const std::string& script) {
        const std::string cmd = "cd '" + dir_.string() + "' && E='" EVCORNER_CLI "' && { " + script +
                                "\n} >out.stdout 2>out.stderr </dev/null";
        const int raw = std::system(cmd.c_str());
        return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(dir_ / "out.stdout"), slurp(dir_ / "out.stderr")};
    }
    std::string sample() const { return "'" + sample_.string() + "'"; }
    std::string copy_sample(const std::string& name) {
        fs::copy_file(sample_, dir_ / name);
        return (dir_ / name).string();
    }
    /// The names in the test's folder, but the captured output streams.
    std::vector<std::string> files() const {
        std::vector<std::string> v;
        for (const auto& e : fs::directory_iterator(dir_)) {
            const std::string n = e.path().filename().string();
            if (n != "out.stdout" && n != "out.stderr") v.push_back(n);
        }
        std::sort(v.begin(), v.end());
        return v;
    }
    /// A /dev/full of our own in the test's folder when we may make one (root), so that a
    /// regression removes a copy, not the system's node.
    std::string full_device() {
        const std::string own = (dir_ / "full").string();
        if (::mknod(own.c_str(), S_IFCHR | 0666, makedev(1, 7)) == 0) return own;
        return "/dev/full";
    }
    std::optional<SensorSize> sensor_of(const std::string& name) {
        io::ReaderOptions o;
        o.fallback_sensor = std::nullopt;
        return io::open_event_reader((dir_ / name).string(), o)->sensor();
    }
};

bool is_char_device(const std::string& p) {
    struct stat st {};
    return ::lstat(p.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

// ---------------------------------------------------------------- output onto an input

TEST_F(CliOutputs, AnOutputOntoTheInputIsRefusedBeforeAnythingIsWritten) {
    const std::string same = copy_sample("same.txt");
    const std::string before = slurp(same);
    fs::create_symlink("same.txt", dir_ / "link.txt");
    for (const std::string args :
         {"detect same.txt -o same.txt", "detect same.txt -o c.txt --mask same.txt",
          "detect same.txt -o c.txt --summary-json same.txt", "detect link.txt -o same.txt",
          "detect same.txt -o link.txt", "detect same.txt -o ./same.txt --to csv", "convert same.txt same.txt",
          "convert link.txt same.txt --to aedat4", "info same.txt --json same.txt"}) {
        SCOPED_TRACE(args);
        const Result r = run(args);
        EXPECT_EQ(r.status, 2) << r.err;
        EXPECT_NE(r.err.find("is the input"), std::string::npos) << r.err;
        EXPECT_EQ(slurp(same), before);
        EXPECT_EQ(files(), (std::vector<std::string>{"link.txt", "same.txt"}));
    }
    // Standard output redirected onto the input (appending would read its own output).
    const Result r = sh("$E detect same.txt -q >> same.txt");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(slurp(same), before);
}

TEST_F(CliOutputs, ABinaryRecordingIsNotConvertedOntoItself) {
    ASSERT_EQ(run("convert " + sample() + " rec.npy -q").status, 0);
    const std::string before = slurp(dir_ / "rec.npy");
    for (const std::string args : {"convert rec.npy rec.npy", "convert rec.npy rec.npy --to aedat4",
                                   "bench rec.npy --json rec.npy -q --min-events 100 --repeat 1 --no-latency -d efast"}) {
        const Result r = run(args);
        EXPECT_EQ(r.status, 2) << args << ": " << r.err;
        EXPECT_EQ(slurp(dir_ / "rec.npy"), before) << args;
    }
}

TEST_F(CliOutputs, LabelEvalAndRenderRefuseOutputsOntoTheirInputs) {
    const std::string same = copy_sample("same.txt");
    const std::string png = copy_sample("same.png");  // event text under a PNG name
    fs::create_directory(dir_ / "rep");
    fs::copy_file(sample_, dir_ / "rep" / "table1.csv");
    const std::string before = slurp(same);
    for (const std::string args :
         {"label same.txt -o same.txt", "label same.txt -o l.txt --json same.txt", "render same.png -o same.png",
          "render same.txt --corners same.png -o same.png", "eval rep/table1.csv --report rep -q --repeat 1"}) {
        SCOPED_TRACE(args);
        const Result r = run(args);
        EXPECT_EQ(r.status, 2) << r.err;
        EXPECT_NE(r.err.find("is the input"), std::string::npos) << r.err;
        EXPECT_EQ(slurp(same), before);
        EXPECT_EQ(slurp(png), before);
        EXPECT_EQ(slurp(dir_ / "rep" / "table1.csv"), before);
        EXPECT_EQ(files(), (std::vector<std::string>{"rep", "same.png", "same.txt"}));
    }
}

// ---------------------------------------------------------------- render to a device

TEST_F(CliOutputs, RenderToAFullDeviceFailsAndRemovesNothing) {
    const std::string full = full_device();
    fs::create_symlink(full, dir_ / "f.png");
    for (const std::string& out : {full, std::string("f.png")}) {
        const Result r = run("render " + sample() + " -k sae -o '" + out + "'");
        EXPECT_EQ(r.status, 1) << out;
        EXPECT_NE(r.err.find("write failed"), std::string::npos) << r.err;
    }
    EXPECT_TRUE(is_char_device(full));
    EXPECT_TRUE(fs::is_symlink(dir_ / "f.png"));
}

// ---------------------------------------------------------------- atomic outputs

// convert reads standard input, which stays open; once the temporary output file exists,
// the signal comes. Nothing may be left under the name but what was there before.
TEST_F(CliOutputs, AnInterruptedConvertLeavesNoPartialFile) {
    const std::string events = slurp(sample_);
    for (const int sig : {SIGINT, SIGTERM}) {
        for (const std::string out : {"out.npy", "out.aedat4", "out.h5", "out.txt"}) {
            SCOPED_TRACE(out + " signal " + std::to_string(sig));
            const bool had_old = out == "out.npy";
            if (had_old) write(out, "old contents");
            int pipe_fd[2];
            ASSERT_EQ(::pipe(pipe_fd), 0);
            const pid_t child = ::fork();
            ASSERT_GE(child, 0);
            if (child == 0) {
                ::dup2(pipe_fd[0], 0);
                ::close(pipe_fd[0]);
                ::close(pipe_fd[1]);
                if (::chdir(dir_.c_str()) != 0) ::_exit(100);
                for (const int s : {SIGINT, SIGTERM}) std::signal(s, SIG_DFL);
                ::execl(EVCORNER_CLI, EVCORNER_CLI, "convert", "-", out.c_str(), "-q", static_cast<char*>(nullptr));
                ::_exit(101);
            }
            ::close(pipe_fd[0]);
            ASSERT_EQ(::write(pipe_fd[1], events.data(), events.size()), static_cast<ssize_t>(events.size()));
            // Wait (up to 20 s) until the temporary file is there: the output is under way.
            bool pending = false;
            for (int k = 0; k < 2000 && !pending; ++k) {
                for (const auto& f : files()) pending |= f.find(".evcorner-") != std::string::npos;
                if (!pending) std::this_thread::sleep_for(std::chrono::milliseconds(10));
            }
            EXPECT_TRUE(pending);
            ::kill(child, sig);
            int status = 0;
            ASSERT_EQ(::waitpid(child, &status, 0), child);
            ::close(pipe_fd[1]);
            EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << status;
            EXPECT_EQ(files(), had_old ? std::vector<std::string>{out} : std::vector<std::string>{});
            if (had_old) {
                EXPECT_EQ(slurp(dir_ / out), "old contents");
            }
            fs::remove(dir_ / out);
        }
    }
}

// A write failing half way (a file size limit, like a full disk) leaves nothing under the
// name, and says why.
TEST_F(CliOutputs, AFailedWriteLeavesNoPartialFileAndSaysWhy) {
    write("old.npy", "old contents");
    for (const std::string out : {"out.npy", "out.aedat4", "out.h5", "out.csv", "old.npy"}) {
        SCOPED_TRACE(out);
        // 64 KiB at most per file; SIGXFSZ ignored so that write() reports EFBIG.
        const Result r = sh("trap '' XFSZ; ulimit -f 64; $E convert " + sample() + " " + out);
        EXPECT_EQ(r.status, 1);
        EXPECT_NE(r.err.find("File too large"), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("HDF5-DIAG"), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("infinite loop"), std::string::npos) << r.err;
        EXPECT_EQ(files(), std::vector<std::string>{"old.npy"});
        EXPECT_EQ(slurp(dir_ / "old.npy"), "old contents");
    }
}

// ---------------------------------------------------------------- two outputs on one

TEST_F(CliOutputs, TwoOutputsOnOneFileOrOnStandardOutputAreRefused) {
    for (const std::string args :
         {"-o out.txt --mask out.txt", "-o out.txt --mask ./out.txt", "-o out.txt --summary-json out.txt",
          "--summary-json - --mask -", "--summary-json -", "-o - --mask -", "--mask out.txt -o sub/../out.txt"}) {
        SCOPED_TRACE(args);
        fs::create_directories(dir_ / "sub");
        const Result r = run("detect " + sample() + " -q " + args);
        EXPECT_EQ(r.status, 2) << r.err;
        EXPECT_TRUE(r.err.find("same file") != std::string::npos ||
                    r.err.find("mix on standard output") != std::string::npos)
            << r.err;
        EXPECT_TRUE(r.out.empty());
        fs::remove(dir_ / "sub");
        EXPECT_EQ(files(), std::vector<std::string>{});
    }
    // Standard output redirected to the file another output names.
    const Result r = sh("$E detect " + sample() + " -q --mask m.txt > m.txt");
    EXPECT_EQ(r.status, 2) << r.err;
    // Different files, and /dev/null twice, are fine.
    EXPECT_EQ(run("detect " + sample() + " -q -o c.txt --mask m.txt --summary-json -").status, 0);
    EXPECT_EQ(run("detect " + sample() + " -q -o /dev/null --mask /dev/null").status, 0);
}

// ---------------------------------------------------------------- write failures

TEST_F(CliOutputs, EveryFailedWriteIsAnError) {
    const std::string full = full_device();
    for (const std::string& cmd :
         {"$E info " + sample() + " > " + full, "$E --help > " + full, "$E detect --help > " + full,
          "$E --version > " + full,
          "$E bench " + sample() + " -q --min-events 1000 --repeat 1 --no-latency -d efast > " + full,
          "$E detect " + sample() + " -q > " + full, "$E detect " + sample() + " -q -o " + full,
          "$E detect " + sample() + " -q -o c.txt --mask " + full,
          "$E detect " + sample() + " -q -o c.txt --summary-json - > " + full,
          "$E convert " + sample() + " - -q > " + full, "$E info " + sample() + " --json " + full,
          // label and eval print their results through the same checked standard output
          "$E detect " + sample() + " -q -o c.txt && $E label c.txt > " + full, "$E eval " + sample() + " -q > " + full}) {
        SCOPED_TRACE(cmd);
        const Result r = sh(cmd);
        EXPECT_EQ(r.status, 1) << r.err;
        EXPECT_NE(r.err.find("write failed"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
    }
    EXPECT_TRUE(is_char_device(full));
}

// ---------------------------------------------------------------- sensor size

TEST_F(CliOutputs, OutputsRecordTheSensorSizeOfTheInput) {
    // ECD text says no size: detect runs on 240x180, convert records it when every event fits.
    for (const std::string out : {"c.aedat4", "c.h5"}) {
        ASSERT_EQ(run("detect " + sample() + " -q -o " + out).status, 0);
        EXPECT_EQ(sensor_of(out), kDavis240) << out;
        ASSERT_EQ(run("convert " + sample() + " -q e" + out).status, 0);
        EXPECT_EQ(sensor_of("e" + out), kDavis240) << out;
        ASSERT_EQ(run("convert " + sample() + " -q --size 346x260 s" + out).status, 0);
        EXPECT_EQ(sensor_of("s" + out), (SensorSize{346, 260})) << out;
        // And back: the size read from the file goes on.
        ASSERT_EQ(run("convert s" + out + " -q t" + out).status, 0);
        EXPECT_EQ(sensor_of("t" + out), (SensorSize{346, 260})) << out;
    }
    // Events beyond 240x180 and no size: the bounding box, with a warning naming --size.
    write("wide.txt", "0.1 5 5 1\n0.2 299 10 0\n0.3 6 199 1\n");
    const Result r = run("convert wide.txt wide.aedat4");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
    EXPECT_EQ(sensor_of("wide.aedat4"), (SensorSize{300, 200}));
}

TEST_F(CliOutputs, RealRecordingsKeepTheirSensorSize) {
    EVCORNER_REQUIRE_SHARED_DATA();
    const fs::path real = test::shared_data() / "real";
    struct Case {
        const char* file;
        SensorSize size;
    };
    for (const Case& c : {Case{"tonic-testdata/sample.aedat4", {320, 240}},
                          Case{"expelliarmus/evt3_sample.raw", {1280, 720}}}) {
        const std::string in = "'" + (real / c.file).string() + "'";
        for (const std::string out : {"c.aedat4", "c.h5"}) {
            SCOPED_TRACE(std::string(c.file) + " -> " + out);
            Result r = run("detect " + in + " -q -o " + out);
            ASSERT_EQ(r.status, 0) << r.err;
            EXPECT_EQ(sensor_of(out), c.size);
            r = run("convert " + in + " -q e" + out);
            if (r.status != 0) {
                // A recording may hold a time step backwards; the part before it is written.
                EXPECT_NE(r.err.find("backwards"), std::string::npos) << r.err;
            }
            EXPECT_EQ(sensor_of("e" + out), c.size);
            fs::remove(dir_ / out);
            fs::remove(dir_ / ("e" + out));
        }
    }
    // N-CARS .dat says no size: 240x180 (all its events fit), and detection on the
    // converted file finds what it finds on the original.
    const std::string ncars = "'" + (real / "tonic-testdata/sample_ncars.dat").string() + "'";
    ASSERT_EQ(run("convert " + ncars + " -q n.aedat4").status, 0);
    EXPECT_EQ(sensor_of("n.aedat4"), kDavis240);
    const Result original = run("detect " + ncars + " -q");
    const Result converted = run("detect n.aedat4 -q");
    ASSERT_EQ(converted.status, 0) << converted.err;
    EXPECT_GT(count_lines(original.out), 0u);
    EXPECT_EQ(converted.out, original.out);
}

// ---------------------------------------------------------------- formats and names

TEST_F(CliOutputs, UnknownOutputExtensionsAreRefused) {
    for (const std::string& args : {"convert " + sample() + " x.npz", "convert " + sample() + " x.json",
                                   "detect " + sample() + " -o c.npz", "convert " + sample() + " x.tar.gz"}) {
        SCOPED_TRACE(args);
        const Result r = run(args);
        EXPECT_EQ(r.status, 2) << r.err;
        EXPECT_NE(r.err.find("unknown extension"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find(".txt, .csv, .npy, .aedat4, .h5, .hdf5"), std::string::npos) << r.err;
        EXPECT_EQ(files(), std::vector<std::string>{});
    }
    // Case does not matter; --to names the format for any name; no extension is text.
    const auto events = io::read_text_file(sample_.string());
    ASSERT_EQ(run("convert " + sample() + " -q x.TXT").status, 0);
    EXPECT_EQ(io::read_text_file((dir_ / "x.TXT").string()), events);
    ASSERT_EQ(run("convert " + sample() + " -q x.NPY").status, 0);
    EXPECT_EQ(io::open_event_reader((dir_ / "x.NPY").string())->format(), "npy");
    ASSERT_EQ(run("convert " + sample() + " -q x.npz --to csv").status, 0);
    EXPECT_EQ(io::open_event_reader((dir_ / "x.npz").string())->format(), "csv");
    ASSERT_EQ(run("convert " + sample() + " -q plain").status, 0);
    EXPECT_EQ(io::read_text_file((dir_ / "plain").string()), events);
}

TEST_F(CliOutputs, UnknownFormatNamesAndCommandsAreUsageErrors) {
    Result r = run("convert " + sample() + " o.txt --to txt");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("unknown output format 'txt'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("ecd-text, csv, npy, aedat4, hdf5"), std::string::npos) << r.err;
    r = run("detect " + sample() + " --to txt");
    EXPECT_EQ(r.status, 2) << r.err;
    r = run("info " + sample() + " --format raw");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("unknown input format 'raw'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("evt2, evt3"), std::string::npos) << r.err;
    r = run("detec " + sample());
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("unknown command 'detec'; did you mean 'detect'?"), std::string::npos) << r.err;
    r = run("conver x y");
    EXPECT_NE(r.err.find("did you mean 'convert'?"), std::string::npos) << r.err;
    r = run("INFO x");
    EXPECT_NE(r.err.find("unknown command 'INFO'; did you mean 'info'?"), std::string::npos) << r.err;
    r = run("frobnicate");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("unknown command 'frobnicate' (commands: detect, info, convert"), std::string::npos)
        << r.err;
    EXPECT_EQ(files(), std::vector<std::string>{});
}

TEST_F(CliOutputs, ConvertToStandardOutputWritesText) {
    const Result r = run("convert " + sample() + " - -q");
    ASSERT_EQ(r.status, 0) << r.err;
    write("back.txt", r.out);
    EXPECT_EQ(io::read_text_file((dir_ / "back.txt").string()), io::read_text_file(sample_.string()));
}

// ---------------------------------------------------------------- JSON and rates

TEST_F(CliOutputs, JsonOnStandardOutputIsAllThereIs) {
    Result r = run("info " + sample() + " --json -");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto info = nlohmann::json::parse(r.out);  // throws if anything else is there
    EXPECT_EQ(info["events"], 30000);
    EXPECT_NE(r.err.find("events       30000"), std::string::npos) << r.err;  // the table, on stderr

    r = run("bench " + sample() + " --json - -q --min-events 1000 --repeat 1 --no-latency -d efast");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto bench = nlohmann::json::parse(r.out);
    ASSERT_EQ(bench["results"].size(), 1u);
    EXPECT_EQ(bench["results"][0]["detector"], "efast");
    EXPECT_NE(r.err.find("ns/event"), std::string::npos) << r.err;
}

TEST_F(CliOutputs, ThePeakRateIsNeverBelowTheMean) {
    auto info = [&](const std::string& name, const std::string& text) {
        write(name, text);
        const Result r = run("info " + name + " --json -");
        EXPECT_EQ(r.status, 0) << r.err;
        return nlohmann::json::parse(r.out);
    };
    // 3 events over 2 us (under 1 ms: one bin, the whole span): peak = mean = 1.5 M/s.
    auto j = info("short.txt", "51.980787 98 52 1\n51.980788 156 101 1\n51.980789 96 36 0\n");
    EXPECT_DOUBLE_EQ(j["mean_rate_eps"].get<double>(), 1.5e6);
    EXPECT_DOUBLE_EQ(j["peak_rate_eps"].get<double>(), 1.5e6);
    // 100 events in the first 100 us, 100 in the last 1 us of a 1.001 ms span: the
    // remainder joins the last bin, so peak = mean = 200 / 1.001 ms.
    std::string text;
    for (int i = 0; i < 100; ++i) text += "0.000" + std::string(i < 10 ? "00" : "0") + std::to_string(i) + " 1 1 1\n";
    for (int i = 0; i < 100; ++i) text += "0.001001 1 1 1\n";
    j = info("edge.txt", text);
    EXPECT_NEAR(j["mean_rate_eps"].get<double>(), 200 / 1.001e-3, 1e-6);
    EXPECT_NEAR(j["peak_rate_eps"].get<double>(), 200 / 1.001e-3, 1e-6);
    // 3.5 ms: bins [0,1) [1,2) and [2,3.5] ms holding 1, 10 and 2 events: peak 10 / 1 ms.
    j = info("bins.txt",
             "0.000000 1 1 1\n" + [] {
                 std::string s;
                 for (int i = 0; i < 10; ++i) s += "0.001" + std::to_string(100 + i) + " 1 1 1\n";
                 return s;
             }() + "0.002500 1 1 1\n0.003500 1 1 1\n");
    EXPECT_DOUBLE_EQ(j["peak_rate_eps"].get<double>(), 10e3);
    EXPECT_NEAR(j["mean_rate_eps"].get<double>(), 13 / 3.5e-3, 1e-6);
    // And on a real cut.
    j = info("s.txt", slurp(sample_));
    EXPECT_GE(j["peak_rate_eps"].get<double>(), j["mean_rate_eps"].get<double>());
}

// ---------------------------------------------------------------- HDF5 reasons

TEST_F(CliOutputs, Hdf5FailuresSayWhyWithoutHdf5sOwnStack) {
    Result r = run("convert " + sample() + " no-such-dir/x.h5");
    EXPECT_EQ(r.status, 2);  // refused before reading, as every output is
    EXPECT_NE(r.err.find("its folder no-such-dir does not exist (No such file or directory)"), std::string::npos)
        << r.err;
    r = run("convert " + sample() + " " + full_device() + " --to hdf5");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("must be a regular file"), std::string::npos) << r.err;
    write("bad.h5", std::string("\x89HDF\r\n\x1a\n", 8) + std::string(600, '\x01'));
    r = run("info bad.h5");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("bad.h5"), std::string::npos) << r.err;
    for (const Result& x : {r, run("convert " + sample() + " no-such-dir/x.h5")}) {
        EXPECT_EQ(x.err.find("HDF5-DIAG"), std::string::npos) << x.err;
        EXPECT_EQ(x.err.find("infinite loop"), std::string::npos) << x.err;
    }
}

// libhdf5 and libmatio (with libcurl, GnuTLS, Kerberos, ... behind them) are opened when an
// HDF5 or .mat file is used, not at every start (io/dynamic_library.hpp).
TEST_F(CliOutputs, Hdf5AndMatioAreLoadedOnlyWhenUsed) {
    // LD_TRACE_LOADED_OBJECTS=1: the dynamic loader lists what it loads at start, and stops
    // (what ldd does).
    const std::string cmd = "LD_TRACE_LOADED_OBJECTS=1 '" EVCORNER_CLI "' >'" + (dir_ / "libs.txt").string() + "' 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const std::string libs = slurp(dir_ / "libs.txt");
    ASSERT_NE(libs.find("libc.so"), std::string::npos) << libs;  // the listing worked
    EXPECT_EQ(libs.find("libhdf5"), std::string::npos) << libs;
    EXPECT_EQ(libs.find("libmatio"), std::string::npos) << libs;
    EXPECT_EQ(libs.find("libcurl"), std::string::npos) << libs;
    // ... and HDF5 still works when asked: a round trip through an .h5 file.
    Result r = run("convert " + sample() + " x.h5");
    ASSERT_EQ(r.status, 0) << r.err;
    r = run("convert x.h5 back.txt");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(count_lines(slurp(dir_ / "back.txt")), count_lines(slurp(sample_)));
}

TEST_F(CliOutputs, UnwritableOutputsAreRefusedBeforeTheInputIsRead) {
    fs::create_directory(dir_ / "folder");
    struct Case {
        std::string command, option, why;
    };
    const std::vector<Case> cases = {
        {"detect " + sample() + " -o c.txt --summary-json folder", "--summary-json folder", "is a folder"},
        {"detect " + sample() + " -o missing/c.txt", "-o missing/c.txt", "its folder missing does not exist"},
        {"detect " + sample() + " --mask c.txt/m.txt -o c.txt", "--mask c.txt/m.txt", "its folder c.txt does not exist"},
        {"convert " + sample() + " folder", "OUTPUT folder", "is a folder"},
        {"label " + sample() + " --json missing/l.json", "--json missing/l.json", "its folder missing does not exist"},
        {"info " + sample() + " --json folder", "--json folder", "is a folder"},
    };
    for (const Case& c : cases) {
        const Result r = sh("$E " + c.command);
        EXPECT_EQ(r.status, 2) << c.command << "\n" << r.err;
        EXPECT_NE(r.err.find("evcorner: error: " + c.option + ": " + c.why), std::string::npos) << c.command << "\n"
                                                                                              << r.err;
        EXPECT_EQ(files(), std::vector<std::string>{"folder"}) << c.command;  // c.txt not written either
    }
    // eval --report: a file where the folder should be.
    write("report", "x");
    const Result r = sh("$E eval " + sample() + " --report report");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("--report report: exists and is not a folder"), std::string::npos) << r.err;
    if (::geteuid() != 0) {  // root may write anywhere
        fs::permissions(dir_ / "folder", fs::perms::owner_read | fs::perms::owner_exec);
        const Result ro = sh("$E detect " + sample() + " -o folder/c.txt");
        fs::permissions(dir_ / "folder", fs::perms::owner_all);
        EXPECT_EQ(ro.status, 2) << ro.err;
        EXPECT_NE(ro.err.find("cannot create files in folder"), std::string::npos) << ro.err;
    }
}

TEST_F(CliOutputs, FormatsThatSeekBackAreRefusedOnPipesUpFront) {
    ASSERT_EQ(::mkfifo((dir_ / "fifo").c_str(), 0600), 0);
    // Nobody reads the FIFO: opening it would block, so a refusal must come before opening.
    for (const std::string& cmd : {"detect " + sample() + " -o fifo --to npy", "convert " + sample() + " fifo --to npy",
                                  "convert " + sample() + " fifo --to hdf5", "convert " + sample() + " fifo --to aedat4"}) {
        const Result r = sh("timeout 20 $E " + cmd);
        EXPECT_EQ(r.status, 2) << cmd << "\n" << r.err;
        EXPECT_NE(r.err.find("output fifo is a pipe or socket, which cannot seek back"), std::string::npos)
            << cmd << "\n" << r.err;
    }
    // Standard output to a pipe: the same, for npy and hdf5.
    Result r = sh("$E convert " + sample() + " - --to npy | cat >/dev/null");
    EXPECT_NE(r.err.find("output - (standard output) is a pipe or socket"), std::string::npos) << r.err;
    // AEDAT 4.0 with a known size streams: a reader on the FIFO gets the whole file.
    r = sh("$E convert " + sample() + " fifo --to aedat4 --size 240x180 -q & cat fifo > got.aedat4; wait $!");
    EXPECT_EQ(r.status, 0) << r.err;
    r = sh("$E convert got.aedat4 back.txt -q");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(count_lines(slurp(dir_ / "back.txt")), count_lines(slurp(sample_)));
}

}  // namespace
}  // namespace evcorner
