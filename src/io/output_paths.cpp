#include "evcorner/io/output_paths.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <system_error>

namespace evcorner::io {

namespace {

namespace fs = std::filesystem;

// What a path refers to: an existing file (device and inode), or a name not taken yet.
struct Identity {
    bool exists = false;
    dev_t dev = 0;
    ino_t ino = 0;
    bool char_device = false;
    std::string absolute;  // for names not taken yet
};

Identity identify(const std::string& path, int std_fd) {
    Identity id;
    struct stat st {};
    const bool ok = path == "-" ? ::fstat(std_fd, &st) == 0 : ::stat(path.c_str(), &st) == 0;
    if (ok) {
        id.exists = true;
        id.dev = st.st_dev;
        id.ino = st.st_ino;
        id.char_device = S_ISCHR(st.st_mode);
        return id;
    }
    if (path == "-") return id;
    std::error_code ec;
    fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
    if (ec) p = fs::absolute(path, ec).lexically_normal();
    id.absolute = p.string();
    return id;
}

bool same_file(const Identity& a, const Identity& b) {
    if (a.exists != b.exists) return false;
    if (!a.exists) return !a.absolute.empty() && a.absolute == b.absolute;
    return a.dev == b.dev && a.ino == b.ino && !a.char_device;
}

std::string describe(const NamedPath& p, bool output) {
    if (p.path == "-") return std::string(p.option) + (output ? " - (standard output)" : " - (standard input)");
    return std::string(p.option) + " " + p.path;
}

}  // namespace

void check_output_paths(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs) {
    std::vector<Identity> in_ids(inputs.size()), out_ids(outputs.size());
    for (std::size_t i = 0; i < inputs.size(); ++i)
        if (!inputs[i].path.empty()) in_ids[i] = identify(inputs[i].path, STDIN_FILENO);
    for (std::size_t k = 0; k < outputs.size(); ++k)
        if (!outputs[k].path.empty()) out_ids[k] = identify(outputs[k].path, STDOUT_FILENO);

    for (std::size_t k = 0; k < outputs.size(); ++k) {
        const NamedPath& out = outputs[k];
        if (out.path.empty()) continue;
        for (std::size_t i = 0; i < inputs.size(); ++i) {
            if (inputs[i].path.empty() || !in_ids[i].exists || !out_ids[k].exists) continue;
            if (same_file(in_ids[i], out_ids[k]))
                throw std::invalid_argument(describe(out, true) + " is the input (" + describe(inputs[i], false) +
                                            "): writing it would destroy the input; choose another output file");
        }
        for (std::size_t j = 0; j < k; ++j) {
            const NamedPath& other = outputs[j];
            if (other.path.empty()) continue;
            if (out.path == "-" && other.path == "-")
                throw std::invalid_argument(describe(other, true) + " and " + describe(out, true) +
                                            " would mix on standard output; send one of them to a file");
            if (same_file(out_ids[j], out_ids[k]))
                throw std::invalid_argument(describe(other, true) + " and " + describe(out, true) +
                                            " are the same file; give each output its own file");
        }
    }
}

namespace {

std::string parent_folder(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    return parent.empty() ? std::string(".") : parent.string();
}

[[noreturn]] void refuse(const NamedPath& p, const std::string& why) {
    throw std::invalid_argument(describe(p, true) + ": " + why);
}

// `dir` must be a folder where files may be created.
void check_writable_folder(const NamedPath& p, const std::string& dir) {
    struct stat st {};
    if (::stat(dir.c_str(), &st) != 0)
        refuse(p, "its folder " + dir + " does not exist (" + std::strerror(errno) + ")");
    if (!S_ISDIR(st.st_mode)) refuse(p, dir + " is not a folder");
    if (::access(dir.c_str(), W_OK | X_OK) != 0)
        refuse(p, "cannot create files in " + dir + " (" + std::strerror(errno) + ")");
}

}  // namespace

void check_outputs_creatable(const std::vector<NamedPath>& outputs) {
    for (const NamedPath& out : outputs) {
        if (out.path.empty() || out.path == "-") continue;
        struct stat st {};
        if (::stat(out.path.c_str(), &st) == 0) {
            if (S_ISDIR(st.st_mode)) refuse(out, "is a folder; give a file name");
            if (!S_ISREG(st.st_mode)) continue;  // devices and FIFOs are opened as they are
            // A file is replaced through a temporary file in its folder, or written in place.
            if (::access(parent_folder(out.path).c_str(), W_OK | X_OK) == 0 || ::access(out.path.c_str(), W_OK) == 0)
                continue;
            refuse(out, "cannot write it or create files in its folder (" + std::string(std::strerror(errno)) + ")");
        }
        if (errno != ENOENT) refuse(out, std::strerror(errno));
        check_writable_folder(out, parent_folder(out.path));
    }
}

bool output_is_file(const std::string& path) {
    if (path.empty() || path == "-") return false;
    struct stat st {};
    return ::stat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode);
}

void check_output_folder(const NamedPath& folder) {
    if (folder.path.empty()) return;
    struct stat st {};
    if (::stat(folder.path.c_str(), &st) == 0) {
        if (!S_ISDIR(st.st_mode)) refuse(folder, "exists and is not a folder");
        if (::access(folder.path.c_str(), W_OK | X_OK) != 0)
            refuse(folder, "cannot create files in it (" + std::string(std::strerror(errno)) + ")");
        return;
    }
    if (errno != ENOENT) refuse(folder, std::strerror(errno));
    // Created with its missing parents: the nearest one that exists must take new folders.
    fs::path p = fs::absolute(folder.path).lexically_normal();
    while (p.has_parent_path() && p.parent_path() != p) {
        p = p.parent_path();
        if (::stat(p.c_str(), &st) == 0) {
            if (!S_ISDIR(st.st_mode)) refuse(folder, p.string() + " is not a folder");
            if (::access(p.c_str(), W_OK | X_OK) != 0)
                refuse(folder, "cannot create it in " + p.string() + " (" + std::strerror(errno) + ")");
            return;
        }
    }
}

}  // namespace evcorner::io
