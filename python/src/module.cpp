// evcorner._evcorner: the C++ library seen from Python (pybind11). A thin front: every
// verb here calls the library (registry.hpp, pipeline/detect.hpp, io/, eval/, sim/); the
// pure-Python parts (python/evcorner/*.py) add keyword parsing, foreign dtypes and Dask.
//
// Events cross the border as numpy structured arrays of EVENT_DTYPE, read in place: an
// array whose dtype, shape, stride or alignment is not exactly that of evcorner::Event is
// refused with an exception, never copied.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <iterator>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "evcorner/error.hpp"
#include "evcorner/eval/feature_tracks.hpp"
#include "evcorner/eval/metrics.hpp"
#include "evcorner/eval/truth_match.hpp"
#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/event_checks.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/formats.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/parallel_detect.hpp"
#include "evcorner/pipeline/detect.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/scored_detector.hpp"
#include "evcorner/sim/scene.hpp"
#include "evcorner/sim/simulator.hpp"
#include "evcorner/sim/truth.hpp"
#include "evcorner/state_memory.hpp"

namespace py = pybind11;
using namespace evcorner;

// EVENT_DTYPE is built from these: numpy reads the C++ struct where it lies.
static_assert(offsetof(Event, t) == 0 && sizeof(Event::t) == 8);
static_assert(offsetof(Event, x) == 8 && sizeof(Event::x) == 2);
static_assert(offsetof(Event, y) == 10 && sizeof(Event::y) == 2);
static_assert(offsetof(Event, p) == 12 && sizeof(Event::p) == 1);
static_assert(sizeof(Event) == 16 && alignof(Event) == 8);

namespace {

const py::dtype& event_dtype() {
    // An aligned struct (align=True): its natural layout is exactly Event's, and numpy keeps
    // it through concatenate() and friends (a packed dtype would lose the padding: 13 bytes).
    // Leaked on purpose: destroyed after the interpreter would be too late.
    static const py::dtype* d = [] {
        py::dict spec;
        spec["names"] = py::make_tuple("t", "x", "y", "p");
        spec["formats"] = py::make_tuple("<i8", "<u2", "<u2", "u1");
        spec["offsets"] = py::make_tuple(offsetof(Event, t), offsetof(Event, x), offsetof(Event, y), offsetof(Event, p));
        spec["itemsize"] = sizeof(Event);
        return new py::dtype(py::module_::import("numpy").attr("dtype")(spec, py::arg("align") = true));
    }();
    return *d;
}

std::string text_of(py::handle h) { return std::string(py::str(h)); }

std::string type_name(py::handle h) { return py::str(py::type::handle_of(h).attr("__name__")); }

/// Whether a dtype lays its events out exactly as evcorner::Event: 16 bytes, t <i8 at 0,
/// x <u2 at 8, y <u2 at 10, p u1 at 12, and any other fields inside the padding (bytes
/// 13..15). EVENT_DTYPE is one; the .npy files evcorner writes (t, x, y, p, '_' V3) are
/// another, so that np.load() of them, memory-mapped or not, is read in place.
bool has_event_layout(const py::dtype& dt) {
    if (dt.ptr() == event_dtype().ptr()) return true;
    // The last dtype found to have the layout: np.load() makes a new dtype object per file,
    // and a chunked loop passes views of one array again and again. (The GIL guards it.)
    static PyObject* last_accepted = nullptr;
    if (dt.ptr() == last_accepted) return true;
    if (dt.itemsize() != static_cast<py::ssize_t>(sizeof(Event))) return false;
    const py::object fields = dt.attr("fields");
    if (fields.is_none()) return false;
    const py::dict f(fields);  // (a mappingproxy, copied into a dict)
    struct Want {
        const char* name;
        py::dtype type;  // native (little-endian) order, as Event's
        std::size_t offset;
    };
    const Want wants[] = {{"t", py::dtype::of<std::int64_t>(), offsetof(Event, t)},
                          {"x", py::dtype::of<std::uint16_t>(), offsetof(Event, x)},
                          {"y", py::dtype::of<std::uint16_t>(), offsetof(Event, y)},
                          {"p", py::dtype::of<std::uint8_t>(), offsetof(Event, p)}};
    std::size_t found = 0;
    for (const auto& [name, spec] : f) {
        // fields maps each name (and each title) to (dtype, offset[, title]).
        const auto entry = py::reinterpret_borrow<py::tuple>(spec);
        const auto field_type = entry[0].cast<py::dtype>();
        const auto offset = entry[1].cast<std::size_t>();
        const std::string n = py::str(name);
        const Want* want = nullptr;
        for (const Want& w : wants)
            if (n == w.name) want = &w;
        if (want != nullptr) {
            if (offset != want->offset) return false;
            if (PyObject_RichCompareBool(field_type.ptr(), want->type.ptr(), Py_EQ) != 1) return false;
            ++found;
        } else if (offset < offsetof(Event, p) + sizeof(Event::p) ||
                   offset + static_cast<std::size_t>(field_type.itemsize()) > sizeof(Event) ||
                   field_type.attr("hasobject").cast<bool>()) {
            return false;  // a field that overlaps an event field or is not plain bytes
        }
    }
    if (found != std::size(wants)) return false;
    Py_XDECREF(last_accepted);
    last_accepted = dt.ptr();
    Py_INCREF(last_accepted);
    return true;
}

/// The events of `obj` in place, or an exception saying why not.
std::span<const Event> events_view(py::handle obj, const char* what = "events") {
    if (!py::isinstance<py::array>(obj))
        throw py::type_error(std::string(what) + ": expected a numpy array of evcorner.EVENT_DTYPE, got " +
                             type_name(obj));
    const auto a = py::reinterpret_borrow<py::array>(obj);
    const py::dtype dt = a.dtype();
    if (!has_event_layout(dt))
        throw py::type_error(std::string(what) + ": dtype " + text_of(dt) + " is not evcorner.EVENT_DTYPE " +
                             text_of(event_dtype()) +
                             " (nor another with its layout, such as that of evcorner's .npy files); convert it "
                             "with evcorner.as_events(array) (one copy)");
    if (a.ndim() != 1)
        throw py::value_error(std::string(what) + ": expected a 1-D array, got " + std::to_string(a.ndim()) +
                              " dimensions");
    const auto n = static_cast<std::size_t>(a.shape(0));
    if (n > 1 && a.strides(0) != static_cast<py::ssize_t>(sizeof(Event)))
        throw py::value_error(std::string(what) + ": the array is strided (" + std::to_string(a.strides(0)) +
                              " bytes between events, 16 expected); evcorner reads arrays in place and does not "
                              "copy silently: pass numpy.ascontiguousarray(events)");
    if (reinterpret_cast<std::uintptr_t>(a.data()) % alignof(Event) != 0)
        throw py::value_error(std::string(what) + ": the array's data is not 8-byte aligned; pass numpy.copy(events)");
    return {static_cast<const Event*>(a.data()), n};
}

/// A 1-D contiguous writable array of T with at least n elements (returned as its first n),
/// or a new one when `out` is None.
template <class T>
py::array_t<T> output_array(py::handle out, std::size_t n, const char* what) {
    if (out.is_none()) return py::array_t<T>(static_cast<py::ssize_t>(n));
    if (!py::isinstance<py::array>(out))
        throw py::type_error(std::string(what) + ": expected a numpy array, got " + type_name(out));
    auto a = py::reinterpret_borrow<py::array>(out);
    const py::dtype want = py::dtype::of<T>();
    if (PyObject_RichCompareBool(a.dtype().ptr(), want.ptr(), Py_EQ) != 1)
        throw py::type_error(std::string(what) + ": dtype " + text_of(a.dtype()) + " is not " +
                             text_of(want));
    if (a.ndim() != 1 || (a.shape(0) > 1 && a.strides(0) != static_cast<py::ssize_t>(sizeof(T))))
        throw py::value_error(std::string(what) + ": expected a 1-D contiguous array");
    if (!a.writeable()) throw py::value_error(std::string(what) + ": the array is read-only");
    if (static_cast<std::size_t>(a.shape(0)) < n)
        throw py::value_error(std::string(what) + ": " + std::to_string(a.shape(0)) + " elements for " +
                              std::to_string(n) + " events");
    if (static_cast<std::size_t>(a.shape(0)) == n) return py::reinterpret_borrow<py::array_t<T>>(out);
    return py::reinterpret_steal<py::array_t<T>>(
        PySequence_GetSlice(out.ptr(), 0, static_cast<Py_ssize_t>(n)));
}

/// A list of format names ("a, b, c") as a tuple of names.
py::tuple format_names(std::string_view list) {
    py::list names;
    while (!list.empty()) {
        const std::size_t comma = list.find(',');
        std::string_view name = list.substr(0, comma);
        while (!name.empty() && name.front() == ' ') name.remove_prefix(1);
        while (!name.empty() && name.back() == ' ') name.remove_suffix(1);
        if (!name.empty()) names.append(py::str(std::string(name)));
        list = comma == std::string_view::npos ? std::string_view{} : list.substr(comma + 1);
    }
    return py::tuple(names);
}

/// Hands a vector of events to numpy without copying it.
py::array to_array(std::vector<Event>&& v) {
    auto* owner = new std::vector<Event>(std::move(v));
    py::capsule free_when_done(owner, [](void* p) { delete static_cast<std::vector<Event>*>(p); });
    return py::array(event_dtype(), {static_cast<py::ssize_t>(owner->size())},
                     {static_cast<py::ssize_t>(sizeof(Event))}, owner->data(), free_when_done);
}

/// Keyword arguments (harris_window=11) as registry values ("harris-window" = 11).
ParamValues params_from(const py::dict& kw) {
    ParamValues values;
    for (const auto& [k, v] : kw) {
        const std::string id = py::str(k);
        const std::string tname = type_name(v);
        if (tname == "bool" || tname == "bool_")
            values.set(param_key(id), v.cast<bool>());
        else if (PyFloat_Check(v.ptr()) || tname.rfind("float", 0) == 0)
            values.set(param_key(id), v.cast<double>());
        else if (PyIndex_Check(v.ptr()))
            values.set(param_key(id), v.cast<std::int64_t>());
        else
            throw py::type_error(id + ": expected an int, float or bool, got " + tname);
    }
    return values;
}

/// (width, height), or None.
py::object size_or_none(const std::optional<SensorSize>& s) {
    if (!s) return py::none();
    return py::make_tuple(s->width, s->height);
}

/// A ReaderOptions size field as a Python property: (width, height) or None.
template <auto Member>
void def_size_property(py::class_<io::ReaderOptions>& c, const char* name) {
    c.def_property(
        name, [](const io::ReaderOptions& o) { return size_or_none(o.*Member); },
        [](io::ReaderOptions& o, std::optional<std::pair<int, int>> s) {
            o.*Member = s ? std::optional(SensorSize{s->first, s->second}) : std::nullopt;
        });
}

SensorSize sensor_of(int width, int height) { return SensorSize{width, height}; }

/// An event that comes before the one it follows (raised as evcorner.InvalidEvent).
class EventsOutOfOrder : public std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

/// The array changed while a call was reading it (raised as RuntimeError).
class EventsChanged : public std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Index of the first event of `ev` whose time is below the one before it (`prev` before
/// the first), or ev.size(). Blocks are tested without a branch per event.
std::size_t first_backwards(std::span<const Event> ev, std::int64_t prev) noexcept {
    if (ev.empty()) return 0;
    if (ev[0].t < prev) return 0;
    constexpr std::size_t kStep = 64;
    for (std::size_t at = 1; at < ev.size(); at += kStep) {
        const std::size_t end = std::min(ev.size(), at + kStep);
        bool back = false;
        for (std::size_t i = at; i < end; ++i) back |= ev[i].t < ev[i - 1].t;  // independent: pipelined
        if (back) [[unlikely]]
            for (std::size_t i = at; i < end; ++i)
                if (ev[i].t < ev[i - 1].t) return i;
    }
    return ev.size();
}

std::string describe_event(const Event& e, std::size_t index) {
    return "event " + std::to_string(index) + " (t=" + std::to_string(e.t) + " x=" + std::to_string(e.x) +
           " y=" + std::to_string(e.y) + " p=" + std::to_string(e.p) + ")";
}

/// One registered detector, stateful across calls.
///
/// A call checks every event of the array in place (on the sensor, polarity, time order,
/// also against the last event of the previous call) and raises before touching the state
/// when one is bad. The detector then reads only private copies of the array, a block at
/// a time, each checked again once copied: another thread writing to the array while the
/// GIL is released can make the result meaningless (EventsChanged when it breaks a check)
/// but never lets the detector read an event it cannot take.
class PyDetector {
public:
    /// Events per private block: small enough to stay in the L1/L2 cache between the copy,
    /// its check and the detector's pass.
    static constexpr std::size_t kBlock = 2048;

    PyDetector(std::string name, int width, int height, const py::dict& params)
        : config_{std::move(name), params_from(params)},
          size_(sensor_of(width, height)),
          det_(make_detector(config_, size_, kIdentifierKeys)) {}

    /// A copy of `o` with its state: it goes on from where `o` is.
    PyDetector(const PyDetector& o) : PyDetector(o, std::lock_guard(o.mutex_)) {}
    PyDetector& operator=(const PyDetector&) = delete;

    py::object process(py::handle events, py::handle out) {
        const std::span<const Event> ev = events_view(events);
        py::array_t<std::uint8_t> mask = output_array<std::uint8_t>(out, ev.size(), "out");
        const std::span<std::uint8_t> flags(mask.mutable_data(), ev.size());
        {
            py::gil_scoped_release release;
            const std::lock_guard lock(mutex_);
            std::visit(
                [&](auto& d) {
                    run(d, ev, [&](std::span<const Event> block, std::size_t at, const TimeSpan& span) {
                        return evcorner::detail::run_batch(d, block, flags.subspan(at, block.size()), span);
                    });
                },
                det_);
        }
        return mask;
    }

    py::tuple process_scored(py::handle events, py::handle out, py::handle scores_out) {
        if (!has_score(det_))
            throw py::type_error("detector '" + config_.name + "' has no score (see evcorner.detectors())");
        const std::span<const Event> ev = events_view(events);
        py::array_t<std::uint8_t> mask = output_array<std::uint8_t>(out, ev.size(), "out");
        py::array_t<double> scores = output_array<double>(scores_out, ev.size(), "scores");
        const std::span<std::uint8_t> flags(mask.mutable_data(), ev.size());
        const std::span<double> sc(scores.mutable_data(), ev.size());
        {
            py::gil_scoped_release release;
            const std::lock_guard lock(mutex_);
            std::visit(
                [&](auto& d) {
                    if constexpr (ScoredDetector<std::remove_cvref_t<decltype(d)>>)
                        run(d, ev, [&](std::span<const Event> block, std::size_t at, const TimeSpan&) {
                            return detect_unchecked(d, block, flags.subspan(at, block.size()),
                                                    sc.subspan(at, block.size()));
                        });
                },
                det_);  // (a detector without a score was refused above)
        }
        return py::make_tuple(std::move(mask), std::move(scores));
    }

    void reset() {
        const std::lock_guard lock(mutex_);
        det_ = make_detector(config_, size_, kIdentifierKeys);
        events_ = corners_ = 0;
        last_address_ = 0;
        last_t_.reset();
    }

    [[nodiscard]] std::string name() const { return config_.name; }
    [[nodiscard]] py::tuple sensor() const { return py::make_tuple(size_.width, size_.height); }
    [[nodiscard]] bool scored() const { return has_score(det_); }
    [[nodiscard]] std::size_t memory() const { return memory_bytes(det_); }
    [[nodiscard]] py::object last_time() const { return last_t_ ? py::object(py::int_(*last_t_)) : py::none(); }
    [[nodiscard]] py::dict params() const {
        py::dict d;
        for (const auto& [key, value] : config_.params) {
            std::string id = key;
            std::replace(id.begin(), id.end(), '-', '_');
            std::visit([&](auto v) { d[py::str(id)] = v; }, value);
        }
        return d;
    }
    std::uint64_t events_ = 0, corners_ = 0;
    std::uintptr_t last_address_ = 0;  ///< where the last call read its events (the zero-copy test)

private:
    PyDetector(const PyDetector& o, const std::lock_guard<std::mutex>&)
        : events_(o.events_),
          corners_(o.corners_),
          last_address_(o.last_address_),
          config_(o.config_),
          size_(o.size_),
          det_(o.det_),
          last_t_(o.last_t_) {}

    /// Checks `ev` in place, then runs `step(block, at, span)` on checked private copies of
    /// its blocks (block = the copy of ev[at, at + block.size())).
    template <class D, class Step>
    void run(D& det, std::span<const Event> ev, Step&& step) {
        const EventLimits limits = det.limits();
        const std::int64_t before = last_t_.value_or(std::numeric_limits<std::int64_t>::min());
        // Both checks a block at a time, so that the second reads the block from the cache.
        for (std::size_t at = 0; at < ev.size(); at += kBlock) {
            const std::span<const Event> part = ev.subspan(at, std::min(kBlock, ev.size() - at));
            TimeSpan span;
            const std::size_t bad = first_invalid_event(part, limits, span);
            const std::size_t back = first_backwards(part.first(bad), at == 0 ? before : ev[at - 1].t);
            if (back < bad) throw_backwards(ev, at + back);
            if (bad != part.size()) throw InvalidEvent(part[bad], limits, at + bad);
        }
        last_address_ = reinterpret_cast<std::uintptr_t>(ev.data());
        if (block_.size() < std::min(ev.size(), kBlock)) block_.resize(kBlock);
        for (std::size_t at = 0; at < ev.size(); at += kBlock) {
            const std::size_t n = std::min(kBlock, ev.size() - at);
            const std::span<Event> copy(block_.data(), n);
            std::memcpy(copy.data(), ev.data() + at, n * sizeof(Event));
            if (at + n < ev.size()) {
                // The next block on its way to the L2 cache while the detector runs on this one.
                const char* next = reinterpret_cast<const char*>(ev.data() + at + n);
                const std::size_t bytes = std::min(kBlock, ev.size() - at - n) * sizeof(Event);
                for (std::size_t b = 0; b < bytes; b += 64) __builtin_prefetch(next + b, 0, 2);
            }
            TimeSpan span;
            const std::size_t bad = first_invalid_event(copy, limits, span);
            const std::size_t back = first_backwards(copy.first(bad), last_t_.value_or(before));
            if (bad != n || back != n) [[unlikely]]
                throw EventsChanged("events: " + describe_event(copy[std::min(bad, back)], at + std::min(bad, back)) +
                                    " changed after the call checked it (another thread wrote to the array); the " +
                                    std::to_string(at) + " events before its block were processed");
            corners_ += step(std::span<const Event>(copy), at, span);
            events_ += n;
            last_t_ = copy[n - 1].t;
        }
    }

    [[noreturn]] void throw_backwards(std::span<const Event> ev, std::size_t i) const {
        const std::int64_t previous = i > 0 ? ev[i - 1].t : *last_t_;
        std::string m = "events: " + describe_event(ev[i], i) + ": " + io::backwards_message(previous, ev[i].t);
        if (i == 0)
            m += "; the previous event is the last one of the detector's previous call (event " +
                 std::to_string(events_ - 1) + " of its stream; reset() starts a new stream)";
        throw EventsOutOfOrder(m);
    }

    DetectorConfig config_;
    SensorSize size_;
    AnyDetector det_;
    std::optional<std::int64_t> last_t_;  ///< the time of the last event taken, if any
    std::vector<Event> block_;            ///< the private copy the detector reads
    mutable std::mutex mutex_;
};

/// An open event file, read in chunks (by count or up to a time) in constant memory.
///
/// Damaged input (an InputError from the reader) never costs the events before it: a call
/// that has gathered events when the error comes returns them, and the error is raised by
/// the next call (and every one after). With allow_damaged, the error ends the input
/// instead; damaged() then says what it was. One call reads at a time (a lock, taken with
/// the GIL released): threads sharing a reader get its events in turn, each event once.
class PyReader {
    // f() under the lock, taken with the GIL released (a reading thread holds the lock
    // without the GIL).
    template <class F>
    auto locked(F&& f) {
        py::gil_scoped_release release;
        const std::lock_guard lock(mutex_);
        return f();
    }

public:
    PyReader(const std::string& path, const io::ReaderOptions& options, const std::string& format,
             bool allow_damaged)
        : reader_(io::open_event_reader(path, options, format)),
          buf_(std::size_t{1} << 16),
          allow_damaged_(allow_damaged) {}

    py::array read_count(std::size_t n) {
        std::vector<Event> out;
        {
            py::gil_scoped_release release;
            const std::lock_guard lock(mutex_);
            out.reserve(std::min<std::size_t>(n, std::size_t{1} << 20));
            while (out.size() < n && next(!out.empty())) {
                const std::size_t take = std::min(n - out.size(), len_ - pos_);
                out.insert(out.end(), buf_.begin() + pos_, buf_.begin() + pos_ + take);
                pos_ += take;
            }
        }
        return to_array(std::move(out));
    }

    /// The events before the first one at or after t_end (file order).
    py::array read_until(std::int64_t t_end) {
        std::vector<Event> out;
        {
            py::gil_scoped_release release;
            const std::lock_guard lock(mutex_);
            while (next(!out.empty())) {
                std::size_t end = pos_;
                while (end < len_ && buf_[end].t < t_end) ++end;
                out.insert(out.end(), buf_.begin() + pos_, buf_.begin() + end);
                pos_ = end;
                if (end < len_) break;
            }
        }
        return to_array(std::move(out));
    }

    /// The time of the next event, or None at the end.
    py::object peek_time() {
        std::optional<std::int64_t> t;
        {
            py::gil_scoped_release release;
            const std::lock_guard lock(mutex_);
            if (next(false)) t = buf_[pos_].t;
        }
        if (!t) return py::none();
        return py::int_(*t);
    }

    [[nodiscard]] py::object sensor() { return size_or_none(locked([&] { return reader_->sensor(); })); }
    [[nodiscard]] std::string format() { return locked([&] { return std::string(reader_->format()); }); }
    [[nodiscard]] std::string name() { return locked([&] { return reader_->name(); }); }
    [[nodiscard]] std::uint64_t skipped() { return locked([&] { return reader_->skipped(); }); }
    [[nodiscard]] std::uint64_t bytes_consumed() { return locked([&] { return reader_->bytes_consumed(); }); }
    [[nodiscard]] std::optional<std::uint64_t> bytes_total() { return locked([&] { return reader_->bytes_total(); }); }
    /// The error that ended the input (allow_damaged), or None.
    [[nodiscard]] py::object damaged() {
        const std::string d = locked([&] { return damaged_; });
        return d.empty() ? py::object(py::none()) : py::str(d);
    }

private:
    // fill(), with the rule for damaged input: false at the end; an error is raised now only
    // when the caller holds no events (`holding` false), else kept for the next call.
    bool next(bool holding) {
        if (pending_) {
            if (holding) return false;
            std::rethrow_exception(pending_);
        }
        try {
            return fill();
        } catch (const InputError& e) {
            if (allow_damaged_) {
                damaged_ = e.what();
                done_ = true;
                pos_ = len_ = 0;
                return false;
            }
            pending_ = std::current_exception();
            if (holding) return false;
            throw;
        }
    }

    // Makes buf_[pos_] the next event; false at the end.
    bool fill() {
        while (pos_ == len_ && !done_) {
            len_ = reader_->read(buf_);
            pos_ = 0;
            if (len_ == 0 && reader_->skipped_in_batch().empty()) done_ = true;
        }
        return pos_ < len_;
    }

    std::unique_ptr<io::EventReader> reader_;
    std::vector<Event> buf_;
    std::size_t pos_ = 0, len_ = 0;
    bool done_ = false;
    bool allow_damaged_ = false;
    std::exception_ptr pending_;  ///< the input error the next call raises
    std::string damaged_;
    std::mutex mutex_;
};

/// Throws InvalidEvent (naming its index) for the first event off `sensor` or with a
/// polarity other than 0/1: what a writer recording that sensor must refuse.
void check_on_sensor(std::span<const Event> ev, std::pair<int, int> sensor) {
    if (sensor.first < 1 || sensor.second < 1 || sensor.first > 65536 || sensor.second > 65536)
        throw py::value_error("sensor: " + std::to_string(sensor.first) + "x" + std::to_string(sensor.second) +
                              " is not a size of 1..65536 x 1..65536");
    check_events(ev, EventLimits{SensorSize{sensor.first, sensor.second}});
}

void write_events(const std::string& path, py::handle events, const std::string& format,
                  std::optional<std::pair<int, int>> sensor) {
    const std::span<const Event> ev = events_view(events);
    py::gil_scoped_release release;
    std::optional<SensorSize> size;
    if (sensor) {
        check_on_sensor(ev, *sensor);  // before the file is created
        size = SensorSize{sensor->first, sensor->second};
    }
    auto writer = io::open_event_writer(path, format, size);
    writer->write(ev);
    writer->close();
}

py::dict summary_dict(const pipeline::DetectSummary& s, const std::string& input, const py::dict& params) {
    py::dict d;
    d["input"] = input;
    d["detector"] = s.detector;
    d["width"] = s.sensor.width;
    d["height"] = s.sensor.height;
    d["events"] = s.events;
    d["corners"] = s.corners;
    d["skipped"] = s.skipped;
    d["reduction_rate"] = s.events ? py::object(py::float_(s.reduction_percent())) : py::object(py::none());
    d["ns_per_event"] = s.events ? py::object(py::float_(s.ns_per_event())) : py::object(py::none());
    d["threads"] = s.threads;
    d["detect_s"] = s.detect_s;
    d["wall_s"] = s.wall_s;
    d["damaged"] = s.damaged.empty() ? py::object(py::none()) : py::object(py::str(s.damaged));
    d["params"] = params;
    return d;
}

py::dict detect_file_py(const std::string& input, const std::string& output, const std::string& detector,
                        const py::dict& params, const io::ReaderOptions& reader, const std::string& format,
                        const std::string& to, const std::string& mask, bool with_score, int threads,
                        bool allow_damaged) {
    pipeline::DetectFiles files;
    files.input = input;
    files.format = format;
    files.reader = reader;
    files.output = output;
    files.to = to;
    files.mask = mask;
    pipeline::DetectOptions options;
    options.detector = DetectorConfig{detector, params_from(params)};
    options.with_score = with_score;
    options.threads = threads;
    options.allow_damaged = allow_damaged;
    options.param_prefix = kIdentifierKeys;  // messages name with_score=, harris_window=
    pipeline::check_detect_options(options);
    pipeline::DetectSummary s;
    {
        py::gil_scoped_release release;
        s = pipeline::detect_file(files, options);
    }
    return summary_dict(s, input, params);
}

py::list detector_list() {
    py::list out;
    for (const DetectorInfo& info : detector_infos()) {
        py::dict d;
        d["name"] = std::string(info.name);
        d["class_name"] = std::string(info.class_name);
        d["summary"] = std::string(info.summary);
        d["has_score"] = info.has_score;
        d["local"] = info.local();
        py::list params;
        for (const ParamInfo& p : info.params) {
            py::dict q;
            std::string id(p.key);
            std::replace(id.begin(), id.end(), '-', '_');
            q["key"] = std::string(p.key);
            q["name"] = id;
            q["type"] = std::string(param_type_name(p.type));
            std::visit([&](auto v) { q["default"] = v; }, p.default_value);
            q["min"] = p.min;
            q["max"] = p.max;
            q["help"] = std::string(p.help);
            params.append(q);
        }
        d["params"] = params;
        out.append(d);
    }
    return out;
}

py::tuple label_py(py::handle corners, const eval::FeatureTrackParams& params) {
    // A private copy (corners are few): another thread writing to the array while the GIL
    // is released cannot change what the labelling indexes by.
    const std::span<const Event> view = events_view(corners, "corners");
    const std::vector<Event> ev(view.begin(), view.end());
    eval::FeatureTrackResult r;
    {
        py::gil_scoped_release release;
        eval::validate(params);
        r = eval::label_feature_tracks(ev, params);
    }
    py::array_t<std::uint8_t> on_track(static_cast<py::ssize_t>(r.on_track.size()));
    std::copy(r.on_track.begin(), r.on_track.end(), on_track.mutable_data());
    py::dict info;
    info["corners"] = r.on_track.size();
    info["on_track"] = r.labelled;
    info["ft_percent"] = r.ft_percent();
    info["hypotheses"] = r.hypotheses;
    info["accepted"] = r.accepted;
    return py::make_tuple(std::move(on_track), info);
}

py::tuple simulate_py(const std::string& scene, bool is_path) {
    std::vector<Event> events;
    SensorSize size;
    {
        py::gil_scoped_release release;
        const sim::Scene s = is_path ? sim::load_scene_file(scene) : sim::parse_scene(scene, "<scene>");
        size = s.sensor;
        events = sim::simulate(s);
    }
    return py::make_tuple(to_array(std::move(events)), py::make_tuple(size.width, size.height));
}

/// Corner events against a simulated scene's truth CSV, streamed one sample time at a time
/// (sim::TruthReader -> eval::TruthMatcher), as `evcorner eval --truth` does: the dict holds
/// the keys of results.json's "truth" object, plus corner_events and the per-event arrays.
py::dict evaluate_truth_py(py::handle corners, const std::string& truth, double radius, std::int64_t tolerance_us,
                           const std::string& credit, const std::string& interpolation,
                           std::optional<std::vector<double>> speed_bins) {
    const std::span<const Event> view = events_view(corners, "corners");
    const std::vector<Event> ev(view.begin(), view.end());  // private, as in label_py
    eval::TruthMatchParams p;
    p.radius = radius;
    p.tolerance_us = tolerance_us;
    p.credit = eval::parse_credit(credit);
    p.interpolation = eval::parse_interpolation(interpolation);
    if (speed_bins) p.speed_edges = std::move(*speed_bins);
    eval::validate(p);
    eval::TruthMatchResult r;
    eval::ErrorSummary err;
    {
        py::gil_scoped_release release;
        // The matcher takes a detector's output, in time order; anything else would be
        // matched wrongly without a word, so it is refused here.
        for (std::size_t i = 1; i < ev.size(); ++i)
            if (ev[i].t < ev[i - 1].t)
                throw std::invalid_argument("corners: not in time order at index " + std::to_string(i) + " (t " +
                                            std::to_string(ev[i].t) + " us after " + std::to_string(ev[i - 1].t) +
                                            " us)");
        eval::TruthMatcher matcher(ev, p);
        sim::TruthReader reader(truth);
        std::vector<sim::TruthCorner> rows;
        while (reader.next_sample(rows)) matcher.add_sample(rows);
        r = matcher.finish();
        err = eval::summarize_errors(r.errors);
    }
    py::dict d;
    d["truth"] = truth;
    d["corner_events"] = r.corner_events;
    d["true_positives"] = r.true_positives;
    d["precision_percent"] = r.precision();
    d["truth_samples"] = r.truth_samples;
    d["recalled"] = r.recalled;
    d["recall_percent"] = r.recall();
    d["loc_median_px"] = err.median;
    d["loc_mean_px"] = err.mean;
    d["loc_p90_px"] = err.p90;
    py::list bins;
    for (const eval::SpeedBin& b : r.bins) {
        py::dict q;
        q["speed_lo"] = b.lo;
        q["speed_hi"] = std::isinf(b.hi) ? py::object(py::none()) : py::object(py::float_(b.hi));
        q["events"] = b.events;
        q["true_positives"] = b.true_positives;
        q["samples"] = b.samples;
        q["recalled"] = b.recalled;
        bins.append(q);
    }
    d["speed_bins"] = bins;
    py::array_t<std::uint8_t> is_true(static_cast<py::ssize_t>(r.is_true.size()));
    std::copy(r.is_true.begin(), r.is_true.end(), is_true.mutable_data());
    py::array_t<float> errors(static_cast<py::ssize_t>(r.errors.size()));
    std::copy(r.errors.begin(), r.errors.end(), errors.mutable_data());
    d["is_true"] = is_true;
    d["errors"] = errors;
    return d;
}

}  // namespace

std::span<const Event> evcorner::python::events_view(py::handle obj, const char* what) { return ::events_view(obj, what); }

PYBIND11_MODULE(_evcorner, m) {
    m.doc() = "evcorner's C++ library (see the evcorner package for the documented API)";

    static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
    static py::exception<OutputError> output_error(m, "OutputError", PyExc_OSError);
    static py::exception<InvalidEvent> invalid_event(m, "InvalidEvent", PyExc_ValueError);
    static py::exception<StateTooLarge> too_large(m, "StateTooLarge", PyExc_MemoryError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            input_error(e.what());
        } catch (const OutputError& e) {
            output_error(e.what());
        } catch (const InvalidEvent& e) {
            invalid_event(e.what());
        } catch (const StateTooLarge& e) {
            too_large(e.what());
        }
    });
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const EventsOutOfOrder& e) {
            invalid_event(e.what());
        }
    });

    m.attr("EVENT_DTYPE") = event_dtype();
    m.def("_event_layout", [] {
        return py::dict(py::arg("itemsize") = sizeof(Event), py::arg("t") = offsetof(Event, t),
                        py::arg("x") = offsetof(Event, x), py::arg("y") = offsetof(Event, y),
                        py::arg("p") = offsetof(Event, p));
    });
    m.def("_address", [](py::handle events) { return reinterpret_cast<std::uintptr_t>(events_view(events).data()); },
          "Where C++ reads the events of an array (checked as every verb checks it).");
    m.def("detectors", &detector_list, "Every registered detector: name, class_name, summary, has_score, params.");
    m.attr("INPUT_FORMATS") = format_names(io::input_format_names());
    m.attr("OUTPUT_FORMATS") = format_names(io::kOutputFormats);

    py::class_<PyDetector>(m, "Detector")
        .def(py::init<std::string, int, int, py::dict>(), py::arg("name"), py::arg("width"), py::arg("height"),
             py::arg("params"))
        .def(py::init<const PyDetector&>(), py::arg("other"),
             "A copy of `other`, its state included: it goes on from where `other` is.")
        .def("process", &PyDetector::process, py::arg("events"), py::arg("out") = py::none())
        .def("process_scored", &PyDetector::process_scored, py::arg("events"), py::arg("out") = py::none(),
             py::arg("scores") = py::none())
        .def("reset", &PyDetector::reset)
        .def_property_readonly("name", &PyDetector::name)
        .def_property_readonly("sensor", &PyDetector::sensor)
        .def_property_readonly("has_score", &PyDetector::scored)
        .def_property_readonly("memory_bytes", &PyDetector::memory)
        .def_property_readonly("params", &PyDetector::params)
        .def_readonly("events", &PyDetector::events_)
        .def_readonly("corners", &PyDetector::corners_)
        .def_property_readonly("last_time", &PyDetector::last_time,
                               "The time of the last event processed (us), or None; the next call's events "
                               "may not be earlier.")
        .def_readonly("last_address", &PyDetector::last_address_);

    py::class_<io::ReaderOptions> reader_options(m, "ReaderOptions");
    // Messages name the options as this package's keywords (sensor=, time_unit, ...).
    reader_options.def(py::init([] {
        io::ReaderOptions o;
        o.keyword_spelling = true;
        return o;
    }));
    def_size_property<&io::ReaderOptions::sensor>(reader_options, "sensor");
    def_size_property<&io::ReaderOptions::fallback_sensor>(reader_options, "fallback_sensor");
    reader_options.def_readwrite("skip_invalid", &io::ReaderOptions::skip_invalid);
    // The user-set options, by their keywords in the library's table (io/formats.hpp).
    py::list keywords;
    for (const io::ReaderOptionInfo& info : io::reader_option_infos()) {
        const io::ReaderOptionInfo* r = &info;
        reader_options.def_property(
            std::string(r->keyword).c_str(), [r](const io::ReaderOptions& o) { return r->get(o); },
            [r](io::ReaderOptions& o, std::string v) { r->set(o, std::move(v)); }, std::string(r->help).c_str());
        keywords.append(std::string(r->keyword));
    }
    m.attr("READER_OPTION_KEYWORDS") = py::tuple(keywords);

    py::class_<PyReader>(m, "Reader")
        .def(py::init<const std::string&, const io::ReaderOptions&, const std::string&, bool>(), py::arg("path"),
             py::arg("options"), py::arg("format") = "auto", py::arg("allow_damaged") = false)
        .def("read_count", &PyReader::read_count, py::arg("n"))
        .def("read_until", &PyReader::read_until, py::arg("t_end"))
        .def("peek_time", &PyReader::peek_time)
        .def_property_readonly("sensor", &PyReader::sensor)
        .def_property_readonly("format", &PyReader::format)
        .def_property_readonly("name", &PyReader::name)
        .def_property_readonly("skipped", &PyReader::skipped)
        .def_property_readonly("bytes_consumed", &PyReader::bytes_consumed)
        .def_property_readonly("bytes_total", &PyReader::bytes_total)
        .def_property_readonly("damaged", &PyReader::damaged);

    m.def(
        "_check_events",
        [](py::handle events, std::pair<int, int> sensor) {
            const std::span<const Event> ev = events_view(events);
            py::gil_scoped_release release;
            check_on_sensor(ev, sensor);
        },
        py::arg("events"), py::arg("sensor"), "InvalidEvent for the first event off sensor=(width, height).");
    m.def("_has_event_layout", [](const py::dtype& dt) { return has_event_layout(dt); }, py::arg("dtype"),
          "Whether C++ reads arrays of this dtype in place (EVENT_DTYPE's layout).");
    m.def("write", &write_events, py::arg("path"), py::arg("events"), py::arg("format") = "auto",
          py::arg("sensor") = py::none());
    m.def("detect_file", &detect_file_py, py::arg("input"), py::arg("output"), py::arg("detector"),
          py::arg("params"), py::arg("reader"), py::arg("format") = "auto", py::arg("to") = "auto",
          py::arg("mask") = "", py::arg("with_score") = false, py::arg("threads") = 1,
          py::arg("allow_damaged") = false);

    py::class_<eval::FeatureTrackParams>(m, "FeatureTrackParams")
        .def(py::init<>())
        .def_readwrite("inner_radius", &eval::FeatureTrackParams::inner_radius)
        .def_readwrite("outer_radius", &eval::FeatureTrackParams::outer_radius)
        .def_readwrite("min_inner", &eval::FeatureTrackParams::min_inner)
        .def_readwrite("max_outer_ratio", &eval::FeatureTrackParams::max_outer_ratio)
        .def_readwrite("max_duration_us", &eval::FeatureTrackParams::max_duration_us)
        .def_readwrite("max_length", &eval::FeatureTrackParams::max_length)
        .def_readwrite("same_polarity", &eval::FeatureTrackParams::same_polarity)
        .def_property(
            "overlap", [](const eval::FeatureTrackParams& p) { return std::string(eval::to_string(p.overlap)); },
            [](eval::FeatureTrackParams& p, const std::string& s) {
                p.overlap = eval::parse_track_overlap(s);
            })
        .def_readwrite("cell_size", &eval::FeatureTrackParams::cell_size);
    m.def("label", &label_py);
    m.def("reduction_rate", &eval::reduction_rate, py::arg("n_events"), py::arg("n_corners"),
          "The reduction rate in percent from two counts: 100 (1 - n_corners / n_events); 0 for no events.");
    m.def("ft_percent", &eval::ft_percent, py::arg("n_corners"), py::arg("n_on_track"),
          "The feature-track percentage from two counts: 100 n_on_track / n_corners; 0 for no corners.");
    m.def("simulate", &simulate_py, py::arg("scene"), py::arg("is_path"));
    python::export_tracks(m);
    m.def("evaluate_truth", &evaluate_truth_py, py::arg("corners"), py::arg("truth"), py::arg("radius"),
          py::arg("tolerance_us"), py::arg("credit"), py::arg("interpolation"), py::arg("speed_bins") = py::none());
}
