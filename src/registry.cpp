// The run-time view of the registry (registry.hpp) and the parameter checks of
// detector_entry.hpp.

#include "evcorner/registry.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace evcorner {

std::string_view param_type_name(ParamType type) noexcept {
    switch (type) {
        case ParamType::integer: return "integer";
        case ParamType::real: return "number";
        case ParamType::boolean: return "true/false";
    }
    return "?";
}

namespace {
std::string format_real(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    // Shortest form that reads back to v.
    for (int prec = 1; prec <= 17; ++prec) {
        char b[64];
        std::snprintf(b, sizeof b, "%.*g", prec, v);
        if (std::strtod(b, nullptr) == v) return b;
    }
    return buf;
}
}  // namespace

std::string format_param_value(const ParamValue& value) {
    if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
    if (const std::int64_t* i = std::get_if<std::int64_t>(&value)) return std::to_string(*i);
    return format_real(std::get<double>(value));
}

std::string param_key(std::string_view identifier) {
    std::string key(identifier);
    for (char& c : key)
        if (c == '_') c = '-';
    return key;
}

std::string KeySpelling::operator()(std::string_view key) const {
    std::string s(prefix);
    for (const char c : key) s += identifiers && c == '-' ? '_' : c;
    return s;
}

namespace detail {

void param_error(const KeySpelling& prefix, std::string_view key, const std::string& what) {
    throw std::invalid_argument(prefix(key) + " " + what);
}

std::int64_t param_as_integer(const KeySpelling& prefix, std::string_view key, const ParamValue& v) {
    if (const std::int64_t* i = std::get_if<std::int64_t>(&v)) return *i;
    if (const double* d = std::get_if<double>(&v)) {
        if (std::isfinite(*d) && std::trunc(*d) == *d && std::fabs(*d) < 9.0e18) return static_cast<std::int64_t>(*d);
        param_error(prefix, key, "takes an integer (got " + format_real(*d) + ")");
    }
    param_error(prefix, key, "takes an integer (got " + format_param_value(v) + ")");
}

double param_as_real(const KeySpelling& prefix, std::string_view key, const ParamValue& v) {
    double x = 0;
    if (const double* d = std::get_if<double>(&v))
        x = *d;
    else if (const std::int64_t* i = std::get_if<std::int64_t>(&v))
        x = static_cast<double>(*i);
    else
        param_error(prefix, key, "takes a number (got " + format_param_value(v) + ")");
    if (!std::isfinite(x)) param_error(prefix, key, "must be a finite number (got " + format_real(x) + ")");
    return x;
}

bool param_as_boolean(const KeySpelling& prefix, std::string_view key, const ParamValue& v) {
    if (const bool* b = std::get_if<bool>(&v)) return *b;
    if (const std::int64_t* i = std::get_if<std::int64_t>(&v); i && (*i == 0 || *i == 1)) return *i == 1;
    param_error(prefix, key, "takes true or false (got " + format_param_value(v) + ")");
}

void check_param_range(const KeySpelling& prefix, std::string_view key, double v, double min, double max) {
    if (v >= min && v <= max) return;
    param_error(prefix, key, "must be within " + format_real(min) + ".." + format_real(max) + " (got " + format_real(v) + ")");
}

}  // namespace detail

// ------------------------------------------------------------------ run-time view

void throw_unknown_detector(std::string_view name) {
    throw std::invalid_argument("unknown detector '" + std::string(name) + "' (known: " + detector_names() + ")");
}

std::span<const DetectorInfo> detector_infos() {
    static const std::vector<DetectorInfo> infos = [] {
        std::vector<DetectorInfo> v;
        for_each_detector_entry([&](const auto& e) { v.push_back(e.info()); });
        return v;
    }();
    return infos;
}

const DetectorInfo& detector_info(std::string_view name) {
    for (const DetectorInfo& i : detector_infos())
        if (i.name == name) return i;
    throw_unknown_detector(name);
}

std::string detector_names(std::string_view separator) {
    std::string s;
    for_each_detector_entry([&](const auto& e) {
        if (!s.empty()) s += separator;
        s += e.name;
    });
    return s;
}

std::vector<ParamKeyInfo> parameter_keys() {
    std::vector<ParamKeyInfo> keys;
    for (const DetectorInfo& d : detector_infos())
        for (const ParamInfo& p : d.params) {
            ParamKeyInfo* k = nullptr;
            for (auto& x : keys)
                if (x.key == p.key) k = &x;
            if (!k) {
                keys.push_back({p.key, p.type, p.help, {}, {}});
                k = &keys.back();
            } else if (k->type != p.type) {
                throw std::logic_error("registry: parameter " + std::string(p.key) + " has two types");
            }
            k->detectors.push_back(d.name);
            k->defaults.push_back(p.default_value);
        }
    return keys;
}

ParamValue parse_param_value(std::string_view key, std::string_view text, const KeySpelling& prefix) {
    const ParamInfo* info = nullptr;
    for (const DetectorInfo& d : detector_infos())
        if (!info) info = d.param(key);
    if (!info) {
        std::string known;
        for (const auto& k : parameter_keys()) known += (known.empty() ? "" : ", ") + std::string(k.key);
        throw std::invalid_argument("unknown parameter " + prefix(key) +
                                    " (known: " + (known.empty() ? "none" : known) + ")");
    }
    const std::string t(text);
    switch (info->type) {
        case ParamType::boolean:
            if (t == "true" || t == "1" || t == "on" || t == "yes") return true;
            if (t == "false" || t == "0" || t == "off" || t == "no") return false;
            detail::param_error(prefix, key, "takes true or false (got '" + t + "')");
        case ParamType::integer: {
            std::int64_t v = 0;
            const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
            if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size())
                detail::param_error(prefix, key, "takes an integer (got '" + t + "')");
            return v;
        }
        case ParamType::real: {
            char* end = nullptr;
            const double v = t.empty() ? 0.0 : std::strtod(t.c_str(), &end);
            if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v))
                detail::param_error(prefix, key, "takes a finite number (got '" + t + "')");
            return v;
        }
    }
    detail::param_error(prefix, key, "has an unknown type");
}

void parse_param_assignment(std::string_view assignment, ParamValues& values, const KeySpelling& prefix) {
    const auto eq = assignment.find('=');
    if (eq == std::string_view::npos || eq == 0)
        throw std::invalid_argument("expected KEY=VALUE, e.g. harris-window=11 (got '" + std::string(assignment) + "')");
    const std::string_view key = assignment.substr(0, eq);
    values.set(key, parse_param_value(key, assignment.substr(eq + 1), prefix));
}

void check_detector_config(const DetectorConfig& config, const KeySpelling& prefix) {
    with_detector_entry(config.name, [&](const auto& e) { (void)e.params_of(config.params, prefix); });
}

DetectorConfig config_for(std::string_view name, const ParamValues& values) {
    const DetectorInfo& info = detector_info(name);
    DetectorConfig c{std::string(name), {}};
    for (const auto& [key, value] : values)
        if (info.param(key)) c.params.set(key, value);
    return c;
}

void check_params_taken(std::span<const std::string> names, const ParamValues& values, const KeySpelling& prefix) {
    for (const auto& [key, value] : values) {
        bool taken = false;
        for (const std::string& n : names) taken = taken || detector_info(n).param(key) != nullptr;
        if (taken) continue;
        std::string list;
        for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
        throw std::invalid_argument("no detector run takes " + prefix(key) + " (detectors: " + list + ")");
    }
}

std::uint64_t detector_state_bytes(const DetectorConfig& config, SensorSize size) {
    return with_detector_entry(config.name,
                               [&](const auto& e) { return e.state_bytes(size, e.params_of(config.params)); });
}

std::optional<int> detector_radius(const DetectorConfig& config) {
    return with_detector_entry(config.name, [&](const auto& e) -> std::optional<int> {
        const auto p = e.params_of(config.params);
        if (e.split == Split::none || !e.radius) return std::nullopt;
        return e.radius(p);
    });
}

AnyDetector make_detector(const DetectorConfig& config, SensorSize size, const KeySpelling& prefix) {
    return with_detector_entry(config.name, [&](const auto& e) {
        return AnyDetector(std::in_place_type<typename std::remove_cvref_t<decltype(e)>::Detector>,
                           e.make(size, e.params_of(config.params, prefix)));
    });
}

std::string_view detector_name(const AnyDetector& d) noexcept { return detector_infos()[d.index()].name; }

std::size_t detect(AnyDetector& d, std::span<const Event> events, std::span<std::uint8_t> is_corner) {
    return std::visit([&](auto& det) { return detect(det, events, is_corner); }, d);
}

std::size_t detect_unchecked(AnyDetector& d, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return std::visit([&](auto& det) { return detect_unchecked(det, events, is_corner); }, d);
}

bool has_score(const AnyDetector& d) noexcept {
    return std::visit([](const auto& det) { return ScoredDetector<std::decay_t<decltype(det)>>; }, d);
}

std::size_t memory_bytes(const AnyDetector& d) noexcept {
    return std::visit([](const auto& det) { return det.memory_bytes(); }, d);
}

}  // namespace evcorner
