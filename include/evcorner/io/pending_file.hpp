#pragma once
// An output file that appears under its name only when it is complete.
//
// A regular file (or a name not yet taken) is written under a temporary name in the same
// directory ("<dir>/.<name>.evcorner-XXXXXX") and renamed onto its name by commit(): a
// reader never sees a partial file, and an interrupted or failed run leaves the old file
// (or nothing) under the name. Until then the temporary name is registered with a handler
// of SIGINT, SIGTERM, SIGHUP and SIGPIPE (installed where the signal's action is the
// default) that removes it before the signal ends the process; destruction without
// commit() removes it too. Only the temporary file is ever removed, never the name.
//
// - A symbolic link is followed: the file it finally points to is replaced, the link stays.
// - A new file gets mode 0666 minus the umask; a replaced file keeps its mode (and, where
//   permitted, its owner and group).
// - Special files (character devices such as /dev/null or /dev/full, FIFOs, sockets) are
//   opened and written directly; commit() has nothing to rename.
// - A regular file in a directory where no temporary file may be created (no write
//   permission) is written in place, as before: the one case that is not atomic.
// - SIGKILL and power loss cannot be caught: they may leave a temporary file behind,
//   never a partial file under the name.
// - The handler removes a relative temporary name relative to the working directory of
//   the moment: a program that changes directory while writing should give absolute paths.
// - Replacing a file by renaming gives it a new inode: other hard links to the old file
//   keep the old content (as with editors that save this way).

#include <string>

namespace evcorner::io {

class PendingFile {
public:
    /// Opens `path` for writing as described above. Throws OutputError naming `path`
    /// with the reason (e.g. "cannot create: No such file or directory").
    explicit PendingFile(std::string path);
    ~PendingFile();  ///< removes the temporary file unless committed
    PendingFile(const PendingFile&) = delete;
    PendingFile& operator=(const PendingFile&) = delete;

    /// The descriptor open for writing (on the temporary file, or the file itself when
    /// written directly); -1 once closed.
    [[nodiscard]] int fd() const noexcept { return fd_; }
    /// The name the data is being written under (for libraries that open files by name,
    /// after close_fd()): the temporary name, or the final one when written directly.
    [[nodiscard]] const std::string& write_path() const noexcept { return write_path_; }
    /// The name given to the constructor.
    [[nodiscard]] const std::string& name() const noexcept { return name_; }
    /// True when the file is written in place (special files; see above).
    [[nodiscard]] bool direct() const noexcept { return direct_; }

    /// Closes the descriptor (idempotent); throws OutputError when close() reports an error.
    void close_fd();
    /// Closes the descriptor and renames the temporary file onto the final name. Throws
    /// OutputError (after removing the temporary file). Idempotent once it succeeded.
    void commit();
    /// Closes the descriptor and removes the temporary file; never throws.
    void discard() noexcept;

private:
    std::string name_;        // as given
    std::string target_;      // the final name, symbolic links resolved
    std::string write_path_;  // the temporary name, or target_ when direct
    int fd_ = -1;
    int slot_ = -1;  // the signal handler's slot, -1 when none
    bool direct_ = false;
    bool done_ = false;  // committed or discarded
};

}  // namespace evcorner::io
