#pragma once
// Checking a command's output paths against its inputs and each other, before anything
// is opened for writing: an output that is an input would destroy it, and two outputs
// on one file or stream would mix.
//
//   io::check_output_paths({{"INPUT", o.input}},
//                          {{"-o", o.output}, {"--mask", o.mask}, {"--summary-json", o.summary_json}});
//
// Each path comes with the option (or argument) that named it, for the message. Empty
// paths (options not given) are left out. "-" is standard input among the inputs and
// standard output among the outputs.

#include <string>
#include <string_view>
#include <vector>

namespace evcorner::io {

struct NamedPath {
    std::string_view option;  ///< how the user gave it: "INPUT", "-o", "--mask", "--json"
    std::string path;         ///< "" = not given; "-" = standard input / output
};

/// Throws std::invalid_argument (a usage error), naming both options and paths, when
///  - an output is an input: the same file (device and inode, symbolic links followed),
///    "-" among the outputs when standard output goes to an input, or an output that is the
///    file standard input ("-") comes from;
///  - two outputs are the same file (device and inode; for files that do not exist yet,
///    the same absolute path, symbolic links in its folders resolved), or both "-", or "-"
///    and the file or pipe standard output goes to.
/// Character devices (/dev/null, a terminal) may take several outputs and never count as an
/// input. Only stat()s the paths: opens, creates and changes nothing.
void check_output_paths(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs);

/// Throws std::invalid_argument, naming the option and path, for an output file that
/// cannot be created: the path is a folder, its folder does not exist (or is not a
/// folder), or neither the folder nor an existing file there may be written. Devices,
/// FIFOs and "-" pass. Checked before anything is read, so that a run fails at once
/// instead of after its work. Only stat()s and access()es the paths.
void check_outputs_creatable(const std::vector<NamedPath>& outputs);

/// True when `path` is written as a file (put under its name only when complete):
/// not "-" and not a device, FIFO or socket; false for those streams, which keep what was
/// written before an error.
bool output_is_file(const std::string& path);

/// The same for an output folder that is created when missing (eval --report): it must be
/// a folder if it exists, else its nearest existing parent must be a folder that may be written.
void check_output_folder(const NamedPath& folder);

}  // namespace evcorner::io
