#include "evcorner/io/formats.hpp"

#include <array>
#include <stdexcept>

#include "evcorner/error.hpp"
#include "evcorner/io/aedat2_reader.hpp"
#include "evcorner/io/aedat4_reader.hpp"
#include "evcorner/io/atis_reader.hpp"
#include "evcorner/io/csv_reader.hpp"
#include "evcorner/io/dat_reader.hpp"
#include "evcorner/io/evt2_reader.hpp"
#include "evcorner/io/evt3_reader.hpp"
#include "evcorner/io/hdf5_events.hpp"
#include "evcorner/io/mat_reader.hpp"
#include "evcorner/io/npy.hpp"
#include "evcorner/io/ros_bag.hpp"
#include "evcorner/io/text_reader.hpp"

namespace evcorner::io {

namespace {

// Readers that read the opened file front to back.
template <class Reader>
std::unique_ptr<EventReader> streamed(InputFile&& file, const std::string& /*path*/, ReaderOptions&& options) {
    return std::make_unique<Reader>(std::move(file), std::move(options));
}

std::unique_ptr<EventReader> open_text(InputFile&& file, const std::string& /*path*/, ReaderOptions&& options) {
    // Text has no sensor size: events are checked against the fallback one.
    if (!options.sensor) options.sensor = options.fallback_sensor;
    return std::make_unique<TextReader>(std::move(file), std::move(options));
}

std::unique_ptr<EventReader> open_hdf5(InputFile&& file, const std::string& path, ReaderOptions&& options) {
    // The HDF5 library seeks, and opens the file by its path: only a regular file will do.
    if (path == "-" || !file.size())
        throw InputError(file.name(), "HDF5 is read by seeking in a regular file; a pipe or standard input "
                                      "cannot be read as HDF5 (save it to a file first)");
    return std::make_unique<Hdf5Reader>(path, std::move(options));
}

std::unique_ptr<EventReader> open_mat(InputFile&& /*file*/, const std::string& path, ReaderOptions&& options) {
    return std::make_unique<MatReader>(path, std::move(options));  // libmatio opens the path
}

template <const std::string_view& kName>
std::unique_ptr<EventReader> open_bag(InputFile&& /*file*/, const std::string& path, ReaderOptions&& options) {
    return open_bag_reader(path, std::move(options), kName);  // read by seeking, by path
}

constexpr std::string_view kRosbag2 = "rosbag2", kMcap = "mcap", kRosbag = "rosbag";

const std::array<InputFormat, 14> kFormats = {{
    {"ecd-text", "text", "Event-Camera-Dataset text: 't x y p' lines, t in seconds", ".txt", {}, false, true, 0,
     open_text},
    {"csv", "", "CSV: columns from the header row or --csv-columns", ".csv", {}, false, true,
     kOptCsvColumns | kOptTimeUnit, streamed<CsvReader>},
    {"npy", "", "numpy .npy: a structured array with fields by name, or (N, 4) with --npy-columns", ".npy",
     {"\x93NUMPY"}, false, false, kOptNpyColumns | kOptTimeUnit, streamed<NpyReader>},
    {"aedat2", "aedat", "AEDAT 2.0 (jAER): DAVIS240/346, DVS128", ".aedat .aedat2", {"#!AER-DAT2.0"}, false, false,
     kOptChip, streamed<Aedat2Reader>},
    {"aedat4", "", "AEDAT 4.0 (DV): the first event stream, LZ4 or ZSTD", ".aedat4", {kAedat4Magic}, false, false, 0,
     streamed<Aedat4Reader>},
    {"evt2", "", "Prophesee RAW EVT 2.0", ".raw", {}, false, false, 0, streamed<Evt2Reader>},
    {"evt3", "", "Prophesee RAW EVT 3.0", ".raw", {}, false, false, 0, streamed<Evt3Reader>},
    {"dat", "", "Prophesee DAT (Event2d / EventCD)", ".dat", {}, false, false, 0, streamed<DatReader>},
    {"hdf5", "h5", "HDF5: DSEC events/{x,y,t,p} or event_utils events/{xs,ys,ts,ps}", ".h5 .hdf5", {kHdf5Magic}, true,
     false, 0, open_hdf5},
    {"atis-bin", "", "ATIS .bin (N-MNIST, N-Caltech101): 5-byte records", ".bin", {}, false, false, 0,
     streamed<AtisReader>},
    {"mat", "", "MATLAB .mat (level 5 or 7.3): an N x 4 variable", ".mat",
     {"MATLAB 5.0 MAT-file", "MATLAB 7.3 MAT-file"}, true, false, kOptMatVar | kOptMatColumns | kOptTimeUnit, open_mat},
    {"rosbag2", "", "ROS 2 bag, SQLite storage (.db3, or the rosbag2 folder)", ".db3", {kSqliteMagic}, true, false,
     kOptTopic, open_bag<kRosbag2>},
    {"mcap", "", "ROS 2 bag, MCAP storage", ".mcap", {kMcapMagic}, true, false, kOptTopic, open_bag<kMcap>},
    {"rosbag", "", "ROS 1 bag, format 2.0", ".bag", {kRosbag1Magic}, true, false, kOptTopic, open_bag<kRosbag>},
}};

const std::array<ReaderOptionInfo, 7> kReaderOptions = {{
    {kOptCsvColumns, "--csv-columns", "csv_columns",
     "CSV column order, e.g. x,y,p,t ('_' skips a column; 'score' reads scores) [default: the header row, else t,x,y,p]",
     [](const ReaderOptions& o) { return o.csv_columns; }, [](ReaderOptions& o, std::string v) { o.csv_columns = std::move(v); }},
    {kOptTimeUnit, "--time-unit", "time_unit",
     "Time unit of CSV, .npy and .mat times: us, ns, ms or s [default: floats s, integers us; .mat us] "
     "(docs/formats.md, \"Times\")",
     [](const ReaderOptions& o) { return o.csv_time_unit; }, [](ReaderOptions& o, std::string v) { o.csv_time_unit = std::move(v); }},
    {kOptNpyColumns, "--npy-columns", "npy_columns",
     "A plain (N, 4) .npy array's column order, e.g. x,y,p,t ('_' skips one) [default: t,x,y,p]",
     [](const ReaderOptions& o) { return o.npy_columns; }, [](ReaderOptions& o, std::string v) { o.npy_columns = std::move(v); }},
    {kOptChip, "--chip", "aedat2_chip",
     "AEDAT 2.0: the camera that recorded the file (DVS128, DAVIS240C, DAVIS346, ...), instead of the header's "
     "'# AEChip' line",
     [](const ReaderOptions& o) { return o.aedat2_chip; }, [](ReaderOptions& o, std::string v) { o.aedat2_chip = std::move(v); }},
    {kOptMatVar, "--mat-var", "mat_var", "MATLAB .mat: the variable holding the N x 4 events [default: the only one]",
     [](const ReaderOptions& o) { return o.mat_var; }, [](ReaderOptions& o, std::string v) { o.mat_var = std::move(v); }},
    {kOptMatColumns, "--mat-columns", "mat_columns",
     "MATLAB .mat: the variable's column order ('_' skips one) [default: x,y,p,t]",
     [](const ReaderOptions& o) { return o.mat_columns; }, [](ReaderOptions& o, std::string v) { o.mat_columns = std::move(v); }},
    {kOptTopic, "--topic", "topic", "ROS bags: the topic to read [default: the bag's one event topic]",
     [](const ReaderOptions& o) { return o.topic; }, [](ReaderOptions& o, std::string v) { o.topic = std::move(v); }},
}};

bool has_word(std::string_view words, std::string_view w) {
    while (!words.empty()) {
        const auto sp = words.find(' ');
        if (words.substr(0, sp) == w) return true;
        if (sp == std::string_view::npos) break;
        words.remove_prefix(sp + 1);
    }
    return false;
}

}  // namespace

std::span<const InputFormat> input_formats() noexcept { return kFormats; }

const InputFormat* find_input_format(std::string_view name) noexcept {
    for (const InputFormat& f : kFormats)
        if (f.name == name || has_word(f.aliases, name)) return &f;
    return nullptr;
}

const std::string& input_format_names() {
    static const std::string names = [] {
        std::string s;
        for (const InputFormat& f : kFormats) s.append(s.empty() ? "" : ", ").append(f.name);
        return s;
    }();
    return names;
}

std::span<const ReaderOptionInfo> reader_option_infos() noexcept { return kReaderOptions; }

std::string option_spelling(const ReaderOptions& o, std::string_view flag) {
    if (!o.keyword_spelling) return std::string(flag);
    if (flag == "--size") return "sensor";
    for (const ReaderOptionInfo& r : kReaderOptions)
        if (r.flag == flag) return std::string(r.keyword);
    std::string k(flag.substr(flag.starts_with("--") ? 2 : 0));  // --skip-invalid: skip_invalid
    for (char& c : k)
        if (c == '-') c = '_';
    return k;
}

void check_reader_options(const InputFormat& format, const ReaderOptions& options, const std::string& file_name) {
    for (const ReaderOptionInfo& o : kReaderOptions) {
        if (o.bit == kOptTimeUnit || (format.options & o.bit) != 0 || o.get(options).empty()) continue;
        std::string takers;
        for (const InputFormat& f : kFormats)
            if (f.options & o.bit) takers.append(takers.empty() ? "" : ", ").append(f.name);
        throw std::invalid_argument(file_name + ": " + option_spelling(options, o.flag) + " applies to " + takers +
                                    " files; this file is " + std::string(format.name));
    }
}

}  // namespace evcorner::io
