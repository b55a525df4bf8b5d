#include "evcorner/io/event_writer.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <stdexcept>

#include "evcorner/error.hpp"
#include "evcorner/io/aedat4_writer.hpp"
#include "evcorner/io/hdf5_events.hpp"
#include "evcorner/io/csv_writer.hpp"
#include "evcorner/io/npy.hpp"
#include "evcorner/io/text_writer.hpp"

namespace evcorner::io {

namespace {

class TextEventWriter final : public EventWriter {
public:
    TextEventWriter(std::string path, bool with_score) : w_(std::move(path)), with_score_(with_score) {}
    void write(std::span<const Event> events) override {
        if (with_score_) throw std::logic_error("TextEventWriter: opened with scores, written without");
        w_.write(events);
    }
    void write(std::span<const Event> events, std::span<const double> scores) override {
        if (!with_score_ || scores.size() != events.size())
            throw std::logic_error("TextEventWriter: scores on a writer opened without, or not one per event");
        for (std::size_t i = 0; i < events.size(); ++i) w_.write(events[i], scores[i]);
    }
    void close() override { w_.close(); }
    [[nodiscard]] const std::string& name() const noexcept override { return w_.name(); }

private:
    TextWriter w_;
    bool with_score_;
};

bool ends_with(const std::string& s, std::string_view suffix) {
    if (s.size() < suffix.size()) return false;
    for (std::size_t i = 0; i < suffix.size(); ++i) {
        const char c = s[s.size() - suffix.size() + i];
        if ((c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c) != suffix[i]) return false;
    }
    return true;
}

}  // namespace

std::string output_format_for(const std::string& path) {
    if (ends_with(path, ".txt")) return "ecd-text";
    if (ends_with(path, ".csv")) return "csv";
    if (ends_with(path, ".npy")) return "npy";
    if (ends_with(path, ".aedat4")) return "aedat4";
    if (ends_with(path, ".h5") || ends_with(path, ".hdf5")) return "hdf5";
    return "";
}

std::string resolve_output_format(const std::string& path, std::string_view format) {
    if (format == "auto") {
        std::string f = output_format_for(path);
        if (!f.empty()) return f;
        // The extension as std::filesystem sees it: after the last '.' of the last
        // component, unless that '.' starts it (".hidden" has none).
        const auto slash = path.find_last_of('/');
        const std::string last = slash == std::string::npos ? path : path.substr(slash + 1);
        const auto dot = last.find_last_of('.');
        if (dot == std::string::npos || dot == 0 || last == "..") return "ecd-text";
        throw std::invalid_argument("output " + path + ": unknown extension '" + last.substr(dot) + "' (known: " +
                                    std::string(kOutputExtensions) + "; or name the format with --to: " +
                                    std::string(kOutputFormats) + ")");
    }
    if (format == "ecd-text" || format == "text") return "ecd-text";
    if (format == "h5" || format == "hdf5") return "hdf5";
    if (format == "csv" || format == "npy" || format == "aedat4") return std::string(format);
    throw std::invalid_argument("unknown output format '" + std::string(format) + "' (known: auto, " +
                                std::string(kOutputFormats) + ")");
}

void EventWriter::write(std::span<const Event> /*events*/, std::span<const double> /*scores*/) {
    throw std::logic_error("EventWriter: this writer was not opened with scores");
}

namespace {

// Refuses, before anything is opened or read, an output that is a pipe or socket (a FIFO
// path, or standard output to one) for a format that completes its file by seeking back:
// it would stream every event and then fail, leaving its reader a header with no count.
void refuse_stream_output(const std::string& path, std::string_view format, std::string_view why) {
    struct stat st {};
    bool stream = false;
    if (path == "-")
        stream = ::fstat(STDOUT_FILENO, &st) == 0 && !S_ISREG(st.st_mode) && ::lseek(STDOUT_FILENO, 0, SEEK_CUR) < 0;
    else
        stream = ::stat(path.c_str(), &st) == 0 && (S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode));
    if (!stream) return;
    throw std::invalid_argument("output " + (path == "-" ? std::string("- (standard output)") : path) +
                                " is a pipe or socket, which cannot seek back: " + std::string(why) + "; write " +
                                std::string(format) + " to a regular file, or stream ecd-text or csv");
}

}  // namespace

std::unique_ptr<EventWriter> open_event_writer(const std::string& path, std::string_view format,
                                               std::optional<SensorSize> sensor, bool with_score) {
    const std::string f = resolve_output_format(path, format);
    if (f == "npy") refuse_stream_output(path, f, "a .npy header holds the event count, written last");
    if (f == "hdf5") refuse_stream_output(path, f, "HDF5 seeks back to complete its file");
    if (f == "aedat4" && !sensor)
        refuse_stream_output(path, f, "with no sensor size given, AEDAT 4.0 records the size at the end");
    if (f == "ecd-text") return std::make_unique<TextEventWriter>(path, with_score);
    if (f == "csv") return std::make_unique<CsvWriter>(path, with_score);
    if (f == "npy") return std::make_unique<NpyWriter>(path, with_score);
    if (with_score && f == "aedat4")
        throw std::invalid_argument("output " + path + ": AEDAT 4.0 event packets have no field for a score "
                                    "(formats that carry scores: " + std::string(kScoredOutputFormats) + ")");
    if (f == "aedat4") {
        Aedat4Writer::Options o;
        o.sensor = sensor;
        return std::make_unique<Aedat4Writer>(path, o);
    }
    Hdf5Writer::Options o;
    o.sensor = sensor;
    o.with_score = with_score;
    return std::make_unique<Hdf5Writer>(path, o);
}

}  // namespace evcorner::io
