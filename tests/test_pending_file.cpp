// Output files that appear under their name only when complete (PendingFile, OutputFile),
// and the check that keeps outputs off inputs and off each other (check_output_paths).

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "evcorner/error.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/io/output_paths.hpp"
#include "evcorner/io/pending_file.hpp"
#include "evcorner/render/image.hpp"
#include "io_test_util.hpp"

namespace evcorner {
namespace {

namespace fs = std::filesystem;
using io::NamedPath;
using io::OutputFile;
using io::PendingFile;
using test::TempDir;

std::string slurp(const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::vector<std::string> names_in(const std::string& dir) {
    std::vector<std::string> v;
    for (const auto& e : fs::directory_iterator(dir)) v.push_back(e.path().filename().string());
    std::sort(v.begin(), v.end());
    return v;
}

void put(int fd, const std::string& s) { ASSERT_EQ(::write(fd, s.data(), s.size()), static_cast<ssize_t>(s.size())); }

bool is_char_device(const std::string& p) {
    struct stat st {};
    return ::lstat(p.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

// A character device that behaves as /dev/full, made in the test's folder when we may
// (as root), so that a regression removes a copy, not the system's node.
std::string full_device(const TempDir& dir) {
    const std::string own = dir.path("full");
    if (::mknod(own.c_str(), S_IFCHR | 0666, makedev(1, 7)) == 0) return own;
    return "/dev/full";
}

TEST(PendingFile, TheNameAppearsOnlyOnCommit) {
    TempDir dir;
    const std::string target = dir.path("a.txt");
    {
        PendingFile f(target);
        EXPECT_FALSE(f.direct());
        put(f.fd(), "hello\n");
        EXPECT_FALSE(fs::exists(target));
        // The data is in a temporary file beside the target.
        EXPECT_EQ(fs::path(f.write_path()).parent_path(), fs::path(target).parent_path());
        EXPECT_EQ(slurp(f.write_path()), "hello\n");
        f.commit();
    }
    EXPECT_EQ(slurp(target), "hello\n");
    EXPECT_EQ(names_in(dir.path("")), std::vector<std::string>{"a.txt"});
}

TEST(PendingFile, WithoutCommitTheOldFileStaysAndNothingIsLeft) {
    TempDir dir;
    const std::string target = dir.write("a.txt", "old\n");
    {
        PendingFile f(target);
        put(f.fd(), "new, unfinished");
    }
    EXPECT_EQ(slurp(target), "old\n");
    EXPECT_EQ(names_in(dir.path("")), std::vector<std::string>{"a.txt"});
    {
        PendingFile f(dir.path("b.txt"));
        put(f.fd(), "x");
        f.discard();
    }
    EXPECT_EQ(names_in(dir.path("")), std::vector<std::string>{"a.txt"});
}

TEST(PendingFile, NewFilesFollowTheUmaskReplacedFilesKeepTheirMode) {
    TempDir dir;
    const mode_t old_mask = ::umask(027);
    {
        PendingFile f(dir.path("new.txt"));
        f.commit();
    }
    ::umask(old_mask);
    EXPECT_EQ(fs::status(dir.path("new.txt")).permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);

    const std::string kept = dir.write("kept.txt", "old");
    ASSERT_EQ(::chmod(kept.c_str(), 0604), 0);
    {
        PendingFile f(kept);
        put(f.fd(), "new");
        f.commit();
    }
    struct stat st {};
    ASSERT_EQ(::stat(kept.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 07777, 0604u);
    EXPECT_EQ(slurp(kept), "new");
}

TEST(PendingFile, ALinkIsFollowedAndStaysALink) {
    TempDir dir;
    fs::create_directories(dir.path("real"));
    const std::string target = dir.write("real/t.txt", "old");
    const std::string link = dir.path("link.txt");
    fs::create_symlink("real/t.txt", link);
    {
        PendingFile f(link);
        put(f.fd(), "new");
        f.commit();
    }
    EXPECT_TRUE(fs::is_symlink(link));
    EXPECT_EQ(slurp(target), "new");
    EXPECT_EQ(names_in(dir.path("real")), std::vector<std::string>{"t.txt"});

    // A link into a folder that does not exist: an error, and the link stays.
    const std::string dangling = dir.path("dangling.png");
    fs::create_symlink("no-such-dir/x.png", dangling);
    try {
        PendingFile f(dangling);
        ADD_FAILURE() << "no error";
    } catch (const OutputError& e) {
        EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(fs::is_symlink(dangling));
}

TEST(PendingFile, DevicesAreWrittenDirectlyAndNeverRemoved) {
    TempDir dir;
    {
        PendingFile f("/dev/null");
        EXPECT_TRUE(f.direct());
        put(f.fd(), "x");
        f.commit();
    }
    EXPECT_TRUE(is_char_device("/dev/null"));
    const std::string full = full_device(dir);
    {
        PendingFile f(full);
        EXPECT_TRUE(f.direct());
    }
    EXPECT_TRUE(is_char_device(full));
}

TEST(PendingFile, ErrorsSayWhy) {
    TempDir dir;
    try {
        PendingFile f(dir.path("no-such-dir/a.txt"));
        ADD_FAILURE() << "no error";
    } catch (const OutputError& e) {
        EXPECT_NE(std::string(e.what()).find("no-such-dir/a.txt: cannot create: No such file or directory"),
                  std::string::npos)
            << e.what();
    }
    try {
        PendingFile f(dir.path(""));
        ADD_FAILURE() << "no error";
    } catch (const OutputError& e) {
        EXPECT_NE(std::string(e.what()).find("Is a directory"), std::string::npos) << e.what();
    }
}

// A signal that ends the process removes the temporary file: nothing under the name, the
// old file intact, nothing else left in the folder.
TEST(PendingFile, ASignalRemovesTheTemporaryFile) {
    for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) {
        SCOPED_TRACE(sig);
        TempDir dir;
        const std::string kept = dir.write("old.npy", "old");
        const pid_t child = ::fork();
        ASSERT_GE(child, 0);
        if (child == 0) {
            for (const int s : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) std::signal(s, SIG_DFL);
            PendingFile a(kept);
            PendingFile b(dir.path("new.npy"));
            if (::write(a.fd(), "partial", 7) != 7 || ::write(b.fd(), "partial", 7) != 7) ::_exit(3);
            std::raise(sig);
            ::_exit(4);  // not reached: the signal ends the process
        }
        int status = 0;
        ASSERT_EQ(::waitpid(child, &status, 0), child);
        ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << WEXITSTATUS(status);
        EXPECT_EQ(WTERMSIG(status), sig);
        EXPECT_EQ(names_in(dir.path("")), std::vector<std::string>{"old.npy"});
        EXPECT_EQ(slurp(kept), "old");
    }
}

TEST(OutputFile, WriteAtPatchesTheFileBeforeItAppears) {
    TempDir dir;
    const std::string p = dir.path("h.bin");
    OutputFile out(p);
    out.write("0000 body");
    out.write_at(0, "HEAD");
    EXPECT_FALSE(fs::exists(p));
    out.close();
    EXPECT_EQ(slurp(p), "HEAD body");
}

TEST(OutputFile, AFailedWriteSaysWhyAndLeavesTheDevice) {
    TempDir dir;
    const std::string full = full_device(dir);
    OutputFile out(full);
    out.write("data");
    try {
        out.close();
        ADD_FAILURE() << "no error";
    } catch (const OutputError& e) {
        EXPECT_NE(std::string(e.what()).find("write failed: No space left on device"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(is_char_device(full));
}

TEST(OutputFile, DestroyedWithoutCloseLeavesNothing) {
    TempDir dir;
    const std::string p = dir.write("o.txt", "old");
    {
        OutputFile out(p);
        out.write("new");
        out.flush();
    }
    EXPECT_EQ(slurp(p), "old");
    EXPECT_EQ(names_in(dir.path("")), std::vector<std::string>{"o.txt"});
}

// libpng's own file writer removed the path when a write failed (a device node, a link).
TEST(WritePng, AFailedWriteRemovesNeitherTheDeviceNorALinkToIt) {
    TempDir dir;
    const std::string full = full_device(dir);
    const render::RgbImage img(8, 8, {1, 2, 3});
    for (const std::string& path : {full, dir.path("f.png")}) {
        if (path != full) fs::create_symlink(full, path);
        try {
            render::write_png(path, img);
            ADD_FAILURE() << "no error";
        } catch (const OutputError& e) {
            EXPECT_NE(std::string(e.what()).find("write failed"), std::string::npos) << e.what();
        }
    }
    EXPECT_TRUE(is_char_device(full));
    EXPECT_TRUE(fs::is_symlink(dir.path("f.png")));
    // A link to a file in a folder that does not exist: the link stays.
    fs::create_symlink("no-such-dir/x.png", dir.path("g.png"));
    EXPECT_THROW(render::write_png(dir.path("g.png"), img), OutputError);
    EXPECT_TRUE(fs::is_symlink(dir.path("g.png")));
    // And a good write replaces a link's target, not the link.
    const std::string target = dir.write("t.png", "old");
    fs::create_symlink("t.png", dir.path("h.png"));
    render::write_png(dir.path("h.png"), img);
    EXPECT_TRUE(fs::is_symlink(dir.path("h.png")));
    EXPECT_EQ(render::read_png(target).bytes(), img.bytes());
}

// ---------------------------------------------------------------- check_output_paths

std::string refusal(const std::vector<NamedPath>& in, const std::vector<NamedPath>& out) {
    try {
        io::check_output_paths(in, out);
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "";
}

TEST(CheckOutputPaths, AnOutputOnAnInputIsRefused) {
    TempDir dir;
    const std::string in = dir.write("same.txt", "1 2 3 1\n");
    const std::string msg = refusal({{"INPUT", in}}, {{"-o", in}});
    EXPECT_NE(msg.find("-o " + in + " is the input (INPUT " + in + ")"), std::string::npos) << msg;
    // Through a link, and through another spelling of the path.
    fs::create_symlink("same.txt", dir.path("link.txt"));
    EXPECT_NE(refusal({{"INPUT", dir.path("link.txt")}}, {{"--mask", in}}), "");
    EXPECT_NE(refusal({{"INPUT", in}}, {{"-o", dir.path("link.txt")}}), "");
    fs::create_directories(dir.path("x"));
    EXPECT_NE(refusal({{"INPUT", in}}, {{"-o", dir.path("./x/../same.txt")}}), "");
    // Another file is fine, and so is an option not given.
    EXPECT_EQ(refusal({{"INPUT", in}}, {{"-o", dir.path("other.txt")}, {"--mask", ""}}), "");
}

TEST(CheckOutputPaths, TwoOutputsOnOneFileOrStreamAreRefused) {
    TempDir dir;
    const std::string out = dir.path("out.txt");  // does not exist yet
    std::string msg = refusal({}, {{"-o", out}, {"--mask", out}});
    EXPECT_NE(msg.find("-o " + out + " and --mask " + out + " are the same file"), std::string::npos) << msg;
    EXPECT_NE(refusal({}, {{"-o", out}, {"--mask", dir.path("sub/../out.txt")}}), "");
    msg = refusal({}, {{"-o", "-"}, {"--summary-json", "-"}});
    EXPECT_NE(msg.find("-o - (standard output) and --summary-json - (standard output)"), std::string::npos) << msg;
    // /dev/null takes any number of outputs.
    EXPECT_EQ(refusal({}, {{"-o", "/dev/null"}, {"--mask", "/dev/null"}}), "");
    EXPECT_EQ(refusal({}, {{"-o", out}, {"--mask", dir.path("mask.txt")}, {"--summary-json", "-"}}), "");
}

}  // namespace
}  // namespace evcorner
