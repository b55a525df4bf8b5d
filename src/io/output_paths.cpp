#include "evcorner/io/output_paths.hpp"

#include <sys/stat.h>
#include <unistd.h>

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

}  // namespace evcorner::io
