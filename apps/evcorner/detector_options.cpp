#include "detector_options.hpp"

#include <fmt/format.h>
#include <memory>
#include <stdexcept>

#include "evcorner/registry.hpp"

namespace evcorner::cli {

namespace {

std::string range_text(const ParamInfo& p) {
    if (p.type == ParamType::boolean) return "true/false";
    const bool lo = std::isfinite(p.min), hi = std::isfinite(p.max);
    if (!lo && !hi) return p.type == ParamType::integer ? "an integer" : "a number";
    if (!hi) return ">= " + format_param_value(p.type == ParamType::integer ? ParamValue(static_cast<std::int64_t>(p.min)) : ParamValue(p.min));
    auto v = [&](double x) {
        return format_param_value(p.type == ParamType::integer ? ParamValue(static_cast<std::int64_t>(x)) : ParamValue(x));
    };
    if (!lo) return "<= " + v(p.max);
    return v(p.min) + ".." + v(p.max);
}

void set_once(ParamValues& values, const std::string& key, ParamValue v) {
    if (values.contains(key)) throw std::invalid_argument("parameter " + key + " given twice (--" + key + " or -p)");
    values.set(key, v);
}

}  // namespace

std::string detectors_help() {
    std::string s;
    for (const DetectorInfo& d : detector_infos()) {
        s += fmt::format("\n  {:<14} {}", d.name, d.summary);
        std::string extras;
        if (d.has_score) extras += "has a score (--with-score)";
        if (!extras.empty()) extras += "; ";
        extras += d.local() ? (d.split == Split::by_polarity ? "--threads: split by polarity" : "--threads: split by rows")
                            : "one thread only";
        std::string keys;
        for (const ParamInfo& p : d.params) keys += (keys.empty() ? "" : " ") + ("--" + std::string(p.key));
        s += fmt::format("\n  {:<14}   {}{}", "", extras, keys.empty() ? "" : "; parameters " + keys);
    }
    return s;
}

CLI::Option* add_detector_option(CLI::App& cmd, std::string& name, const std::string& help) {
    return cmd.add_option("-d,--detector", name, help)->capture_default_str()->check([](const std::string& n) {
        for (const DetectorInfo& d : detector_infos())
            if (d.name == n) return std::string();
        return "unknown detector '" + n + "' (known: " + detector_names() + ")";
    });
}

void add_param_options(CLI::App& cmd, ParamValues& values) {
    const std::string group = "Detector parameters";
    for (const ParamKeyInfo& k : parameter_keys()) {
        const std::string key(k.key);
        // Help: the first detector's text, then per detector its range and default.
        std::string help(k.help);
        std::string per;
        for (std::size_t i = 0; i < k.detectors.size(); ++i) {
            const ParamInfo* p = detector_info(k.detectors[i]).param(k.key);
            per += fmt::format("{}{}: {}, default {}", per.empty() ? "" : "; ", k.detectors[i], range_text(*p),
                               format_param_value(k.defaults[i]));
        }
        help += " [" + per + "]";
        CLI::Option* opt = nullptr;
        switch (k.type) {
            case ParamType::integer:
                opt = cmd.add_option_function<std::int64_t>(
                    "--" + key, [&values, key](const std::int64_t& v) { set_once(values, key, v); }, help);
                opt->type_name("INT");
                break;
            case ParamType::real:
                opt = cmd.add_option_function<double>("--" + key, [&values, key](const double& v) { set_once(values, key, v); },
                                                      help);
                opt->type_name("NUMBER");
                break;
            case ParamType::boolean:
                opt = cmd.add_option_function<std::string>(
                    "--" + key, [&values, key](const std::string& v) { set_once(values, key, parse_param_value(key, v, "--")); },
                    help);
                opt->type_name("true|false");
                break;
        }
        opt->group(group);
    }
    cmd.add_option_function<std::vector<std::string>>(
           "-p,--param",
           [&values](const std::vector<std::string>& list) {
               for (const std::string& a : list) {
                   ParamValues one;
                   parse_param_assignment(a, one);
                   for (const auto& [key, v] : one) set_once(values, key, v);
               }
           },
           "A detector parameter as KEY=VALUE (the same keys as the options above, without --); repeatable")
        ->type_name("KEY=VALUE")
        ->group(group);
}

std::vector<std::string> parse_detector_list(const std::string& list) {
    std::vector<std::string> out;
    std::size_t at = 0;
    while (at <= list.size()) {
        const std::size_t comma = std::min(list.find(',', at), list.size());
        const std::string name = list.substr(at, comma - at);
        at = comma + 1;
        if (name.empty()) continue;
        if (name == "all") {
            for (const DetectorInfo& d : detector_infos()) out.emplace_back(d.name);
            continue;
        }
        (void)detector_info(name);  // unknown names throw
        out.push_back(name);
    }
    if (out.empty()) throw std::invalid_argument("-d: no detector named");
    // Each detector once, in the order first named.
    std::vector<std::string> unique;
    for (const auto& n : out)
        if (std::find(unique.begin(), unique.end(), n) == unique.end()) unique.push_back(n);
    return unique;
}

std::string all_detectors_list() { return detector_names(","); }

void add_nms_options(CLI::App& cmd, bool& on, NmsParams& params, std::string& rule, CLI::Option* enabler) {
    const char* group = "Non-maximum suppression";
    CLI::Option* nms = cmd.add_flag("--nms", on,
                 "Asynchronous non-maximum suppression after the detector (docs/nms.md): a corner is dropped "
                 "when an earlier corner of its polarity within --nms-radius px and --nms-time us has an equal or "
                 "larger score (rule window) or an equal or larger decayed score (rule decay); decided at the "
                 "corner's own time from the past only. Every detector has a score (docs/scores.md)")
        ->group(group);
    cmd.add_option("--nms-rule", rule, "window (a hard time window) or decay (scores decayed by exp(-dt/time))")
        ->capture_default_str()
        ->check(CLI::IsMember({"window", "decay"}))
        ->group(group);
    cmd.add_option("--nms-radius", params.radius, "Neighbourhood half side in px (a (2r+1)^2 square)")
        ->capture_default_str()
        ->check(CLI::Range(0, NmsParams::kMaxRadius))
        ->group(group);
    cmd.add_option("--nms-time", params.time_us, "Time window (rule window) or decay constant (rule decay), us")
        ->capture_default_str()
        ->check(CLI::Range(std::int64_t{1}, NmsParams::kMaxTimeUs))
        ->group(group);
    // The --nms-* options change nothing unless NMS runs.
    const std::string needed = enabler ? "--nms or " + enabler->get_name() : std::string("--nms");
    cmd.parse_complete_callback([&cmd, nms, enabler, needed] {
        if (nms->count() > 0 || (enabler && enabler->count() > 0)) return;
        for (const char* name : {"--nms-rule", "--nms-radius", "--nms-time"})
            if (cmd.count(name) > 0)
                throw CLI::ValidationError(std::string(name) + ": does nothing without " + needed);
    });
}

}  // namespace evcorner::cli
