// evcorner: corner detection on event-camera streams.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>

#include "commands.hpp"

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
    evcorner::cli::add_detect_command(app);
    evcorner::cli::add_info_command(app);
    evcorner::cli::add_convert_command(app);
    evcorner::cli::add_label_command(app);
    evcorner::cli::add_eval_command(app);
    evcorner::cli::add_render_command(app);
    evcorner::cli::add_bench_command(app);
    // The command list shows each command's first line; the rest of its description
    // heads its own --help, before the examples.
    for (CLI::App* cmd : app.get_subcommands({})) {
        const std::string text = cmd->get_description();
        const auto nl = text.find('\n');
        if (nl == std::string::npos) continue;
        cmd->footer(text.substr(nl + 1) + "\n\n" + cmd->get_footer());
        cmd->description(text.substr(0, nl));
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
        return 2;
    } catch (const std::invalid_argument& e) {
        // A parameter out of range, caught when the detector or writer is built.
        std::fprintf(stderr, "evcorner: error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "evcorner: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
