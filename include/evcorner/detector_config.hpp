#pragma once
// A detector chosen at run time: its name and the values of the parameters given,
// as plain typed values keyed by the parameter's name ("harris-window" = 11). What
// the command line's --harris-window 11 and -p harris-window=11 fill, and what a
// binding's keyword arguments (harris_window=11) map onto. The registry (registry.hpp)
// checks the values against the chosen detector and turns them into its Params struct.

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace evcorner {

enum class ParamType { integer, real, boolean };

/// "integer", "number" or "true/false".
std::string_view param_type_name(ParamType type) noexcept;

/// A parameter's value as given. An integer value may be given for a real parameter;
/// an integral real value (11.0) for an integer one.
using ParamValue = std::variant<bool, std::int64_t, double>;

/// "11", "0.04", "true".
std::string format_param_value(const ParamValue& value);

/// One parameter of one detector.
struct ParamInfo {
    std::string_view key;  ///< global, command-line style name: "harris-window"
    ParamType type = ParamType::integer;
    ParamValue default_value;
    double min = 0, max = 0;  ///< accepted range, inclusive (unused for a boolean)
    std::string_view help;    ///< one line
};

/// The values given, by key (each key once). Keys the chosen detector does not take
/// are an error when the detector is built (registry.hpp), not here.
class ParamValues {
public:
    using Map = std::map<std::string, ParamValue, std::less<>>;

    /// Sets `key` (replacing an earlier value).
    void set(std::string_view key, ParamValue value) { values_.insert_or_assign(std::string(key), value); }
    /// The value of `key`, or nullptr when it was not given.
    [[nodiscard]] const ParamValue* find(std::string_view key) const noexcept {
        const auto it = values_.find(key);
        return it == values_.end() ? nullptr : &it->second;
    }
    [[nodiscard]] bool contains(std::string_view key) const noexcept { return find(key) != nullptr; }
    [[nodiscard]] bool empty() const noexcept { return values_.empty(); }
    [[nodiscard]] std::size_t size() const noexcept { return values_.size(); }
    [[nodiscard]] Map::const_iterator begin() const noexcept { return values_.begin(); }
    [[nodiscard]] Map::const_iterator end() const noexcept { return values_.end(); }

private:
    Map values_;
};

/// The key of a parameter named as an identifier, as a binding's keyword argument names
/// it: "harris_window" -> "harris-window" (underscores become hyphens).
std::string param_key(std::string_view identifier);

/// How error messages spell a parameter's or an option's key ("harris-window") for the
/// caller that gave it: `prefix` before it ("--": the command line's --harris-window), and
/// with `identifiers`, underscores for hyphens (a binding's keyword harris_window).
struct KeySpelling {
    std::string_view prefix;
    bool identifiers = false;

    constexpr KeySpelling(const char* p = "") noexcept : prefix(p) {}
    constexpr KeySpelling(std::string_view p, bool as_identifiers) noexcept : prefix(p), identifiers(as_identifiers) {}
    /// The key as the caller knows it.
    [[nodiscard]] std::string operator()(std::string_view key) const;
};
/// Keys as keyword arguments name them (harris_window).
inline constexpr KeySpelling kIdentifierKeys{"", true};

/// A detector by name with the parameter values given (the others keep their defaults).
struct DetectorConfig {
    std::string name = "efast";
    ParamValues params;
};

/// How --threads may split the sensor for a detector (parallel_detect.hpp).
enum class Split {
    none,         ///< not local: one thread only
    by_polarity,  ///< bands of rows of one polarity (a decision reads its own polarity only)
    by_rows,      ///< bands of rows carrying both polarities (a decision reads both)
};

/// What the registry says about one detector, for --help, checks and the bindings.
struct DetectorInfo {
    std::string_view name;        ///< the name used on the command line: "efast"
    std::string_view class_name;  ///< the C++ class's name ("EFast"), which bindings give their class
    std::string_view summary;     ///< one line
    std::vector<ParamInfo> params;
    bool has_score = false;  ///< it reports a score per event (ScoredDetector)
    Split split = Split::none;
    std::string_view not_local;  ///< why it runs on one thread only (split == none)

    [[nodiscard]] bool local() const noexcept { return split != Split::none; }
    /// The parameter called `key`, or nullptr when this detector does not take it.
    [[nodiscard]] const ParamInfo* param(std::string_view key) const noexcept {
        for (const ParamInfo& p : params)
            if (p.key == key) return &p;
        return nullptr;
    }
};

}  // namespace evcorner
