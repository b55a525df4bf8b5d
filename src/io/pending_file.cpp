#include "evcorner/io/pending_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <utility>

#include "evcorner/error.hpp"

namespace evcorner::io {

namespace {

// ---------------------------------------------------------------- signal clean-up
// The temporary names live in a fixed table of C strings so that the handler needs
// nothing but unlink(), signal() and raise(), all async-signal-safe. A slot is filled
// before it is marked used, and marked unused before it is reused.

constexpr int kSlots = 64;
constexpr std::size_t kSlotBytes = 4096;
char g_paths[kSlots][kSlotBytes];
volatile std::sig_atomic_t g_used[kSlots];
std::mutex g_mutex;
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};

extern "C" void remove_pending_files(int sig) {
    for (int i = 0; i < kSlots; ++i)
        if (g_used[i]) ::unlink(g_paths[i]);
    // The signal is blocked while its handler runs: raised again, it takes its default
    // action (ending the process) as soon as the handler returns.
    std::signal(sig, SIG_DFL);
    std::raise(sig);
}

void install_handlers() {
    struct sigaction sa {};
    sa.sa_handler = remove_pending_files;
    sigemptyset(&sa.sa_mask);
    for (const int s : kSignals) sigaddset(&sa.sa_mask, s);
    for (const int s : kSignals) {
        struct sigaction old {};
        // An ignored signal cannot end the process, and a handler the program installed
        // itself is its own business: only the default action is replaced (ours stays).
        if (::sigaction(s, nullptr, &old) == 0 && !(old.sa_flags & SA_SIGINFO) && old.sa_handler == SIG_DFL)
            ::sigaction(s, &sa, nullptr);
    }
}

int register_pending(const std::string& path) {
    if (path.size() >= kSlotBytes) return -1;
    const std::lock_guard lock(g_mutex);
    // Checked at every registration, not once: the program may have changed a
    // signal's action since (a few system calls per output file).
    install_handlers();
    for (int i = 0; i < kSlots; ++i) {
        if (g_used[i]) continue;
        std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
        std::atomic_signal_fence(std::memory_order_seq_cst);
        g_used[i] = 1;
        return i;
    }
    return -1;  // more files in flight than slots: removed on failure, not on a signal
}

void unregister_pending(int slot) noexcept {
    if (slot < 0) return;
    const std::lock_guard lock(g_mutex);
    g_used[slot] = 0;
    std::atomic_signal_fence(std::memory_order_seq_cst);
}

// ---------------------------------------------------------------- names

// The file a chain of symbolic links ends at (the path itself when it is no link, or
// when the chain is too long: opening it then reports the loop).
std::string resolve_links(std::string path) {
    for (int depth = 0; depth < 40; ++depth) {
        struct stat st {};
        if (::lstat(path.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return path;
        std::string link(4096, '\0');
        const ssize_t n = ::readlink(path.c_str(), link.data(), link.size());
        if (n <= 0 || static_cast<std::size_t>(n) >= link.size()) return path;
        link.resize(static_cast<std::size_t>(n));
        if (link[0] == '/') {
            path = link;
        } else {
            const auto slash = path.find_last_of('/');
            path = slash == std::string::npos ? link : path.substr(0, slash + 1) + link;
        }
    }
    return path;
}

std::string temp_name(const std::string& target, std::uint64_t salt) {
    const auto slash = target.find_last_of('/');
    const std::string dir = slash == std::string::npos ? std::string() : target.substr(0, slash + 1);
    std::string base = slash == std::string::npos ? target : target.substr(slash + 1);
    if (base.size() > 200) base.resize(200);  // room for the suffix within NAME_MAX
    static constexpr char kDigits[] = "0123456789abcdefghijklmnopqrstuvwxyz";
    std::string suffix;
    for (int k = 0; k < 8; ++k) {
        suffix += kDigits[salt % 36];
        salt /= 36;
    }
    return dir + "." + base + ".evcorner-" + suffix;
}

std::uint64_t next_salt() {
    static std::atomic<std::uint64_t> counter{0};
    const auto now = static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
    std::uint64_t x = now ^ (static_cast<std::uint64_t>(::getpid()) << 40) ^
                      (counter.fetch_add(1) * 0x9E3779B97F4A7C15ULL);
    x ^= x >> 31;
    x *= 0xBF58476D1CE4E5B9ULL;
    return x ^ (x >> 29);
}

std::string reason(int err) { return std::strerror(err); }

}  // namespace

PendingFile::PendingFile(std::string path) : name_(std::move(path)) {
    target_ = resolve_links(name_);
    struct stat st {};
    const bool exists = ::stat(target_.c_str(), &st) == 0;
    if (exists && S_ISDIR(st.st_mode)) throw OutputError(name_, "cannot create: " + reason(EISDIR));
    if (exists && !S_ISREG(st.st_mode)) {
        // A device, FIFO or socket: there is nothing to replace, only to write to.
        fd_ = ::open(target_.c_str(), O_WRONLY | O_CLOEXEC);
        if (fd_ < 0) throw OutputError(name_, "cannot open: " + reason(errno));
        direct_ = true;
        write_path_ = target_;
        return;
    }
    int err = 0;
    for (int attempt = 0; attempt < 100; ++attempt) {
        std::string tmp = temp_name(target_, next_salt());
        // Mode 0666 under the umask, as open() gives any new file.
        fd_ = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd_ >= 0) {
            write_path_ = std::move(tmp);
            break;
        }
        err = errno;
        if (err != EEXIST) break;
    }
    if (fd_ < 0) {
        if (exists && (err == EACCES || err == EPERM || err == EROFS)) {
            // The directory takes no new file but the file may be writable: in place.
            fd_ = ::open(target_.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
            if (fd_ < 0) throw OutputError(name_, "cannot create: " + reason(errno));
            direct_ = true;
            write_path_ = target_;
            return;
        }
        throw OutputError(name_, "cannot create: " + reason(err));
    }
    if (exists) {
        // The replacement keeps the replaced file's owner, group and mode (chown first:
        // it may clear set-id bits). Failing to keep the owner is not an error.
        (void)!::fchown(fd_, st.st_uid, st.st_gid);
        (void)!::fchmod(fd_, st.st_mode & 07777);
    }
    slot_ = register_pending(write_path_);
}

PendingFile::~PendingFile() { discard(); }

void PendingFile::close_fd() {
    if (fd_ < 0) return;
    const int fd = std::exchange(fd_, -1);
    if (::close(fd) != 0 && errno != EINTR) throw OutputError(name_, "write failed (at close): " + reason(errno));
}

void PendingFile::commit() {
    if (done_) return;
    close_fd();
    if (!direct_ && ::rename(write_path_.c_str(), target_.c_str()) != 0) {
        const int err = errno;
        discard();
        throw OutputError(name_, "cannot put the finished file in place: " + reason(err));
    }
    unregister_pending(slot_);
    slot_ = -1;
    done_ = true;
}

void PendingFile::discard() noexcept {
    if (fd_ >= 0) ::close(std::exchange(fd_, -1));
    if (!done_ && !direct_) ::unlink(write_path_.c_str());
    unregister_pending(slot_);
    slot_ = -1;
    done_ = true;
}

}  // namespace evcorner::io
