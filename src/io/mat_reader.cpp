#include "evcorner/io/mat_reader.hpp"

#include <fmt/format.h>
#include <matio.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cmath>
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
                throw InputError(name_, "--mat-columns '" + spec + "': expected 4 names, each t, x, y, p or _");
            if (role >= 0) {
                if (seen[role] >= 0) throw InputError(name_, "--mat-columns '" + spec + "' names a column twice");
                seen[role] = col;
            }
            if (comma == std::string::npos) break;
            start = comma + 1;
        }
        if (col != 3 || std::find(std::begin(seen), std::end(seen), -1) != std::end(seen))
            throw InputError(name_, "--mat-columns '" + spec + "' must name 4 columns and each of t, x, y, p once");
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
                                        : "several N x 4 numeric variables: " + list + "; pick one with --mat-var");
        }
    }
    // A damaged header can declare far more data than the file holds (fuzz_mat: 2^31 rows in
    // a 360-byte file), and libmatio would allocate it all before reading. Deflate (v5
    // compressed, v7.3) expands at most 1032:1, so a declared size beyond that is damage.
    if (VarPtr info{Mat_VarReadInfo(mat.get(), var_.c_str())}) {
        double declared = static_cast<double>(Mat_SizeOfClass(info->class_type));
        for (int d = 0; d < info->rank && info->dims; ++d) declared *= static_cast<double>(info->dims[d]);
        const double limit = 1032.0 * static_cast<double>(file_size_.value_or(0)) + 65536.0;
        if (declared > limit)
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
                                            ".mat times); pass --time-unit s (or ms, ns) if the times are in another unit",
                                            values_[i]));
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
                if (!options_.skip_invalid) fail_row(i, outside_sensor_message(e.x, e.y, sensor_));
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
