// evcorner: corner detection on event-camera streams.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <exception>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "commands.hpp"
#include "std_streams.hpp"

using evcorner::cli::finish_stdout;

namespace {

std::size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diag = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diag = up;
        }
    }
    return row[b.size()];
}

// "unknown command 'detec'; did you mean 'detect'?" for a first argument that names no
// command; empty when it is one (or an option).
std::string unknown_command(CLI::App& app, const std::string& word) {
    if (word.empty() || word[0] == '-') return {};
    std::vector<std::string> names;
    for (const CLI::App* cmd : app.get_subcommands({})) {
        if (cmd->check_name(word)) return {};
        names.push_back(cmd->get_name());
    }
    std::string best;
    std::size_t best_d = std::string::npos;
    for (const auto& n : names) {
        std::string lower = word;  // "DETECT" is a slip too
        for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        const std::size_t d = lower == n ? 1 : edit_distance(lower, n);
        if (d < best_d) {
            best_d = d;
            best = n;
        }
    }
    std::string msg = "unknown command '" + word + "'";
    // Close enough to be a slip: at most 2 edits, and fewer than half the word.
    if (best_d <= 2 && 2 * best_d < std::max(word.size(), best.size())) return msg + "; did you mean '" + best + "'?";
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    return msg + " (commands: " + list + ")";
}

// "did you mean '--nms-radius'?" for the first long option of the command line that the
// command named (or the top level) does not have, when one of its options is close to it;
// empty otherwise.
std::string option_suggestion(CLI::App& app, int argc, char** argv) {
    CLI::App* cmd = &app;
    for (CLI::App* sub : app.get_subcommands())  // the command that was parsed
        cmd = sub;
    std::vector<std::string> names;
    for (const CLI::Option* opt : cmd->get_options())
        for (const std::string& n : opt->get_lnames()) names.push_back("--" + n);
    for (int i = 1; i < argc; ++i) {
        std::string word = argv[i];
        if (word == "--") break;
        if (word.size() < 3 || word.compare(0, 2, "--") != 0) continue;
        if (const auto eq = word.find('='); eq != std::string::npos) word.resize(eq);
        if (std::find(names.begin(), names.end(), word) != names.end()) continue;
        std::string best;
        std::size_t best_d = std::string::npos;
        for (const auto& n : names)
            if (const std::size_t d = edit_distance(word, n); d < best_d) {
                best_d = d;
                best = n;
            }
        if (best_d <= 2 && 2 * best_d < std::max(word.size(), best.size()) - 2)
            return "did you mean '" + best + "'? (" + cmd->get_name() + " has no option '" + word + "')";
        return {};
    }
    return {};
}

// Help and version text, through stdio so that a failed write keeps its errno.
int print_help(const CLI::App& app, const CLI::Error& e) {
    std::ostringstream text;
    const int status = app.exit(e, text);
    const std::string s = text.str();
    errno = 0;
    if (std::fwrite(s.data(), 1, s.size(), stdout) != s.size()) {
        std::fprintf(stderr, "evcorner: error: <stdout>: write failed: %s\n", std::strerror(errno));
        return 1;
    }
    return finish_stdout(status);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{
        "evcorner: turn an event-camera stream into a stream of corner events.\n"
        "Runs eFAST (Mueggler, Bartolozzi, Scaramuzza, BMVC 2017) event by event on the\n"
        "Surface of Active Events. Use 'evcorner COMMAND --help' for a command's options."};
    app.name("evcorner");
    app.set_version_flag("--version", "evcorner " EVCORNER_VERSION);
    app.require_subcommand(1);
    app.footer(
        "Example:\n"
        "  evcorner detect events.txt -o corners.txt     # Event-Camera-Dataset text in and out\n"
        "  evcorner info recording.aedat                 # what a file holds (any readable format)\n"
        "  evcorner convert recording.raw events.npy     # to text, CSV, npy, AEDAT 4 or HDF5\n"
        "  evcorner eval data/ecd --report report        # the paper's Tables 1 and 2, figures\n"
        "  evcorner bench events.txt                     # ns/event, max rate, latency on this machine\n"
        "Exit status: 0 on success, 1 on bad input or a failed write, 2 on a usage error.");
    // Only the command the first argument names is built: all eight commands' options
    // took about 7 M instructions, two thirds of a run's start. With no command named
    // (--help, --version, nothing, a slip), all of them, for the list and the suggestions.
    static constexpr struct {
        const char* name;
        void (*add)(CLI::App&);
    } kCommands[] = {{"detect", evcorner::cli::add_detect_command},   {"info", evcorner::cli::add_info_command},
                     {"convert", evcorner::cli::add_convert_command}, {"label", evcorner::cli::add_label_command},
                     {"eval", evcorner::cli::add_eval_command},       {"render", evcorner::cli::add_render_command},
                     {"bench", evcorner::cli::add_bench_command},     {"simulate", evcorner::cli::add_simulate_command},
                     {"track", evcorner::cli::add_track_command},     {"eval-tracks", evcorner::cli::add_eval_tracks_command}};
    const auto named = std::find_if(std::begin(kCommands), std::end(kCommands),
                                    [&](const auto& c) { return argc > 1 && std::strcmp(argv[1], c.name) == 0; });
    for (const auto& c : kCommands)
        if (named == std::end(kCommands) || &c == named) c.add(app);
    // The command list shows each command's first line; the rest of its description
    // heads its own --help, before the examples.
    for (CLI::App* cmd : app.get_subcommands({})) {
        const std::string text = cmd->get_description();
        const auto nl = text.find('\n');
        if (nl == std::string::npos) continue;
        cmd->footer(text.substr(nl + 1) + "\n\n" + cmd->get_footer());
        cmd->description(text.substr(0, nl));
    }
    if (argc > 1) {
        const std::string msg = unknown_command(app, argv[1]);
        if (!msg.empty()) {
            std::fprintf(stderr, "evcorner: error: %s\nRun with --help for more information.\n", msg.c_str());
            return 2;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return print_help(app, e);
    } catch (const CLI::CallForAllHelp& e) {
        return print_help(app, e);
    } catch (const CLI::CallForVersion& e) {
        return print_help(app, e);
    } catch (const CLI::ParseError& e) {
        std::string msg = e.what();
        if (const std::string hint = option_suggestion(app, argc, argv); !hint.empty()) msg += "; " + hint;
        std::fprintf(stderr, "evcorner: error: %s\nRun with --help for more information.\n", msg.c_str());
        return finish_stdout(2);
    } catch (const std::invalid_argument& e) {
        // A parameter out of range, caught when the detector or writer is built, or
        // outputs that would overwrite an input or each other (checked before opening).
        std::fprintf(stderr, "evcorner: error: %s\n", e.what());
        return finish_stdout(2);
    } catch (const std::system_error& e) {
        // fmt::print reports a failed write to a stream this way.
        if (std::ferror(stdout)) {
            std::fprintf(stderr, "evcorner: error: <stdout>: write failed: %s\n", e.code().message().c_str());
            return 1;
        }
        std::fprintf(stderr, "evcorner: error: %s\n", e.what());
        return finish_stdout(1);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "evcorner: error: %s\n", e.what());
        return finish_stdout(1);
    }
    return finish_stdout(0);
}
