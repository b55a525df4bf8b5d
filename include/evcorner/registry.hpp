#pragma once
// Every detector evcorner runs, in ONE place: detector_registry() below. Adding a
// detector is one #include and one DetectorEntry in that list (docs/detectors.md);
// every command (detect, eval, render, bench, --threads, --help), the detection
// pipeline (pipeline/detect.hpp) and AnyDetector take it from here.
//
// Picking a detector at run time: AnyDetector is a std::variant of the listed classes,
// visited once outside the per-event loop, so that the loop itself is statically
// dispatched; with_detector_entry() hands a generic lambda the entry of a named
// detector, to build loops (or a ParallelDetector) on its concrete class.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "evcorner/detector_config.hpp"
#include "evcorner/detector_entry.hpp"
#include "evcorner/sensor.hpp"

// The detectors.
#include "evcorner/efast.hpp"
#include "evcorner/harris.hpp"
#include "evcorner/harris_global.hpp"
#include "evcorner/arcstar.hpp"
#include "evcorner/fa_harris.hpp"
#include "evcorner/efast_harris.hpp"
#include "evcorner/luvharris.hpp"

namespace evcorner {

// Parameter groups several detectors share (same keys, same meaning, same ranges): the
// Harris score of a patch, the newest-Nl patch, and Arc*'s filter and arcs. P is any
// params struct with the named fields.
template <class P>
std::vector<ParamField<P>> harris_score_params() {
    return {
        param("harris-window", &P::window, 5, 15, "patch side, odd"),
        param("harris-k", &P::k, -kUnbounded, kUnbounded, "k in H = det - k trace^2"),
        param("harris-threshold", &P::threshold, -kUnbounded, kUnbounded, "corner iff score > threshold"),
    };
}
template <class P>
std::vector<ParamField<P>> harris_patch_params() {
    auto v = harris_score_params<P>();
    v.insert(v.begin() + 1, param("harris-nl", &P::nl, 1, 225, "newest distinct pixels lit in the patch, at most window^2"));
    return v;
}
template <class P>
std::vector<ParamField<P>> arc_filter_params() {
    return {
        param("arc-filter", &P::filter, "the published filter (false: every event passes)"),
        param("arc-filter-us", &P::filter_us, std::int64_t{0}, ArcStar::kMaxFilterUs,
              "filter window in us: an event passes when its pixel's last one is older by more"),
        param("arc-minority-only", &P::minority_only, "accept only minority arcs (3..6, 4..8), not the majority arcs"),
        param("arc-zero-init", &P::zero_init, "the authors' zero-initialised filter (a never-fired pixel reads as t = 0)"),
    };
}
template <class P>
std::vector<ParamField<P>> operator+(std::vector<ParamField<P>> a, const std::vector<ParamField<P>>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

/// THE list: one entry per detector, in the order --help lists them. Keys of parameters
/// are global: a key several detectors take (harris-window) means the same thing for
/// each and has the same type.
// Entries name only the fields they need (the others keep DetectorEntry's defaults).
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
inline const auto& detector_registry() {
    static const std::tuple entries{
        DetectorEntry<EFast>{
            .name = "efast",
            .class_name = "EFast",
            .summary = "eFAST (Mueggler et al., BMVC 2017): arcs on the SAE circles of radius 3 and 4",
            .params = {},
            .split = Split::by_polarity,
            .radius = [](const EFastParams&) { return kCircleMargin; },
        },
        DetectorEntry<Harris>{
            .name = "harris",
            .class_name = "Harris",
            .summary = "spatially-adaptive Harris (Mueggler et al., BMVC 2017, Sec. 3.2): newest Nl pixels of the window",
            .params = harris_patch_params<HarrisParams>(),
            .split = Split::by_polarity,
            .radius = [](const HarrisParams& p) { return p.window / 2; },
        },
        DetectorEntry<HarrisGlobal>{
            .name = "harris-global",
            .class_name = "HarrisGlobal",
            .summary = "event-based Harris (Vasco et al., IROS 2016): newest N pixels of the sensor",
            .params = harris_score_params<HarrisGlobalParams>() +
                      std::vector{param("harris-n", &HarrisGlobalParams::n, 1, 2147483647,
                                        "newest distinct pixels lit over the sensor per polarity (1000 or 2000 in "
                                        "Vasco et al.)")},
            .split = Split::none,
            .not_local = "its surface holds the newest N pixels of the whole sensor",
        },
        DetectorEntry<ArcStar>{
            .name = "arcstar",
            .class_name = "ArcStar",
            .summary = "Arc* (Alzugaray and Chli, RA-L 2018): 50 ms filter, then its arc test on the radius-3/4 circles, "
                       "majority arcs included",
            .params = arc_filter_params<ArcStarParams>(),
            .split = Split::by_rows,
            .radius = [](const ArcStarParams&) { return kCircleMargin; },
        },
        DetectorEntry<FaHarris>{
            .name = "fa-harris",
            .class_name = "FaHarris",
            .summary = "FA-Harris (Li et al., IROS 2019): Arc* candidates refined by the adaptive Harris on the newest "
                       "filtered pixels",
            .params = arc_filter_params<FaHarrisParams>() + harris_patch_params<FaHarrisParams>(),
            .split = Split::by_rows,
            // A border event changes no state: in a part (parallel_detect.hpp) the rows within
            // kCircleMargin of the part's edge are border rows, so the halo holds those on top
            // of the rows an event reads (the circles and the Harris window).
            .radius = [](const FaHarrisParams& p) { return std::max(kCircleMargin, p.window / 2) + kCircleMargin; },
        },
        DetectorEntry<EFastHarris>{
            .name = "efast-harris",
            .class_name = "EFastHarris",
            .summary = "eFAST -> Harris cascade (Mueggler et al., BMVC 2017, Sec. 4): eFAST corners the adaptive Harris "
                       "also scores above its threshold",
            .params = harris_patch_params<HarrisParams>(),
            .split = Split::by_polarity,
            .radius = [](const HarrisParams& p) { return std::max(kCircleMargin, p.window / 2); },
        },
        DetectorEntry<LuvHarris>{
            .name = "luvharris",
            .class_name = "LuvHarris",
            .summary = "luvHarris (Glover et al., TPAMI 2021): TOS surface, Harris table refreshed at fixed points of the "
                       "stream (reproducible)",
            .params =
                {
                    param("luv-tos-size", &LuvHarrisParams::tos_size, 3, 31, "TOS neighbourhood side k, odd"),
                    param("luv-tos-threshold", &LuvHarrisParams::tos_threshold, 0, 254,
                          "TOS T: values below 255 - k*T drop to 0 (at most 254/k)"),
                    param("luv-gradient", &LuvHarrisParams::gradient, 3, 5,
                          "derivative kernel side: 5 (the paper's Harris kernels) or 3 (Sobel)"),
                    param("luv-block", &LuvHarrisParams::block, 1, 15,
                          "structure-tensor block side, odd (box: 1..15, gaussian: 3..9)"),
                    param("luv-gaussian-block", &LuvHarrisParams::gaussian_block, "binomial block weights instead of a box"),
                    param("luv-k", &LuvHarrisParams::k, 0.0, 0.25, "Harris k (rounded to a multiple of 2^-16)"),
                    param("luv-refresh-us", &LuvHarrisParams::refresh_us, std::int64_t{0}, LuvHarris::kMaxRefreshUs,
                          "refresh the table every this much event time (0: never by time)"),
                    param("luv-refresh-events", &LuvHarrisParams::refresh_events, std::int64_t{0},
                          std::int64_t{1} << 40, "refresh the table every this many events (0: never by count)"),
                    param("luv-adaptive", &LuvHarrisParams::adaptive,
                          "threshold = running mean + sigmas * std of the looked-up values (false: luv-threshold)"),
                    param("luv-sigmas", &LuvHarrisParams::sigmas, -kUnbounded, kUnbounded,
                          "adaptive: standard deviations above the mean"),
                    param("luv-alpha", &LuvHarrisParams::alpha, 0.0, 1.0,
                          "adaptive: weight of each new value in the running statistics, (0, 1]"),
                    param("luv-threshold", &LuvHarrisParams::threshold, -kUnbounded, kUnbounded,
                          "fixed rule: corner iff the looked-up value > threshold"),
                    param("luv-replicate-border", &LuvHarrisParams::replicate_border,
                          "beyond the sensor the TOS reads as its nearest pixel (else 0)"),
                },
            .split = Split::none,
            .not_local = "its look-up table is refreshed over the whole sensor at points of the whole stream",
        },
    };
    return entries;
}
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace detail {
template <class Entries>
struct DetectorVariant;
template <class... E>
struct DetectorVariant<std::tuple<E...>> {
    using type = std::variant<typename E::Detector...>;
};
}  // namespace detail

/// Any detector of the registry.
using AnyDetector = detail::DetectorVariant<std::remove_cvref_t<decltype(detector_registry())>>::type;

/// Calls f(entry) for every entry, in order.
template <class F>
void for_each_detector_entry(F&& f) {
    std::apply([&](const auto&... e) { (f(e), ...); }, detector_registry());
}

/// [[noreturn]]: "unknown detector 'x' (known: efast, harris, harris-global)".
[[noreturn]] void throw_unknown_detector(std::string_view name);

/// Returns f(entry) for the entry called `name` (f: a generic lambda taking `const
/// DetectorEntry<D>&`; every instantiation must return the same type); throws
/// std::invalid_argument for an unknown name.
template <class F>
decltype(auto) with_detector_entry(std::string_view name, F&& f) {
    using R = decltype(f(std::get<0>(detector_registry())));
    if constexpr (std::is_void_v<R>) {
        bool found = false;
        for_each_detector_entry([&](const auto& e) {
            if (!found && e.name == name) {
                found = true;
                f(e);
            }
        });
        if (!found) throw_unknown_detector(name);
    } else {
        std::optional<R> out;
        for_each_detector_entry([&](const auto& e) {
            if (!out && e.name == name) out.emplace(f(e));
        });
        if (!out) throw_unknown_detector(name);
        return R(std::move(*out));
    }
}

// ------------------------------------------------------------------ run-time view

/// Every detector, in the registry's order.
std::span<const DetectorInfo> detector_infos();
/// The detector called `name`; throws std::invalid_argument for an unknown name.
const DetectorInfo& detector_info(std::string_view name);
/// "efast, harris, harris-global".
std::string detector_names(std::string_view separator = ", ");

/// One parameter key as all the detectors that take it see it.
struct ParamKeyInfo {
    std::string_view key;
    ParamType type = ParamType::integer;
    std::string_view help;                 ///< the first detector's
    std::vector<std::string_view> detectors;  ///< the detectors that take it, in order
    std::vector<ParamValue> defaults;         ///< their defaults, in the same order
};
/// Every distinct key, in order of first appearance. Throws std::logic_error when two
/// detectors give one key different types (a registry bug; a test checks).
std::vector<ParamKeyInfo> parameter_keys();

/// Reads `text` as a value of parameter `key` ("11", "0.04", "true"/"false"/"1"/"0");
/// throws std::invalid_argument (naming prefix + key) for an unknown key or a bad value.
ParamValue parse_param_value(std::string_view key, std::string_view text, const KeySpelling& prefix = {});
/// Reads "KEY=VALUE" (the command line's -p) into `values`.
void parse_param_assignment(std::string_view assignment, ParamValues& values, const KeySpelling& prefix = {});

/// Throws std::invalid_argument when `config` names an unknown detector, a key that
/// detector does not take, or a value of the wrong type or out of range (messages name
/// the key as prefix + key). Parameters whose valid range depends on another (Harris's
/// nl <= window^2) are checked when the detector is built.
void check_detector_config(const DetectorConfig& config, const KeySpelling& prefix = {});

/// The values of `values` that detector `name` takes (for commands that run several
/// detectors with one set of options).
DetectorConfig config_for(std::string_view name, const ParamValues& values);

/// Throws std::invalid_argument when a key of `values` is taken by none of `names`.
void check_params_taken(std::span<const std::string> names, const ParamValues& values,
                        const KeySpelling& prefix = {});

/// Bytes of state the configured detector needs over `size` (its static state_bytes());
/// throws as check_detector_config() does.
std::uint64_t detector_state_bytes(const DetectorConfig& config, SensorSize size);
inline std::uint64_t detector_state_bytes(std::string_view name, SensorSize size) {
    return detector_state_bytes(DetectorConfig{std::string(name), {}}, size);
}

/// The locality radius for --threads (parallel_detect.hpp), or nullopt when the detector
/// is not local; throws as check_detector_config() does.
std::optional<int> detector_radius(const DetectorConfig& config);

/// Builds the configured detector; throws std::invalid_argument for an unknown name, a
/// parameter out of range or a sensor side outside 1..kMaxSensorSide, and, before
/// allocating, StateTooLarge (state_memory.hpp) when its state needs more memory than
/// available_memory_bytes() (e.g. "a 65536x65536 sensor needs 68.7 GB for efast's state
/// (16 B per pixel); 21.3 GB is available").
AnyDetector make_detector(const DetectorConfig& config, SensorSize size, const KeySpelling& prefix = {});
inline AnyDetector make_detector(std::string_view name, SensorSize size) {
    return make_detector(DetectorConfig{std::string(name), {}}, size);
}

/// The registry name of the detector `d` holds.
std::string_view detector_name(const AnyDetector& d) noexcept;

/// detect() on whichever detector `d` holds (checked; see detector.hpp).
std::size_t detect(AnyDetector& d, std::span<const Event> events, std::span<std::uint8_t> is_corner);
/// detect_unchecked() on whichever detector `d` holds.
std::size_t detect_unchecked(AnyDetector& d, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept;

/// Whether the detector reports a score (ScoredDetector).
bool has_score(const AnyDetector& d) noexcept;

/// Bytes of state the detector holds.
std::size_t memory_bytes(const AnyDetector& d) noexcept;

}  // namespace evcorner
