#pragma once
// One detector's entry in the registry (registry.hpp): everything the library and the
// commands need to know to run detector class D, written next to the other entries.
//
//   DetectorEntry<Harris>{
//       .name = "harris",
//       .summary = "spatially-adaptive Harris ...",
//       .params = {param("harris-window", &HarrisParams::window, 5, 15, "patch side, odd"), ...},
//       .split = Split::by_polarity,
//       .radius = [](const HarrisParams& p) { return p.window / 2; },
//   }
//
// D follows the detector contract (docs/detectors.md): a Params struct (`using Params`),
// D(SensorSize, const Params&, int planes), static state_bytes(SensorSize, const Params&,
// int planes), memory_bytes(), the Detector concept, and last_score() when it has a
// score. Defaults come from the Params struct itself (never written twice); whether it
// has a score from the ScoredDetector concept.

#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/detector_config.hpp"
#include "evcorner/scored_detector.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/state_memory.hpp"

namespace evcorner {

namespace detail {
// "harris-window must be within 5..15 (got 3)": `prefix` spells the key as the caller
// knows it ("--" on the command line).
[[noreturn]] void param_error(const KeySpelling& prefix, std::string_view key, const std::string& what);
std::int64_t param_as_integer(const KeySpelling& prefix, std::string_view key, const ParamValue& v);
double param_as_real(const KeySpelling& prefix, std::string_view key, const ParamValue& v);
bool param_as_boolean(const KeySpelling& prefix, std::string_view key, const ParamValue& v);
void check_param_range(const KeySpelling& prefix, std::string_view key, double v, double min, double max);
}  // namespace detail

/// One parameter: its key, the field of P it sets, its range and help.
template <class P>
struct ParamField {
    std::string_view key;
    std::variant<int P::*, std::int64_t P::*, double P::*, bool P::*> member;
    double min = 0, max = 0;
    std::string_view help;

    [[nodiscard]] ParamInfo info() const {
        ParamInfo i;
        i.key = key;
        i.min = min;
        i.max = max;
        i.help = help;
        if constexpr (!std::is_empty_v<P>) {  // (an empty P has no fields: quiets -Warray-bounds)
            static const P defaults{};  // static: a member pointer may address its padding as the compiler sees it
            std::visit(
                [&](auto m) {
                    using T = std::remove_cvref_t<decltype(defaults.*m)>;
                    if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::int64_t>) {
                        i.type = ParamType::integer;
                        i.default_value = static_cast<std::int64_t>(defaults.*m);
                    } else if constexpr (std::is_same_v<T, double>) {
                        i.type = ParamType::real;
                        i.default_value = defaults.*m;
                    } else {
                        i.type = ParamType::boolean;
                        i.default_value = defaults.*m;
                    }
                },
                member);
        }
        return i;
    }

    /// Checks `v` (type, range) and stores it in `p`; throws std::invalid_argument naming the key.
    void apply(P& p, const ParamValue& v, const KeySpelling& prefix) const {
        (void)p, (void)v, (void)prefix;
        if constexpr (!std::is_empty_v<P>) {  // (an empty P has no fields: quiets -Warray-bounds)
            std::visit(
                [&](auto m) {
                    using T = std::remove_cvref_t<decltype(p.*m)>;
                    if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::int64_t>) {
                        const std::int64_t x = detail::param_as_integer(prefix, key, v);
                        detail::check_param_range(prefix, key, static_cast<double>(x), min, max);
                        p.*m = static_cast<T>(x);
                    } else if constexpr (std::is_same_v<T, double>) {
                        const double x = detail::param_as_real(prefix, key, v);
                        detail::check_param_range(prefix, key, x, min, max);
                        p.*m = x;
                    } else {
                        p.*m = detail::param_as_boolean(prefix, key, v);
                    }
                },
                member);
        }
    }
};

/// An integer parameter within [min, max].
template <class P>
ParamField<P> param(std::string_view key, int P::*member, int min, int max, std::string_view help) {
    return {key, member, static_cast<double>(min), static_cast<double>(max), help};
}
/// A 64-bit integer parameter within [min, max] (times in microseconds, counts).
template <class P>
ParamField<P> param(std::string_view key, std::int64_t P::*member, std::int64_t min, std::int64_t max,
                    std::string_view help) {
    return {key, member, static_cast<double>(min), static_cast<double>(max), help};
}
/// A real parameter within [min, max] (finite; +-infinity bounds: any finite value).
template <class P>
ParamField<P> param(std::string_view key, double P::*member, double min, double max, std::string_view help) {
    return {key, member, min, max, help};
}
/// A true/false parameter.
template <class P>
ParamField<P> param(std::string_view key, bool P::*member, std::string_view help) {
    return {key, member, 0, 1, help};
}

inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

template <class D>
struct DetectorEntry {
    using Detector = D;
    using Params = typename D::Params;
    static constexpr bool kHasScore = ScoredDetector<D>;

    std::string_view name;        ///< the name on the command line
    std::string_view class_name;  ///< D's name without its namespace ("EFast"): a binding's class
    std::string_view summary;     ///< one line for --help
    std::vector<ParamField<Params>> params;
    /// How --threads may split the sensor; Split::none: not local (one thread only).
    Split split = Split::none;
    /// The locality radius (parallel_detect.hpp) for given parameters; unused when not local.
    int (*radius)(const Params&) = nullptr;
    /// Why it is not local (the --threads refusal names it); unused when local.
    std::string_view not_local;

    /// Params from the values given: each key must be one of this detector's, each value
    /// of its type and within its range; throws std::invalid_argument naming the key (as
    /// prefix + key) and, for a key it does not take, the detector and the keys it takes.
    [[nodiscard]] Params params_of(const ParamValues& values, const KeySpelling& prefix = {}) const {
        Params p{};
        for (const auto& [key, value] : values) {
            const ParamField<Params>* f = field(key);
            if (!f) {
                std::string takes;
                for (const auto& g : params) takes += (takes.empty() ? "" : ", ") + prefix(g.key);
                throw std::invalid_argument("detector '" + std::string(name) + "' takes no parameter " + prefix(key) +
                                            (takes.empty() ? " (it takes none)" : " (it takes: " + takes + ")"));
            }
            f->apply(p, value, prefix);
        }
        return p;
    }

    /// Bytes of state the detector holds over `size` (its static state_bytes()).
    [[nodiscard]] std::uint64_t state_bytes(SensorSize size, const Params& p, int planes = 2) const noexcept {
        if constexpr (requires { D::state_bytes(size, p, planes); })
            return D::state_bytes(size, p, planes);
        else
            return D::state_bytes(size, p);  // a detector with one form of state (planes unused)
    }

    /// Builds the detector: throws std::invalid_argument for a parameter or sensor side out
    /// of range and, before allocating, StateTooLarge when its state does not fit in the
    /// memory available (state_memory.hpp).
    [[nodiscard]] D make(SensorSize size, const Params& p, int planes = 2) const {
        checked_sensor_size(size, std::string(name).c_str());
        require_state_fits(name, size, state_bytes(size, p, planes), available_memory_bytes());
        if constexpr (std::is_constructible_v<D, SensorSize, const Params&, int>)
            return D(size, p, planes);
        else
            return D(size, p);
    }

    [[nodiscard]] DetectorInfo info() const {
        DetectorInfo i;
        i.name = name;
        i.class_name = class_name;
        i.summary = summary;
        for (const auto& f : params) i.params.push_back(f.info());
        i.has_score = kHasScore;
        i.split = split;
        i.not_local = not_local;
        return i;
    }

    [[nodiscard]] const ParamField<Params>* field(std::string_view key) const noexcept {
        for (const auto& f : params)
            if (f.key == key) return &f;
        return nullptr;
    }
};

}  // namespace evcorner
