#include "evcorner/io/mat_reader.hpp"

#include <fmt/format.h>
#include <matio.h>
#include <sys/stat.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <mutex>

#include "evcorner/error.hpp"
#include "evcorner/io/dynamic_library.hpp"
#include "evcorner/io/line_source.hpp"

namespace evcorner::io {

namespace {

// ---------------------------------------------------------------- libmatio, opened on first use
// libmatio is not linked: io/dynamic_library.hpp says why, and how the names below shadow
// <matio.h>'s. Every matio function this file calls:
#define EVCORNER_MATIO_FUNCTIONS(X)                                                                              \
    X(Mat_LogInitFunc) X(Mat_Open) X(Mat_Close) X(Mat_VarReadInfo) X(Mat_VarReadNextInfo) X(Mat_VarRead)          \
    X(Mat_VarFree) X(Mat_SizeOfClass)

struct MatioApi {
#define EVCORNER_FIELD(name) decltype(&::name) name = nullptr;
    EVCORNER_MATIO_FUNCTIONS(EVCORNER_FIELD)
#undef EVCORNER_FIELD

    /// The table, the library loaded on the first call (thread-safe); throws
    /// std::runtime_error when it cannot be loaded or lacks a name.
    static const MatioApi& get() {
        static const MatioApi api = [] {
            static const DynamicLibrary lib("libmatio, which .mat files need (Debian: apt-get install libmatio11)",
                                            {EVCORNER_MATIO_SONAME, EVCORNER_MATIO_PATH});
            MatioApi a;
#define EVCORNER_LOAD(name) lib.symbol(a.name, #name);
            EVCORNER_MATIO_FUNCTIONS(EVCORNER_LOAD)
#undef EVCORNER_LOAD
            return a;
        }();
        return api;
    }
};

// The shadows: Mat_Open(...) here calls the loaded Mat_Open.
#define EVCORNER_SHADOW(name) [[maybe_unused]] constexpr auto name = &Forwarder<decltype(&::name)>::call<MatioApi, &MatioApi::name>;
EVCORNER_MATIO_FUNCTIONS(EVCORNER_SHADOW)
#undef EVCORNER_SHADOW
#undef EVCORNER_MATIO_FUNCTIONS

// libmatio reports through a log function (its default one prints, and aborts on errors):
// ours keeps the last message for our own error.
thread_local std::string g_matio_message;
void matio_log(int /*level*/, char* message) { g_matio_message = message != nullptr ? message : ""; }
// Also loads libmatio; its failure is an InputError naming `file`.
void init_matio_log(const std::string& file) {
    load_for<MatioApi, InputError>(file);
    static std::once_flag once;
    std::call_once(once, [] { Mat_LogInitFunc("evcorner", matio_log); });
}

struct MatClose {
    void operator()(mat_t* m) const { Mat_Close(m); }
};
struct VarFree {
    void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using MatPtr = std::unique_ptr<mat_t, MatClose>;
using VarPtr = std::unique_ptr<matvar_t, VarFree>;

bool numeric_class(matio_classes c) { return c >= MAT_C_DOUBLE && c <= MAT_C_UINT64; }

bool is_event_matrix(const matvar_t* v) {
    return v->rank == 2 && v->dims[1] == 4 && numeric_class(v->class_type) && v->isComplex == 0 &&
           v->isLogical == 0;
}

std::string describe(const matvar_t* v) {
    std::string dims;
    for (int i = 0; i < v->rank; ++i) {
        if (i > 0) dims += 'x';
        dims += std::to_string(v->dims[i]);
    }
    static constexpr const char* kClass[] = {"empty",  "cell",   "struct", "object", "char",   "sparse",
                                             "double", "single", "int8",   "uint8",  "int16",  "uint16",
                                             "int32",  "uint32", "int64",  "uint64", "function", "opaque"};
    const auto c = static_cast<std::size_t>(v->class_type);
    return fmt::format("{} ({} {}{})", quote_bytes(v->name ? v->name : "?", 64), dims, c < std::size(kClass) ? kClass[c] : "?",
                       v->isComplex ? ", complex" : "");
}

// ---------------------------------------------------------------- MAT 5 tags, before libmatio
// libmatio sizes some allocations by the tags of a variable's header before it reads them,
// and does not see a file cut short:
// - Mat_VarReadNextInfo allocates the dimensions array from the byte count of its tag: a
//   420-byte file whose dimensions declared 4 GiB made it ask for 8 GiB (fuzz_mat), and the
//   scan then ended in "no variable" rather than in the damage;
// - array flags with a damaged tag, then a name tag declaring 3.3 GB: 3.3 GB of memory
//   filled for a 325-byte file (fuzz_mat, fuzz/seeds/regress-damaged-flags.mat);
// - an uncompressed variable missing its last bytes read them as zeros (a time of 0).
// So the element tags of a MAT 5 file are walked here first (the MAT-File Format's Level 5
// layout: a 128-byte header, then data elements, each an 8-byte tag of type and byte count,
// or a 4-byte "small element" tag when the count's half of the first word is not zero; a matrix
// opens with its array flags, dimensions and name sub-elements; a compressed element is a
// zlib stream holding one such element). MAT 7.3 files (HDF5 inside) are not walked, and
// Level 4 files are refused (check_mat_file()).
constexpr std::uint32_t kMiMatrix = 14;
constexpr std::uint32_t kMiCompressed = 15;
// The most data `compressed` bytes can hold: deflate expands at most 1032:1 (zlib's
// bound), with 64 KiB of slack. Shared by the tag walk and the variable's declared data.
double most_inflated(double compressed) noexcept { return 1032.0 * compressed + 65536.0; }

struct Mat5Tag {
    std::uint32_t type;
    std::uint32_t bytes;
    bool small;  // 4-byte tag, data in the tag's second word
    // The bytes the element takes with its tag, sub-elements padded to 8 bytes.
    [[nodiscard]] std::uint64_t padded() const noexcept { return small ? 8 : 8 + ((std::uint64_t{bytes} + 7) & ~std::uint64_t{7}); }
};

class Mat5Walk {
public:
    Mat5Walk(const std::string& name, bool little) : name_(name), little_(little) {}

    [[nodiscard]] std::uint32_t word(const unsigned char* p) const noexcept {
        return little_ ? std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24
                       : std::uint32_t{p[3]} | std::uint32_t{p[2]} << 8 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[0]} << 24;
    }
    [[nodiscard]] Mat5Tag tag(const unsigned char* p) const noexcept {
        const std::uint32_t w = word(p);
        if ((w >> 16) != 0) return {w & 0xFFFF, w >> 16, true};
        return {w, word(p + 4), false};
    }

    // The array flags, dimensions and name of a matrix whose content declares `declared`
    // bytes; `body` holds the first `have` of them. The matrix element's tag lies at byte
    // offset `at` of the file, or (`compressed`) begins the stream of the compressed
    // element at `at`.
    void check_matrix(std::uint64_t at, const unsigned char* body, std::size_t have, std::uint64_t declared,
                      bool compressed) const {
        // What each sub-element must be (the format fixes them): the array flags 8 bytes of
        // miUINT32 (6), the dimensions 4 bytes of miINT32 (5) per dimension and at least
        // two, the name miINT8 (1), a small element when it has 4 characters or fewer.
        // A tag out of form shifts what libmatio reads next away from what is checked here:
        // it reads the flags as 8 bytes whatever their tag says, and after dimensions of
        // type 69 and 4 bytes it took its name tag from 4 bytes before where the format
        // puts it (fuzz_mat: a name of 2.6 GB, fuzz/seeds/regress-damaged-dims-type.mat).
        struct Part {
            const char* name;
            const char* expected;
            bool (*valid)(const Mat5Tag&);
        };
        static constexpr Part kParts[] = {
            {"array flags", "8 bytes of type 6, miUINT32",
             [](const Mat5Tag& t) { return !t.small && t.type == 6 && t.bytes == 8; }},
            {"dimensions", "type 5, miINT32, 4 bytes per dimension and at least 8",
             [](const Mat5Tag& t) { return !t.small && t.type == 5 && t.bytes % 4 == 0 && t.bytes >= 8; }},
            {"name", "type 1, miINT8", [](const Mat5Tag& t) { return t.type == 1; }},
        };
        const auto where = [&](std::uint64_t off) {
            return compressed ? fmt::format("{} (a compressed variable, byte {} of its decompressed data)", at, 8 + off)
                              : std::to_string(at + 8 + off);
        };
        std::uint64_t off = 0;
        bool sparse = false;  // its dimensions may exceed its data
        bool object = false;  // mxOPAQUE: sizes checked, not the form
        for (int i = 0; i < 3; ++i) {
            const Part& part = kParts[i];
            if (off + 8 > have) return;  // not read here: libmatio's own checks follow
            const Mat5Tag t = tag(body + off);
            if (!part.valid(t) && !(object && i > 0))
                throw InputError(name_, fmt::format("byte offset {}: the {} of a variable have a damaged tag (type {}, "
                                                    "{} bytes; {} expected): the file is damaged",
                                                    where(off), part.name, t.type, t.bytes, part.expected));
            const std::uint64_t end = off + (t.small ? 8 : 8 + std::uint64_t{t.bytes});
            if (end > declared)
                throw InputError(name_, fmt::format("byte offset {}: the {} of a variable declare {} bytes, more than "
                                                    "the {} bytes of its matrix element: the file is damaged",
                                                    where(off), part.name, t.bytes, declared));
            if (i == 0) {
                if (have < 16) return;
                // The class, the low byte of the flags. An object (17, mxOPAQUE) is laid
                // out otherwise (names follow its flags, no dimensions), but libmatio reads
                // dimensions and a name there all the same (fuzz_mat: "dimensions" of 1
                // GB in a 500-byte object, a 2 GB allocation): for an object only the sizes
                // are checked, not the form.
                const std::uint32_t cls = word(body + 8) & 0xFF;
                object = cls == 17;
                sparse = cls == 5;
            } else if (i == 1 && !sparse && !object && end <= have) {
                // Every element of a dense array, cell or struct takes at least a byte of
                // the matrix element (libmatio sized allocations by the dimensions: 4 x
                // 687 865 860 in a 320-byte file, fuzz/seeds/regress-damaged-dims-count.mat).
                double elements = 1;
                for (std::uint64_t d = 0; d < t.bytes / 4; ++d) elements *= static_cast<double>(word(body + off + 8 + 4 * d));
                if (elements > static_cast<double>(declared))
                    throw InputError(name_, fmt::format("byte offset {}: the dimensions of a variable hold {:.0f} "
                                                        "elements, more than the {} bytes of its matrix element: the "
                                                        "file is damaged",
                                                        where(off), elements, declared));
            }
            off += t.padded();
        }
    }

    void check_file(std::ifstream& in, std::uint64_t size) const {
        std::uint64_t at = 128;
        std::vector<unsigned char> body;
        while (at + 8 <= size) {
            unsigned char raw[8];
            in.seekg(static_cast<std::streamoff>(at));
            if (!in.read(reinterpret_cast<char*>(raw), 8)) return;
            const Mat5Tag t = tag(raw);
            if (t.small) {
                at += 8;
                continue;
            }
            if (t.bytes > size - at - 8)
                throw InputError(name_, fmt::format("byte offset {}: a data element declares {} bytes, but only {} "
                                                    "follow its tag: the file is cut short or damaged",
                                                    at, t.bytes, size - at - 8));
            if (t.type == kMiMatrix || t.type == kMiCompressed) {
                // A compressed element's stream is read past its declared end too: libmatio
                // inflates on from the file (fuzz_mat: 5 bytes declared, a header of 296
                // inflated from what follows, dimensions of 1.9 GB).
                const std::uint64_t readable = t.type == kMiMatrix ? t.bytes : size - at - 8;
                body.resize(static_cast<std::size_t>(std::min<std::uint64_t>(readable, 4096)));
                if (!in.read(reinterpret_cast<char*>(body.data()), static_cast<std::streamsize>(body.size()))) return;
                if (t.type == kMiMatrix) check_matrix(at, body.data(), body.size(), t.bytes, false);
                else check_compressed(at, body, t.bytes);
            }
            at += 8 + std::uint64_t{t.bytes};  // top-level elements are not padded
        }
    }

private:
    // A compressed element at byte offset `at` of `bytes` compressed bytes, the first of
    // which are in `z`: the tag and matrix header of the element it holds.
    void check_compressed(std::uint64_t at, const std::vector<unsigned char>& z, std::uint64_t bytes) const {
        unsigned char out[512];
        z_stream zs{};
        if (inflateInit(&zs) != Z_OK) return;
        zs.next_in = const_cast<unsigned char*>(z.data());
        zs.avail_in = static_cast<uInt>(z.size());
        zs.next_out = out;
        zs.avail_out = sizeof out;
        // What inflates before any error in the stream: libmatio reads a header out of a
        // stream damaged after it (fuzz_mat: dimensions of 1.9 GB, then bad deflate data),
        // and reports the damage itself.
        inflate(&zs, Z_SYNC_FLUSH);
        const std::size_t have = sizeof out - zs.avail_out;
        inflateEnd(&zs);
        if (have < 8) return;
        const Mat5Tag inner = tag(out);
        if (inner.small || inner.type != kMiMatrix) return;
        if (static_cast<double>(inner.bytes) > most_inflated(static_cast<double>(bytes)))
            throw InputError(name_, fmt::format("byte offset {}: a compressed variable declares {} bytes, more than its "
                                                "{} compressed bytes can hold: the file is damaged",
                                                at, inner.bytes, bytes));
        check_matrix(at, out + 8, have - 8, inner.bytes, true);
    }

    const std::string& name_;
    bool little_;
};

// Checks a MAT-file before libmatio opens it: the 128-byte header of a Level 5 (MATLAB 5
// and later) or 7.3 file, then, for Level 5, the element tags (InputError for one out of
// form or declaring more than its file or element holds). A file without that header is
// refused: libmatio would take it for a Level 4 file, whose header's name length it
// allocates before reading (fuzz_mat: 1.7 GB filled for a 357-byte file).
void check_mat_file(const std::string& name, std::uint64_t size) {
    std::ifstream in(name, std::ios::binary);
    unsigned char head[128];
    if (!in || !in.read(reinterpret_cast<char*>(head), sizeof head))
        throw InputError(name, fmt::format("{} bytes, shorter than the 128-byte header of a MAT-file", size));
    // Bytes 126-127, the endian indicator: "IM" written little-endian, "MI" big-endian;
    // bytes 124-125: the version, 0x0100 for Level 5, 0x0200 for 7.3 (HDF5 inside).
    const bool little = head[126] == 'I' && head[127] == 'M';
    const bool big = head[126] == 'M' && head[127] == 'I';
    const unsigned version = little ? head[124] | head[125] << 8 : head[125] | head[124] << 8;
    if ((!little && !big) || (version != 0x0100 && version != 0x0200))
        throw InputError(name, "bytes 124-127 hold no MAT-file version (0x0100 or 0x0200) and endian indicator "
                               "('IM' or 'MI'): not a MAT-file of MATLAB 5 or later (Level 4 MAT-files are not read)");
    if (version == 0x0100) Mat5Walk(name, little).check_file(in, size);
}

// Column `c` (0-based) of the rows x 4 column-major data of `v`, as T.
template <class Fn>
void each_value(const matvar_t* v, std::size_t rows, int c, Fn&& fn) {
    const std::size_t base = static_cast<std::size_t>(c) * rows;
    auto run = [&](auto* data) {
        for (std::size_t i = 0; i < rows; ++i) fn(i, data[base + i]);
    };
    switch (v->class_type) {
        case MAT_C_DOUBLE: return run(static_cast<const double*>(v->data));
        case MAT_C_SINGLE: return run(static_cast<const float*>(v->data));
        case MAT_C_INT8: return run(static_cast<const std::int8_t*>(v->data));
        case MAT_C_UINT8: return run(static_cast<const std::uint8_t*>(v->data));
        case MAT_C_INT16: return run(static_cast<const std::int16_t*>(v->data));
        case MAT_C_UINT16: return run(static_cast<const std::uint16_t*>(v->data));
        case MAT_C_INT32: return run(static_cast<const std::int32_t*>(v->data));
        case MAT_C_UINT32: return run(static_cast<const std::uint32_t*>(v->data));
        case MAT_C_INT64: return run(static_cast<const std::int64_t*>(v->data));
        case MAT_C_UINT64: return run(static_cast<const std::uint64_t*>(v->data));
        default: return;
    }
}

}  // namespace

MatReader::MatReader(const std::string& path, ReaderOptions options) : name_(path), options_(std::move(options)) {
    struct stat st {};
    if (path == "-" || ::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
        throw InputError(name_ == "-" ? "<stdin>" : name_,
                         "a MATLAB .mat file is read by libmatio from a regular file; a pipe or standard input "
                         "cannot be read as .mat (save it to a file first)");
    file_size_ = static_cast<std::uint64_t>(st.st_size);
    check_mat_file(path, *file_size_);
    init_matio_log(name_);
    g_matio_message.clear();
    MatPtr mat(Mat_Open(path.c_str(), MAT_ACC_RDONLY));
    if (!mat)
        throw InputError(name_, "libmatio cannot open it as a MAT-file" +
                                    (g_matio_message.empty() ? std::string() : ": libmatio says " + quote_bytes(g_matio_message, 200)));

    // Columns.
    const std::string spec = options_.mat_columns.empty() ? "x,y,p,t" : options_.mat_columns;
    {
        int seen[4] = {-1, -1, -1, -1};
        std::size_t start = 0;
        int col = 0;
        for (;; ++col) {
            const auto comma = spec.find(',', start);
            std::string_view field = std::string_view(spec).substr(start, comma == std::string::npos ? std::string::npos : comma - start);
            while (!field.empty() && field.front() == ' ') field.remove_prefix(1);
            while (!field.empty() && field.back() == ' ') field.remove_suffix(1);
            std::string n;
            for (const char ch : field) n += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
            int role = -1;
            if (n == "t" || n == "ts" || n == "timestamp" || n == "time" || n == "t_us") role = 0;
            else if (n == "x") role = 1;
            else if (n == "y") role = 2;
            else if (n == "p" || n == "pol" || n == "polarity" || n == "on") role = 3;
            else if (n != "_" || col >= 4)
                throw InputError(name_, option_spelling(options_, "--mat-columns") + " '" + spec + "': expected 4 names, each t, x, y, p or _");
            if (role >= 0) {
                if (seen[role] >= 0) throw InputError(name_, option_spelling(options_, "--mat-columns") + " '" + spec + "' names a column twice");
                seen[role] = col;
            }
            if (comma == std::string::npos) break;
            start = comma + 1;
        }
        if (col != 3 || std::find(std::begin(seen), std::end(seen), -1) != std::end(seen))
            throw InputError(name_, option_spelling(options_, "--mat-columns") + " '" + spec + "' must name 4 columns and each of t, x, y, p once");
        std::copy(std::begin(seen), std::end(seen), col_);
    }

    // The variable.
    if (!options_.mat_var.empty()) {
        var_ = options_.mat_var;
    } else {
        std::vector<std::string> candidates, others;
        while (VarPtr info{Mat_VarReadNextInfo(mat.get())}) {
            if (is_event_matrix(info.get())) candidates.push_back(describe(info.get()));
            else others.push_back(describe(info.get()));
            if (is_event_matrix(info.get()) && candidates.size() == 1) var_ = info->name ? info->name : "";
        }
        if (candidates.size() != 1) {
            std::string list;
            for (const auto& c : candidates.empty() ? others : candidates) list += (list.empty() ? "" : ", ") + c;
            throw InputError(name_, candidates.empty()
                                        ? "no N x 4 real numeric variable to read events from (variables: " +
                                              (list.empty() ? std::string("none") : list) + ")"
                                        : "several N x 4 numeric variables: " + list + "; pick one with " + option_spelling(options_, "--mat-var"));
        }
    }
    // A damaged header can declare far more data than the file holds (fuzz_mat: 2^31 rows in
    // a 360-byte file), and libmatio would allocate it all before reading. Deflate (v5
    // compressed, v7.3) expands at most 1032:1, so a declared size beyond that is damage.
    if (VarPtr info{Mat_VarReadInfo(mat.get(), var_.c_str())}) {
        double declared = static_cast<double>(Mat_SizeOfClass(info->class_type));
        for (int d = 0; d < info->rank && info->dims; ++d) declared *= static_cast<double>(info->dims[d]);
        if (declared > most_inflated(static_cast<double>(file_size_.value_or(0))))
            throw InputError(name_, fmt::format("variable {} declares {:.0f} bytes of data, more than this {}-byte "
                                                "file can hold even compressed: the file is damaged",
                                                describe(info.get()), declared, file_size_.value_or(0)));
    }
    VarPtr var(Mat_VarRead(mat.get(), var_.c_str()));
    if (!var)
        throw InputError(name_, "no variable " + quote_bytes(var_) + " can be read" +
                                    (g_matio_message.empty() ? std::string() : " (libmatio says " + quote_bytes(g_matio_message, 200) + ")"));
    if (!is_event_matrix(var.get()) || var->data == nullptr)
        throw InputError(name_, "variable " + describe(var.get()) + " is not an N x 4 real numeric matrix");
    rows_ = var->dims[0];
    const std::size_t rows = static_cast<std::size_t>(rows_);

    const std::string& unit = options_.csv_time_unit;
    if (!unit.empty() && unit != "us" && unit != "ns" && unit != "ms" && unit != "s")
        throw InputError(name_, "unknown time unit '" + unit + "' (us, ns, ms or s)");
    float_time_ = var->class_type == MAT_C_DOUBLE || var->class_type == MAT_C_SINGLE;
    // MATLAB stores every number as double unless told otherwise, so the class says
    // nothing about the unit: microseconds unless told, and then a double time must be
    // a whole number (a fraction means another unit: an error that names --time-unit).
    whole_us_ = unit.empty() && float_time_;
    const std::string u = unit.empty() ? "us" : unit;
    time_scale_ = u == "s" ? 1e6 : u == "ms" ? 1e3 : u == "us" ? 1.0 : 1e-3;
    time_mul_ = u == "s" ? 1'000'000 : u == "ms" ? 1000 : 1;
    time_div_ = u == "ns" ? 1000 : 1;

    values_.resize(rows * 4);
    for (int role = 1; role <= 3; ++role)
        each_value(var.get(), rows, col_[role], [&](std::size_t i, auto v) {
            values_[static_cast<std::size_t>(role) * rows + i] = static_cast<double>(v);
        });
    if (float_time_) {
        each_value(var.get(), rows, col_[0],
                   [&](std::size_t i, auto v) { values_[i] = static_cast<double>(v); });
    } else {
        tint_.resize(rows);
        std::uint64_t bad = rows;
        each_value(var.get(), rows, col_[0], [&](std::size_t i, auto v) {
            if constexpr (std::is_integral_v<decltype(v)>) {
                if (bad == rows && std::is_unsigned_v<decltype(v)> &&
                    static_cast<std::uint64_t>(v) > static_cast<std::uint64_t>(INT64_MAX))
                    bad = i;
                tint_[i] = static_cast<std::int64_t>(v);
            }
        });
        rows_ = std::min<std::uint64_t>(rows_, bad);  // rows up to the bad one are read, then the error
        if (bad < rows) error_ = std::make_exception_ptr(InputError(
                            name_, fmt::format("variable {}, row {}: time does not fit 63 bits", quote_bytes(var_, 64), bad + 1)));
    }
    sensor_ = options_.sensor ? options_.sensor : options_.fallback_sensor;
    if (sensor_) {
        limit_w_ = static_cast<std::uint32_t>(sensor_->width);
        limit_h_ = static_cast<std::uint32_t>(sensor_->height);
    }
}

MatReader::~MatReader() = default;

std::uint64_t MatReader::bytes_consumed() const noexcept {
    if (!file_size_ || rows_ == 0) return 0;
    return static_cast<std::uint64_t>(static_cast<double>(*file_size_) * static_cast<double>(next_) /
                                      static_cast<double>(rows_));
}

void MatReader::fail_row(std::uint64_t row, const std::string& reason) const {
    throw InputError(name_, fmt::format("variable {}, row {}: {}", quote_bytes(var_, 64), row + 1, reason));
}

std::size_t MatReader::read(std::span<Event> out) {
    skips_.new_batch();
    if (next_ == rows_ && error_) std::rethrow_exception(error_);
    const std::size_t rows = values_.size() / 4;
    std::size_t n = 0;
    try {
        while (n < out.size() && next_ < rows_) {
            const std::size_t i = static_cast<std::size_t>(next_);
            Event e;
            if (float_time_) {
                const double v = values_[i] * time_scale_;
                if (!(std::fabs(v) < 9.2e18)) fail_row(i, fmt::format("time {} is out of range", values_[i]));
                if (whole_us_ && v != std::floor(v))
                    fail_row(i, fmt::format("time {} is not a whole number of microseconds (the default unit of "
                                            ".mat times); pass {} s (or ms, ns) if the times are in another unit",
                                            values_[i], option_spelling(options_, "--time-unit")));
                e.t = std::llrint(v);
            } else {
                const std::int64_t v = tint_[i];
                if (time_mul_ > 1 && (v > INT64_MAX / time_mul_ || v < INT64_MIN / time_mul_))
                    fail_row(i, fmt::format("time {} overflows in microseconds", v));
                if (time_div_ > 1) {
                    const std::int64_t q = v / time_div_, r = v % time_div_;
                    e.t = q + (r >= time_div_ / 2 ? 1 : r <= -time_div_ / 2 ? -1 : 0);
                } else {
                    e.t = v * time_mul_;
                }
            }
            const double x = values_[rows + i], y = values_[2 * rows + i], p = values_[3 * rows + i];
            if (!(x >= 0 && x <= 65535 && x == std::floor(x))) fail_row(i, fmt::format("x = {} is not an integer in 0..65535", x));
            if (!(y >= 0 && y <= 65535 && y == std::floor(y))) fail_row(i, fmt::format("y = {} is not an integer in 0..65535", y));
            if (p != 1 && p != 0 && p != -1) fail_row(i, fmt::format("polarity {} where 1 (ON), 0 or -1 (OFF) is expected", p));
            e.x = static_cast<std::uint16_t>(x);
            e.y = static_cast<std::uint16_t>(y);
            e.p = p == 1 ? 1 : 0;
            if (e.x >= limit_w_ || e.y >= limit_h_) {
                if (!options_.skip_invalid) fail_row(i, outside_sensor_message(e.x, e.y, sensor_, options_.keyword_spelling));
                skips_.skip(n);
                ++next_;
                continue;
            }
            if (e.t < last_t_) fail_row(i, backwards_message(last_t_, e.t));
            last_t_ = e.t;
            out[n++] = e;
            ++next_;
        }
    } catch (const InputError&) {
        error_ = std::current_exception();
        rows_ = next_;  // nothing more after the damage
        if (n == 0 && skips_.batch().empty()) throw;
    }
    return n;
}

}  // namespace evcorner::io
