#include "evcorner/io/hdf5_events.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <stdexcept>
#include <cstring>
#include <fmt/format.h>
#include <utility>

#include "evcorner/error.hpp"
#include "evcorner/io/dynamic_library.hpp"
#include "evcorner/io/pending_file.hpp"

namespace evcorner::io {

namespace {

// ---------------------------------------------------------------- libhdf5, opened on first use
// libhdf5 is not linked: io/dynamic_library.hpp says why, and how the names below shadow
// <hdf5.h>'s. Every HDF5 function this file calls (also through H5E_BEGIN_TRY / H5E_END_TRY
// and the H5OPEN in the type macros), and every global behind a macro it uses:
#define EVCORNER_HDF5_FUNCTIONS(X)                                                                               \
    X(H5open) X(H5check_version) X(H5dont_atexit) X(H5Eauto_is_v2) X(H5Eget_auto1) X(H5Eset_auto1) X(H5Eget_auto2)                 \
    X(H5Eset_auto2) X(H5Ewalk2) X(H5Eclear2) X(H5Fis_hdf5) X(H5Fopen) X(H5Fcreate) X(H5Fclose) X(H5Fflush)       \
    X(H5Fget_vfd_handle) X(H5Gcreate2) X(H5Gclose) X(H5Lexists) X(H5Dopen2) X(H5Dcreate2) X(H5Dclose)            \
    X(H5Dget_space) X(H5Dget_type) X(H5Dget_create_plist) X(H5Dget_storage_size) X(H5Dget_offset)                \
    X(H5Dget_chunk_info_by_coord) X(H5Dread) X(H5Dwrite) X(H5Dset_extent) X(H5Aexists) X(H5Aopen)                \
    X(H5Acreate2) X(H5Aget_space) X(H5Aget_type) X(H5Aread) X(H5Awrite) X(H5Aclose) X(H5Screate)                 \
    X(H5Screate_simple) X(H5Sget_simple_extent_ndims) X(H5Sget_simple_extent_dims)                              \
    X(H5Sget_simple_extent_npoints) X(H5Sselect_hyperslab) X(H5Sclose) X(H5Tget_class) X(H5Tget_size)           \
    X(H5Tget_native_type) X(H5Tclose) X(H5Pcreate) X(H5Pclose) X(H5Pget_nfilters) X(H5Pget_filter2)             \
    X(H5Pget_layout) X(H5Pget_chunk) X(H5Pset_chunk) X(H5Pset_deflate) X(H5Pset_filter) X(H5Zfilter_avail)
#define EVCORNER_HDF5_GLOBALS(X)                                                                                 \
    X(H5T_NATIVE_DOUBLE_g) X(H5T_NATIVE_INT_g) X(H5T_NATIVE_INT32_g) X(H5T_NATIVE_INT64_g)                        \
    X(H5T_NATIVE_UINT16_g) X(H5T_NATIVE_UINT8_g) X(H5T_STD_I32LE_g) X(H5T_STD_I64LE_g) X(H5T_STD_U16LE_g)        \
    X(H5T_STD_U8LE_g) X(H5T_IEEE_F64LE_g) X(H5P_CLS_DATASET_CREATE_ID_g)

struct Hdf5Api {
#define EVCORNER_FIELD(name) decltype(&::name) name = nullptr;
    EVCORNER_HDF5_FUNCTIONS(EVCORNER_FIELD)
#undef EVCORNER_FIELD
#define EVCORNER_FIELD(name) const hid_t* name = nullptr;
    EVCORNER_HDF5_GLOBALS(EVCORNER_FIELD)
#undef EVCORNER_FIELD

    /// The table, the library loaded on the first call (thread-safe); throws
    /// std::runtime_error when it cannot be loaded or lacks a name.
    static const Hdf5Api& get() {
        static const Hdf5Api api = [] {
            static const DynamicLibrary lib("libhdf5, which HDF5 files need (Debian: apt-get install libhdf5-103-1)",
                                            {EVCORNER_HDF5_SONAME, EVCORNER_HDF5_PATH});
            Hdf5Api a;
#define EVCORNER_LOAD(name) lib.symbol(a.name, #name);
            EVCORNER_HDF5_FUNCTIONS(EVCORNER_LOAD)
#undef EVCORNER_LOAD
#define EVCORNER_LOAD(name) a.name = static_cast<const hid_t*>(lib.variable_address(#name));
            EVCORNER_HDF5_GLOBALS(EVCORNER_LOAD)
#undef EVCORNER_LOAD
            // HDF5 prints its error stack to standard error on failure, also from the
            // library's own clean-up at exit, where no H5E_BEGIN_TRY reaches: switched off
            // once for the process (evcorner reports every failure itself, with
            // hdf5_reason()). And that clean-up at exit is not registered (H5dont_atexit,
            // which must come before HDF5's first call): after a write failure libhdf5 1.10
            // keeps a file it cannot close, and its clean-up then crashes or prints "infinite
            // loop closing library". Every file evcorner opens is closed by its reader or
            // writer; the operating system takes back the rest at exit. H5open() sets the
            // type globals (the type macros call it too, before reading one).
            a.H5dont_atexit();
            a.H5open();
            a.H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
            return a;
        }();
        return api;
    }
};

// The shadows: H5Fopen(...) here calls the loaded H5Fopen, H5T_NATIVE_INT reads the loaded
// H5T_NATIVE_INT_g.
#define EVCORNER_SHADOW(name) [[maybe_unused]] constexpr auto name = &Forwarder<decltype(&::name)>::call<Hdf5Api, &Hdf5Api::name>;
EVCORNER_HDF5_FUNCTIONS(EVCORNER_SHADOW)
#undef EVCORNER_SHADOW
struct Hdf5Global {
    const hid_t* Hdf5Api::*field;
    operator hid_t() const { return *(Hdf5Api::get().*field); }  // NOLINT: converts implicitly, as the global did
};
#define EVCORNER_SHADOW(name) [[maybe_unused]] constexpr Hdf5Global name{&Hdf5Api::name};
EVCORNER_HDF5_GLOBALS(EVCORNER_SHADOW)
#undef EVCORNER_SHADOW
#undef EVCORNER_HDF5_FUNCTIONS
#undef EVCORNER_HDF5_GLOBALS

// An HDF5 identifier closed by the matching H5?close at scope exit.
class Hid {
public:
    Hid() = default;
    Hid(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
    Hid(Hid&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = H5I_INVALID_HID; }
    Hid& operator=(Hid&& o) noexcept {
        std::swap(id_, o.id_);
        std::swap(close_, o.close_);
        return *this;
    }
    ~Hid() {
        if (id_ >= 0 && close_) {
            H5E_BEGIN_TRY { close_(id_); }
            H5E_END_TRY;
        }
    }
    [[nodiscard]] hid_t get() const noexcept { return id_; }
    hid_t release() noexcept { return std::exchange(id_, H5I_INVALID_HID); }
    [[nodiscard]] bool ok() const noexcept { return id_ >= 0; }

private:
    hid_t id_ = H5I_INVALID_HID;
    herr_t (*close_)(hid_t) = nullptr;
};

// HDF5 prints its error stack on failure unless told not to; the callers report errors.
template <class F>
auto quiet(F&& f) {
    decltype(f()) r{};
    H5E_BEGIN_TRY { r = f(); }
    H5E_END_TRY;
    return r;
}

// Why the last HDF5 call failed, from its error stack: the operating system's message
// where HDF5 recorded one ("errno = 28, error message = 'No space left on device'"),
// else the description of the innermost error (where it was detected). `err`: errno
// right after the call, the fallback.
std::string hdf5_reason(int err = 0) {
    struct Found {
        std::string system, innermost;
    } found;
    H5Ewalk2(
        H5E_DEFAULT, H5E_WALK_UPWARD,
        [](unsigned n, const H5E_error2_t* e, void* data) -> herr_t {
            auto& f = *static_cast<Found*>(data);
            const std::string desc = e->desc ? e->desc : "";
            if (n == 0) f.innermost = desc;
            const std::string key = "error message = '";
            const auto at = desc.find(key);
            if (f.system.empty() && at != std::string::npos) {
                const auto end = desc.find('\'', at + key.size());
                f.system = desc.substr(at + key.size(), end == std::string::npos ? std::string::npos : end - at - key.size());
            }
            return 0;
        },
        &found);
    H5Eclear2(H5E_DEFAULT);
    if (!found.system.empty()) return found.system;
    if (!found.innermost.empty()) return found.innermost;
    if (err != 0) return std::strerror(err);
    return "reason unknown";
}

bool link_exists(hid_t loc, const char* name) { return quiet([&] { return H5Lexists(loc, name, H5P_DEFAULT); }) > 0; }

// The Debian package that holds an HDF5 filter plugin.
std::string filter_hint(H5Z_filter_t id) {
    switch (id) {
        case 32001: return "the Blosc filter (Debian: apt-get install hdf5-filter-plugin-blosc-serial)";
        case 32004: return "the LZ4 filter (Debian: apt-get install hdf5-filter-plugin)";
        case 307: return "the BZip2 filter (Debian: apt-get install hdf5-filter-plugin)";
        case 32008: return "the Bitshuffle filter (Debian: apt-get install hdf5-filter-plugin)";
        case 32015: return "the ZSTD filter (not packaged in Debian 12: install hdf5plugin's libh5zstd into HDF5_PLUGIN_PATH)";
        default: return fmt::format("HDF5 filter {} (see https://portal.hdfgroup.org/display/support/Registered+Filter+Plugins)", id);
    }
}

std::optional<std::uint64_t> regular_file_size(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
    return static_cast<std::uint64_t>(st.st_size);
}

}  // namespace

struct Hdf5Reader::Impl {
    Hid file;
    Hid dset[4];  // x, y, t, p
    Hid score;    // events/score, when the file has one
    const char* names[4] = {};
    bool t_float = false;
    bool p_enum = false;
    std::size_t p_size = 1;
    hsize_t chunk = 0;  // the datasets' chunk length (0: contiguous)
    std::vector<unsigned char> p_raw;
};

Hdf5Reader::Hdf5Reader(std::string path, ReaderOptions options)
    : impl_(std::make_unique<Impl>()), name_(path == "-" ? "<stdin>" : path), options_(std::move(options)) {
    load_for<Hdf5Api, InputError>(name_);
    if (path == "-") throw InputError(name_, "HDF5 files cannot be read from standard input");
    file_size_ = regular_file_size(path);
    if (!file_size_) throw InputError(name_, "cannot open: not a regular file, or missing");
    if (quiet([&] { return H5Fis_hdf5(path.c_str()); }) <= 0)
        throw InputError(name_, InputError::Unit::byte, 0, "not an HDF5 file (no HDF5 signature)");
    impl_->file = Hid(quiet([&] { return H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT); }), H5Fclose);
    if (!impl_->file.ok()) throw InputError(name_, "HDF5 cannot open the file (damaged?): " + hdf5_reason(errno));
    const hid_t f = impl_->file.get();
    if (!link_exists(f, "events")) throw InputError(name_, "unsupported format: this looks like an HDF5 file without events (no 'events' group: "
                                              "not a DSEC or event_utils layout)");
    static const char* dsec[4] = {"events/x", "events/y", "events/t", "events/p"};
    static const char* eu[4] = {"events/xs", "events/ys", "events/ts", "events/ps"};
    if (link_exists(f, dsec[2]))
        layout_ = Layout::dsec;
    else if (link_exists(f, eu[2]))
        layout_ = Layout::event_utils;
    else
        throw InputError(name_, "neither events/t (DSEC) nor events/ts (event_utils) exists");
    const char* const* names = layout_ == Layout::dsec ? dsec : eu;
    for (int i = 0; i < 4; ++i) {
        impl_->names[i] = names[i];
        impl_->dset[i] = Hid(quiet([&] { return H5Dopen2(f, names[i], H5P_DEFAULT); }), H5Dclose);
        if (!impl_->dset[i].ok())
            throw InputError(name_, fmt::format("cannot open dataset {}: {}", names[i], hdf5_reason()));
        const hid_t d = impl_->dset[i].get();
        Hid space(H5Dget_space(d), H5Sclose);
        hsize_t dims[2] = {0, 0};
        if (!space.ok() || quiet([&] { return H5Sget_simple_extent_ndims(space.get()); }) != 1 ||
            quiet([&] { return H5Sget_simple_extent_dims(space.get(), dims, nullptr); }) != 1)
            throw InputError(name_, fmt::format("dataset {} is not one-dimensional", names[i]));
        if (i == 0)
            total_ = dims[0];
        else if (dims[0] != total_)
            throw InputError(name_, fmt::format("dataset {} holds {} values but {} holds {}", names[i], dims[0],
                                                names[0], total_));
        Hid type(H5Dget_type(d), H5Tclose);
        const H5T_class_t cls = type.ok() ? H5Tget_class(type.get()) : H5T_NO_CLASS;
        const bool number = cls == H5T_INTEGER || cls == H5T_FLOAT || (i == 3 && cls == H5T_ENUM);
        if (!number) throw InputError(name_, fmt::format("dataset {} does not hold numbers", names[i]));
        if (i == 2) impl_->t_float = cls == H5T_FLOAT;
        if (i == 3 && cls == H5T_ENUM) {
            impl_->p_enum = true;
            impl_->p_size = H5Tget_size(type.get());
            if (impl_->p_size != 1 && impl_->p_size != 2 && impl_->p_size != 4)
                throw InputError(name_, fmt::format("dataset {}: unsupported enum size {}", names[i], impl_->p_size));
        }
        // A filter HDF5 cannot load (a missing plugin) fails every read: say so now.
        Hid dcpl(H5Dget_create_plist(d), H5Pclose);
        const int nf = dcpl.ok() ? H5Pget_nfilters(dcpl.get()) : 0;
        for (int k = 0; k < nf; ++k) {
            unsigned flags = 0;
            std::size_t nelem = 0;
            char fname[64] = {};
            const H5Z_filter_t id =
                quiet([&] { return H5Pget_filter2(dcpl.get(), static_cast<unsigned>(k), &flags, &nelem, nullptr,
                                                  sizeof fname, fname, nullptr); });
            if (id >= 0 && quiet([&] { return H5Zfilter_avail(id); }) <= 0)
                throw InputError(name_, fmt::format("dataset {} is compressed with {}, which HDF5 cannot load: "
                                                    "install {}",
                                                    names[i], id, filter_hint(id)));
        }
        // libhdf5 1.10 trusts a compact or contiguous dataset's size field and reads past
        // its buffer when the field is too small for the dataspace (found by fuzz_hdf5).
        const H5D_layout_t lay = dcpl.ok() ? H5Pget_layout(dcpl.get()) : H5D_LAYOUT_ERROR;
        if (lay == H5D_COMPACT || lay == H5D_CONTIGUOUS) {
            const hsize_t need = dims[0] * H5Tget_size(type.get());
            if (need / std::max<std::size_t>(H5Tget_size(type.get()), 1) != dims[0] ||
                quiet([&] { return H5Dget_storage_size(d); }) < need)
                throw InputError(name_, fmt::format("dataset {} stores fewer bytes than its {} values need (damaged)",
                                                    names[i], dims[0]));
        } else if (lay != H5D_CHUNKED) {
            throw InputError(name_, fmt::format("dataset {} has an unsupported storage layout", names[i]));
        }
        if (i == 0 && lay == H5D_CHUNKED) {
            hsize_t c = 0;
            if (H5Pget_chunk(dcpl.get(), 1, &c) == 1) impl_->chunk = c;
        }
    }
    // events/score (corner files written with scores): one number per event.
    if (layout_ == Layout::dsec && link_exists(f, "events/score")) {
        impl_->score = Hid(quiet([&] { return H5Dopen2(f, "events/score", H5P_DEFAULT); }), H5Dclose);
        Hid space(impl_->score.ok() ? H5Dget_space(impl_->score.get()) : H5I_INVALID_HID, H5Sclose);
        Hid type(impl_->score.ok() ? H5Dget_type(impl_->score.get()) : H5I_INVALID_HID, H5Tclose);
        hsize_t dims[2] = {0, 0};
        const H5T_class_t cls = type.ok() ? H5Tget_class(type.get()) : H5T_NO_CLASS;
        if (!space.ok() || quiet([&] { return H5Sget_simple_extent_ndims(space.get()); }) != 1 ||
            quiet([&] { return H5Sget_simple_extent_dims(space.get(), dims, nullptr); }) != 1 || dims[0] != total_ ||
            (cls != H5T_INTEGER && cls != H5T_FLOAT))
            throw InputError(name_, fmt::format("dataset events/score is not {} numbers, one per event", total_));
        has_score_ = true;
    }
    // t_offset (DSEC): a scalar integer dataset at the root.
    if (layout_ == Layout::dsec && link_exists(f, "t_offset")) {
        Hid d(quiet([&] { return H5Dopen2(f, "t_offset", H5P_DEFAULT); }), H5Dclose);
        Hid space(d.ok() ? H5Dget_space(d.get()) : H5I_INVALID_HID, H5Sclose);
        if (!space.ok() || quiet([&] { return H5Sget_simple_extent_npoints(space.get()); }) != 1 ||
            quiet([&] { return H5Dread(d.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, &t_offset_); }) < 0)
            throw InputError(name_, "t_offset is not a single integer");
    }
    // Sensor size: width / height, else sensor_resolution = (height, width).
    std::optional<SensorSize> from_file;
    const auto read_attr = [&](const char* name, int* values, hssize_t want_min, hssize_t want_max) -> hssize_t {
        if (quiet([&] { return H5Aexists(f, name); }) <= 0) return 0;
        Hid a(quiet([&] { return H5Aopen(f, name, H5P_DEFAULT); }), H5Aclose);
        Hid space(a.ok() ? H5Aget_space(a.get()) : H5I_INVALID_HID, H5Sclose);
        Hid type(a.ok() ? H5Aget_type(a.get()) : H5I_INVALID_HID, H5Tclose);
        if (!space.ok() || !type.ok() || H5Tget_class(type.get()) != H5T_INTEGER) return 0;
        const hssize_t n = quiet([&] { return H5Sget_simple_extent_npoints(space.get()); });
        if (n < want_min || n > want_max) return 0;
        if (quiet([&] { return H5Aread(a.get(), H5T_NATIVE_INT, values); }) < 0) return 0;
        return n;
    };
    int w = 0, h = 0, res[3] = {0, 0, 0};
    if (read_attr("width", &w, 1, 1) && read_attr("height", &h, 1, 1))
        from_file = SensorSize{w, h};
    else if (read_attr("sensor_resolution", res, 2, 3))
        from_file = SensorSize{res[1], res[0]};
    if (from_file && (from_file->width < 1 || from_file->height < 1 || from_file->width > kMaxSensorSide ||
                      from_file->height > kMaxSensorSide))
        throw InputError(name_, fmt::format("sensor size {}x{} in the file's attributes is out of range",
                                            from_file->width, from_file->height));
    sensor_ = options_.sensor ? options_.sensor : from_file ? from_file : options_.fallback_sensor;
    limit_w_ = static_cast<std::uint32_t>(sensor_ ? sensor_->width : kMaxSensorSide);
    limit_h_ = static_cast<std::uint32_t>(sensor_ ? sensor_->height : kMaxSensorSide);
}

Hdf5Reader::~Hdf5Reader() = default;

std::uint64_t Hdf5Reader::bytes_consumed() const noexcept {
    if (!file_size_ || total_ == 0) return 0;
    const double done = static_cast<double>(chunk_start_ + next_) / static_cast<double>(total_);
    return static_cast<std::uint64_t>(done * static_cast<double>(*file_size_));
}

void Hdf5Reader::fail_at(std::uint64_t index, int dataset, const std::string& reason) const {
    // The file address of the data holding event `index` of the dataset, where HDF5 knows it.
    const hid_t d = impl_->dset[dataset].get();
    haddr_t addr = HADDR_UNDEF;
    if (impl_->chunk > 0) {
        const hsize_t start = index / impl_->chunk * impl_->chunk;
        unsigned mask = 0;
        hsize_t size = 0;
        if (quiet([&] { return H5Dget_chunk_info_by_coord(d, &start, &mask, &addr, &size); }) < 0) addr = HADDR_UNDEF;
    } else {
        addr = quiet([&] { return H5Dget_offset(d); });
        if (addr != HADDR_UNDEF) {
            Hid type(H5Dget_type(d), H5Tclose);
            addr += index * (type.ok() ? H5Tget_size(type.get()) : 0);
        }
    }
    const std::string what = fmt::format("event {} ({}): {}", index, impl_->names[dataset], reason);
    if (addr == HADDR_UNDEF) throw InputError(name_, what);
    throw InputError(name_, InputError::Unit::byte, addr, what);
}

void Hdf5Reader::load_chunk() {
    chunk_start_ += chunk_n_;
    next_ = 0;
    chunk_n_ = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, total_ - chunk_start_));
    if (chunk_n_ == 0) return;
    x_.resize(kChunk);
    y_.resize(kChunk);
    p_.resize(kChunk);
    if (impl_->t_float) ts_.resize(kChunk);
    t_.resize(kChunk);
    const hsize_t start = chunk_start_, count = chunk_n_;
    Hid mem(H5Screate_simple(1, &count, nullptr), H5Sclose);
    for (int i = 0; i < 4; ++i) {
        const hid_t d = impl_->dset[i].get();
        Hid space(H5Dget_space(d), H5Sclose);
        if (!space.ok() || quiet([&] { return H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, &start, nullptr,
                                                                  &count, nullptr); }) < 0)
            fail_at(chunk_start_, i, "cannot select the events to read");
        herr_t r = -1;
        if (i == 0) r = quiet([&] { return H5Dread(d, H5T_NATIVE_INT32, mem.get(), space.get(), H5P_DEFAULT, x_.data()); });
        if (i == 1) r = quiet([&] { return H5Dread(d, H5T_NATIVE_INT32, mem.get(), space.get(), H5P_DEFAULT, y_.data()); });
        if (i == 2)
            r = impl_->t_float
                    ? quiet([&] { return H5Dread(d, H5T_NATIVE_DOUBLE, mem.get(), space.get(), H5P_DEFAULT, ts_.data()); })
                    : quiet([&] { return H5Dread(d, H5T_NATIVE_INT64, mem.get(), space.get(), H5P_DEFAULT, t_.data()); });
        if (i == 3) {
            if (impl_->p_enum) {
                impl_->p_raw.resize(kChunk * impl_->p_size);
                Hid ft(H5Dget_type(d), H5Tclose);
                Hid mt(ft.ok() ? H5Tget_native_type(ft.get(), H5T_DIR_ASCEND) : H5I_INVALID_HID, H5Tclose);
                if (mt.ok() && H5Tget_size(mt.get()) == impl_->p_size)
                    r = quiet([&] { return H5Dread(d, mt.get(), mem.get(), space.get(), H5P_DEFAULT, impl_->p_raw.data()); });
                for (std::size_t k = 0; r >= 0 && k < chunk_n_; ++k) {
                    const unsigned char* q = impl_->p_raw.data() + k * impl_->p_size;
                    if (impl_->p_size == 1) p_[k] = static_cast<std::int8_t>(q[0]);
                    if (impl_->p_size == 2) { std::int16_t v; std::memcpy(&v, q, 2); p_[k] = v; }
                    if (impl_->p_size == 4) std::memcpy(&p_[k], q, 4);
                }
            } else {
                r = quiet([&] { return H5Dread(d, H5T_NATIVE_INT32, mem.get(), space.get(), H5P_DEFAULT, p_.data()); });
            }
        }
        if (r < 0)
            fail_at(chunk_start_, i,
                    "HDF5 cannot read these events (damaged data, or a filter that fails): " + hdf5_reason(errno));
    }
    if (has_score_) {
        s_.resize(kChunk);
        Hid space(H5Dget_space(impl_->score.get()), H5Sclose);
        if (!space.ok() ||
            quiet([&] { return H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, &start, nullptr, &count, nullptr); }) < 0 ||
            quiet([&] { return H5Dread(impl_->score.get(), H5T_NATIVE_DOUBLE, mem.get(), space.get(), H5P_DEFAULT, s_.data()); }) < 0)
            throw InputError(name_, fmt::format("events/score: HDF5 cannot read the scores of events {} to {}: {}",
                                                chunk_start_, chunk_start_ + chunk_n_ - 1, hdf5_reason(errno)));
    }
    if (impl_->t_float) {
        for (std::size_t k = 0; k < chunk_n_; ++k) {
            const double us = ts_[k] * 1e6;
            if (!std::isfinite(us) || std::fabs(us) > 9.0e18)
                fail_at(chunk_start_ + k, 2, fmt::format("time {} s is not a finite time", ts_[k]));
            t_[k] = std::llround(us);
        }
    } else if (t_offset_ != 0) {
        for (std::size_t k = 0; k < chunk_n_; ++k) {
            if (__builtin_add_overflow(t_[k], t_offset_, &t_[k]))
                fail_at(chunk_start_ + k, 2, "t + t_offset overflows 64 bits");
        }
    }
}

std::size_t Hdf5Reader::read(std::span<Event> out) {
    skips_.new_batch();
    batch_n_ = 0;
    if (error_) std::rethrow_exception(error_);
    if (has_score_ && scores_.size() < out.size()) scores_.resize(out.size());
    std::size_t n = 0;
    try {
        while (n < out.size() && skips_.batch().size() < out.size()) {
            if (next_ == chunk_n_) {
                if (chunk_start_ + chunk_n_ >= total_) break;
                load_chunk();
                continue;
            }
            const std::size_t k = next_++;
            const auto x = static_cast<std::uint32_t>(x_[k]);  // negative: huge, outside
            const auto y = static_cast<std::uint32_t>(y_[k]);
            if (x >= limit_w_ || y >= limit_h_) [[unlikely]] {
                if (!options_.skip_invalid) fail_at(chunk_start_ + k, 0, outside_sensor_message(x_[k], y_[k], sensor_, options_.keyword_spelling));
                skips_.skip(n);
                continue;
            }
            if (t_[k] < last_t_) [[unlikely]]
                fail_at(chunk_start_ + k, 2, backwards_message(last_t_, t_[k]));
            last_t_ = t_[k];
            if (has_score_) scores_[n] = s_[k];
            out[n++] = Event{t_[k], static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                             static_cast<std::uint8_t>(p_[k] > 0)};
        }
    } catch (const InputError&) {
        error_ = std::current_exception();
        if (n == 0 && skips_.batch().empty()) throw;
    }
    batch_n_ = n;
    return n;
}

// ---------------------------------------------------------------- writer

struct Hdf5Writer::Impl {
    // Declared first, destroyed last: the HDF5 file is closed before an unfinished
    // temporary file is removed.
    std::optional<PendingFile> pending;
    Hid file, group;
    Hid dset[5];  // x, y, t, p, score (with_score)

    // Gives up the file (a failed write, or no close()): its content no longer matters.
    // libhdf5 1.10 cannot close a file whose writes fail: H5Fclose fails, the file stays
    // open, and the library's own clean-up at exit then crashes (or prints "infinite loop
    // closing library"). So the file's descriptor is first pointed at /dev/null, where
    // every write succeeds, and then everything is closed; the temporary file is removed
    // afterwards by `pending`.
    void abandon() noexcept {
        if (file.ok()) {
            void* handle = nullptr;
            if (quiet([&] { return H5Fget_vfd_handle(file.get(), H5P_DEFAULT, &handle); }) >= 0 && handle) {
                const int fd = *static_cast<int*>(handle);
                const int null = ::open("/dev/null", O_RDWR | O_CLOEXEC);
                if (null >= 0) {
                    ::dup2(null, fd);
                    ::close(null);
                }
            }
        }
        for (auto& d : dset) d = Hid();
        group = Hid();
        file = Hid();
    }
    ~Impl() { abandon(); }
};

bool Hdf5Writer::filter_available(int id) {
    load_for<Hdf5Api, OutputError>("HDF5 output");
    return quiet([&] { return H5Zfilter_avail(static_cast<H5Z_filter_t>(id)); }) > 0;
}

Hdf5Writer::Hdf5Writer(std::string path, Options options)
    : impl_(std::make_unique<Impl>()), name_(path == "-" ? "<stdout>" : path), options_(options) {
    load_for<Hdf5Api, OutputError>(name_);
    if (path == "-") throw OutputError(name_, "HDF5 files cannot go to standard output");
    if (options_.chunk_events == 0) options_.chunk_events = std::size_t{1} << 14;
    // HDF5 writes a temporary file in the target's folder (pending_file.hpp), renamed by close().
    impl_->pending.emplace(path);
    if (impl_->pending->direct())
        throw OutputError(name_, "an HDF5 file must be a regular file (HDF5 seeks back to complete it); "
                                 "this path is a device, FIFO or socket");
    impl_->pending->close_fd();  // HDF5 opens the file by name
    impl_->file = Hid(quiet([&] {
                          return H5Fcreate(impl_->pending->write_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
                      }),
                      H5Fclose);
    if (!impl_->file.ok()) throw OutputError(name_, "HDF5 cannot create the file: " + hdf5_reason(errno));
    impl_->group = Hid(quiet([&] { return H5Gcreate2(impl_->file.get(), "events", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT); }),
                       H5Gclose);
    if (!impl_->group.ok()) throw OutputError(name_, "HDF5 cannot create the events group: " + hdf5_reason(errno));
    const hsize_t zero = 0, unlimited = H5S_UNLIMITED, chunk = options_.chunk_events;
    Hid space(H5Screate_simple(1, &zero, &unlimited), H5Sclose);
    Hid dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    H5Pset_chunk(dcpl.get(), 1, &chunk);
    if (options_.filter == 1) {
        H5Pset_deflate(dcpl.get(), 4);
    } else if (options_.filter != 0) {
        if (!filter_available(options_.filter))
            throw OutputError(name_, fmt::format("HDF5 cannot load {}", filter_hint(static_cast<H5Z_filter_t>(options_.filter))));
        // Blosc: values 0..3 are filled in by the filter; level 5, byte shuffle, ZSTD (5).
        const unsigned cd[7] = {0, 0, 0, 0, 5, 1, 5};
        if (quiet([&] { return H5Pset_filter(dcpl.get(), static_cast<H5Z_filter_t>(options_.filter), H5Z_FLAG_MANDATORY,
                                              options_.filter == 32001 ? 7 : 0, cd); }) < 0)
            throw OutputError(name_, fmt::format("HDF5 cannot set filter {}: {}", options_.filter, hdf5_reason()));
    }
    const char* names[5] = {"x", "y", "t", "p", "score"};
    const hid_t types[5] = {H5T_STD_U16LE, H5T_STD_U16LE, H5T_STD_I64LE, H5T_STD_U8LE, H5T_IEEE_F64LE};
    for (int i = 0; i < (options_.with_score ? 5 : 4); ++i) {
        impl_->dset[i] = Hid(quiet([&] { return H5Dcreate2(impl_->group.get(), names[i], types[i], space.get(), H5P_DEFAULT,
                                                           dcpl.get(), H5P_DEFAULT); }),
                             H5Dclose);
        if (!impl_->dset[i].ok())
            throw OutputError(name_, fmt::format("HDF5 cannot create events/{}: {}", names[i], hdf5_reason(errno)));
    }
    x_.reserve(options_.chunk_events);
    y_.reserve(options_.chunk_events);
    p_.reserve(options_.chunk_events);
    t_.reserve(options_.chunk_events);
    if (options_.with_score) s_.reserve(options_.chunk_events);
}

// Without close(): the HDF5 objects close (Impl::abandon), then the temporary file is removed.
Hdf5Writer::~Hdf5Writer() = default;

void Hdf5Writer::set_sensor(SensorSize size) {
    if (closed_) throw OutputError(name_, "set_sensor after close");
    options_.sensor = size;
}

void Hdf5Writer::write(std::span<const Event> events) {
    if (options_.with_score) throw std::logic_error("Hdf5Writer: opened with scores, written without");
    write_events(events, {});
}

void Hdf5Writer::write(std::span<const Event> events, std::span<const double> scores) {
    if (!options_.with_score || scores.size() != events.size())
        throw std::logic_error("Hdf5Writer: scores on a writer opened without, or not one per event");
    write_events(events, scores);
}

void Hdf5Writer::write_events(std::span<const Event> events, std::span<const double> scores) {
    if (closed_) throw OutputError(name_, "write after close");
    for (std::size_t i = 0; i < events.size(); ++i) {
        const Event& e = events[i];
        if (!t_offset_) t_offset_ = e.t;
        x_.push_back(e.x);
        y_.push_back(e.y);
        p_.push_back(e.p != 0);
        t_.push_back(e.t - *t_offset_);
        if (!scores.empty()) s_.push_back(scores[i]);
        if (x_.size() == options_.chunk_events) flush();
    }
}

void Hdf5Writer::flush() {
    if (x_.empty()) return;
    const hsize_t start = written_, count = x_.size(), size = written_ + x_.size();
    Hid mem(H5Screate_simple(1, &count, nullptr), H5Sclose);
    const void* bufs[5] = {x_.data(), y_.data(), t_.data(), p_.data(), s_.data()};
    const hid_t mtypes[5] = {H5T_NATIVE_UINT16, H5T_NATIVE_UINT16, H5T_NATIVE_INT64, H5T_NATIVE_UINT8, H5T_NATIVE_DOUBLE};
    for (int i = 0; i < (options_.with_score ? 5 : 4); ++i) {
        const hid_t d = impl_->dset[i].get();
        if (quiet([&] { return H5Dset_extent(d, &size); }) < 0)
            throw OutputError(name_, "HDF5 cannot extend a dataset: " + hdf5_reason(errno));
        Hid space(H5Dget_space(d), H5Sclose);
        if (quiet([&] { return H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, &start, nullptr, &count, nullptr); }) < 0 ||
            quiet([&] { return H5Dwrite(d, mtypes[i], mem.get(), space.get(), H5P_DEFAULT, bufs[i]); }) < 0)
            throw OutputError(name_, "write failed: " + hdf5_reason(errno));
    }
    written_ += x_.size();
    x_.clear();
    y_.clear();
    p_.clear();
    t_.clear();
    s_.clear();
}

void Hdf5Writer::close() {
    if (closed_) return;
    flush();
    const hid_t f = impl_->file.get();
    {
        Hid scalar(H5Screate(H5S_SCALAR), H5Sclose);
        const std::int64_t off = t_offset_.value_or(0);
        Hid d(quiet([&] { return H5Dcreate2(f, "t_offset", H5T_STD_I64LE, scalar.get(), H5P_DEFAULT, H5P_DEFAULT,
                                            H5P_DEFAULT); }),
              H5Dclose);
        if (!d.ok() || quiet([&] { return H5Dwrite(d.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, &off); }) < 0)
            throw OutputError(name_, "HDF5 cannot write t_offset: " + hdf5_reason(errno));
        if (options_.sensor) {
            const int wh[2] = {options_.sensor->width, options_.sensor->height};
            const char* names[2] = {"width", "height"};
            for (int i = 0; i < 2; ++i) {
                Hid a(quiet([&] { return H5Acreate2(f, names[i], H5T_STD_I32LE, scalar.get(), H5P_DEFAULT, H5P_DEFAULT); }),
                      H5Aclose);
                if (!a.ok() || quiet([&] { return H5Awrite(a.get(), H5T_NATIVE_INT, &wh[i]); }) < 0)
                    throw OutputError(name_, "HDF5 cannot write the sensor size: " + hdf5_reason(errno));
            }
        }
    }
    // Everything to the file while the file is sound: a write that fails here leaves it
    // open and sound for Impl::abandon(), whereas a failed H5Fclose leaves HDF5 with a file
    // it can neither close nor give up.
    if (quiet([&] { return H5Fflush(f, H5F_SCOPE_LOCAL); }) < 0)
        throw OutputError(name_, "write failed: " + hdf5_reason(errno));
    for (auto& ds : impl_->dset) ds = Hid();
    impl_->group = Hid();
    if (quiet([&] { return H5Fclose(f); }) < 0) {
        const std::string why = hdf5_reason(errno);
        impl_->file.release();  // not to be touched again
        throw OutputError(name_, "write failed (completing the HDF5 file): " + why);
    }
    impl_->file.release();
    impl_->pending->commit();
    closed_ = true;
}

}  // namespace evcorner::io
