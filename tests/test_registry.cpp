// The registry (registry.hpp): every entry builds, says what its state takes, takes its
// parameters by key with their defaults and ranges, refuses what it does not take with a
// message naming the detector and the key; the run-time view agrees with the types.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "evcorner/registry.hpp"

namespace evcorner {
namespace {

std::vector<Event> random_events(SensorSize s, std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<Event> ev;
    std::int64_t t = 0;
    for (std::size_t i = 0; i < n; ++i) {
        t += static_cast<std::int64_t>(rng() % 4);
        ev.push_back({t, static_cast<std::uint16_t>(rng() % static_cast<unsigned>(s.width)),
                      static_cast<std::uint16_t>(rng() % static_cast<unsigned>(s.height)), static_cast<std::uint8_t>(rng() & 1)});
    }
    return ev;
}

std::vector<std::uint8_t> flags_of(AnyDetector d, const std::vector<Event>& ev) {
    std::vector<std::uint8_t> f(ev.size());
    detect(d, std::span<const Event>(ev), f);
    return f;
}

std::string message_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "(no exception)";
}

TEST(Registry, TheVariantHoldsEveryEntryInOrder) {
    ASSERT_EQ(std::variant_size_v<AnyDetector>, detector_infos().size());
    std::set<std::string_view> names;
    for (const DetectorInfo& d : detector_infos()) {
        EXPECT_TRUE(names.insert(d.name).second) << "two entries named " << d.name;
        EXPECT_FALSE(d.summary.empty()) << d.name;
        if (!d.local()) {
            EXPECT_FALSE(d.not_local.empty()) << d.name << ": --threads needs a reason to refuse";
        }
    }
    // The paper's three come first (new detectors are added after them).
    EXPECT_EQ(detector_names().rfind("efast, harris, harris-global", 0), 0u) << detector_names();
    std::string joined;
    for (const DetectorInfo& d : detector_infos()) joined += (joined.empty() ? "" : ",") + std::string(d.name);
    EXPECT_EQ(detector_names(","), joined);
}

TEST(Registry, EveryEntryBuildsAndItsStateBytesAreWhatItHolds) {
    for (const SensorSize s : {SensorSize{240, 180}, SensorSize{17, 11}, SensorSize{1280, 720}}) {
        for (const DetectorInfo& info : detector_infos()) {
            SCOPED_TRACE(std::string(info.name));
            const DetectorConfig config{std::string(info.name), {}};
            AnyDetector d = make_detector(config, s);
            EXPECT_EQ(detector_name(d), info.name);
            EXPECT_EQ(has_score(d), info.has_score);
            EXPECT_EQ(detector_state_bytes(config, s), memory_bytes(d));
            EXPECT_GT(memory_bytes(d), 0u);
        }
    }
    // With parameters that change the state's size too.
    ParamValues v;
    v.set("harris-window", std::int64_t{15});
    for (const char* name : {"harris", "harris-global"}) {
        const DetectorConfig c{name, v};
        EXPECT_EQ(detector_state_bytes(c, kDavis240), memory_bytes(make_detector(c, kDavis240))) << name;
        EXPECT_GT(detector_state_bytes(c, kDavis240), detector_state_bytes(name, kDavis240)) << name;
    }
}

TEST(Registry, DefaultsAreTheParamsStructs) {
    const HarrisParams hp;
    const HarrisGlobalParams gp;
    const DetectorInfo& h = detector_info("harris");
    ASSERT_NE(h.param("harris-window"), nullptr);
    EXPECT_EQ(std::get<std::int64_t>(h.param("harris-window")->default_value), hp.window);
    EXPECT_EQ(std::get<std::int64_t>(h.param("harris-nl")->default_value), hp.nl);
    EXPECT_EQ(std::get<double>(h.param("harris-k")->default_value), hp.k);
    EXPECT_EQ(std::get<double>(h.param("harris-threshold")->default_value), hp.threshold);
    EXPECT_EQ(h.param("harris-n"), nullptr);
    const DetectorInfo& g = detector_info("harris-global");
    EXPECT_EQ(std::get<std::int64_t>(g.param("harris-n")->default_value), gp.n);
    EXPECT_EQ(g.param("harris-nl"), nullptr);
    EXPECT_TRUE(detector_info("efast").params.empty());

    // Every parameter set explicitly to its default gives the default detector's flags.
    const auto ev = random_events({64, 48}, 60000, 5);
    for (const DetectorInfo& info : detector_infos()) {
        DetectorConfig c{std::string(info.name), {}};
        for (const ParamInfo& p : info.params) c.params.set(p.key, p.default_value);
        EXPECT_EQ(flags_of(make_detector(c, {64, 48}), ev), flags_of(make_detector(info.name, {64, 48}), ev)) << info.name;
    }
}

TEST(Registry, ParametersReachTheDetector) {
    DetectorConfig c{"harris", {}};
    c.params.set("harris-window", std::int64_t{11});
    c.params.set("harris-nl", std::int64_t{40});
    c.params.set("harris-k", 0.05);
    c.params.set("harris-threshold", std::int64_t{3});  // an integer for a real parameter
    const AnyDetector d = make_detector(c, kDavis240);
    const HarrisParams& p = std::get<Harris>(d).params();
    EXPECT_EQ(p.window, 11);
    EXPECT_EQ(p.nl, 40);
    EXPECT_EQ(p.k, 0.05);
    EXPECT_EQ(p.threshold, 3.0);
    // One shared key reaches each detector that takes it.
    const DetectorConfig g = config_for("harris-global", c.params);
    EXPECT_EQ(g.params.size(), 3u);  // harris-nl is harris's only
    EXPECT_EQ(std::get<HarrisGlobal>(make_detector(g, kDavis240)).params().window, 11);
    // An integral real value is an integer.
    c.params.set("harris-window", 7.0);
    EXPECT_EQ(std::get<Harris>(make_detector(c, kDavis240)).params().window, 7);
}

TEST(Registry, RangesAreEnforcedWithTheKeyInTheMessage) {
    int checked = 0;
    for (const DetectorInfo& info : detector_infos())
        for (const ParamInfo& p : info.params) {
            if (p.type == ParamType::boolean) continue;
            SCOPED_TRACE(std::string(info.name) + " " + std::string(p.key));
            auto config = [&](double v) {
                DetectorConfig c{std::string(info.name), {}};
                if (p.type == ParamType::integer)
                    c.params.set(p.key, static_cast<std::int64_t>(v));
                else
                    c.params.set(p.key, v);
                return c;
            };
            const double step = p.type == ParamType::integer ? 1.0 : 1e-6 * std::max(1.0, std::fabs(p.max));
            if (std::isfinite(p.min)) {
                EXPECT_NO_THROW(check_detector_config(config(p.min)));
                const std::string m = message_of([&] { check_detector_config(config(p.min - step), "--"); });
                EXPECT_NE(m.find("--" + std::string(p.key) + " must be within"), std::string::npos) << m;
                ++checked;
            }
            if (std::isfinite(p.max)) {
                EXPECT_NO_THROW(check_detector_config(config(p.max)));
                const std::string m = message_of([&] { check_detector_config(config(p.max + step)); });
                EXPECT_NE(m.find(std::string(p.key) + " must be within"), std::string::npos) << m;
                ++checked;
            }
            if (p.type == ParamType::real) {
                const std::string m = message_of([&] { check_detector_config(config(std::nan(""))); });
                EXPECT_NE(m.find(std::string(p.key)), std::string::npos) << m;
            }
        }
    EXPECT_GE(checked, 6);  // harris-window (x2), harris-nl, harris-n: both ends
    // The detector's own checks of what depends on two parameters still apply.
    DetectorConfig c{"harris", {}};
    c.params.set("harris-nl", std::int64_t{100});  // > 9 x 9
    const std::string m = message_of([&] { (void)make_detector(c, kDavis240); });
    EXPECT_NE(m.find("81"), std::string::npos) << m;
}

TEST(Registry, TypesAreEnforced) {
    DetectorConfig c{"harris", {}};
    c.params.set("harris-window", 9.5);
    EXPECT_NE(message_of([&] { check_detector_config(c); }).find("harris-window takes an integer"), std::string::npos);
    c.params.set("harris-window", true);
    EXPECT_NE(message_of([&] { check_detector_config(c); }).find("harris-window takes an integer"), std::string::npos);
    c.params.set("harris-window", std::int64_t{9});
    c.params.set("harris-k", false);
    EXPECT_NE(message_of([&] { check_detector_config(c); }).find("harris-k takes a number"), std::string::npos);

    EXPECT_EQ(std::get<std::int64_t>(parse_param_value("harris-window", "11")), 11);
    EXPECT_EQ(std::get<double>(parse_param_value("harris-k", "0.05")), 0.05);
    EXPECT_EQ(std::get<double>(parse_param_value("harris-k", "1e-2")), 0.01);
    for (const char* bad : {"", "11x", "1.5", " 3"})
        EXPECT_NE(message_of([&] { (void)parse_param_value("harris-window", bad); }).find("harris-window"),
                  std::string::npos)
            << bad;
    EXPECT_THROW((void)parse_param_value("harris-k", "nan"), std::invalid_argument);
    EXPECT_THROW((void)parse_param_value("harris-k", "inf"), std::invalid_argument);
    // A binding's keyword argument names the key as an identifier.
    EXPECT_EQ(param_key("harris_window"), "harris-window");
    EXPECT_NE(detector_info("harris").param(param_key("harris_nl")), nullptr);
    ParamValues v;
    parse_param_assignment("harris-window=13", v);
    EXPECT_EQ(std::get<std::int64_t>(*v.find("harris-window")), 13);
    EXPECT_THROW(parse_param_assignment("harris-window", v), std::invalid_argument);
    EXPECT_THROW(parse_param_assignment("=3", v), std::invalid_argument);
}

TEST(Registry, UnknownNamesAndKeysAreNamed) {
    EXPECT_EQ(message_of([] { (void)make_detector("fast", kDavis240); }),
              "unknown detector 'fast' (known: " + detector_names() + ")");
    EXPECT_EQ(message_of([] { (void)detector_info("nope"); }), "unknown detector 'nope' (known: " + detector_names() + ")");
    EXPECT_NE(detector_names().find("harris-global"), std::string::npos);

    DetectorConfig c{"efast", {}};
    c.params.set("harris-window", std::int64_t{9});
    EXPECT_EQ(message_of([&] { check_detector_config(c, "--"); }),
              "detector 'efast' takes no parameter --harris-window (it takes none)");
    c.name = "harris";
    c.params.set("harris-n", std::int64_t{9});
    EXPECT_EQ(message_of([&] { check_detector_config(c); }),
              "detector 'harris' takes no parameter harris-n (it takes: harris-window, harris-nl, harris-k, "
              "harris-threshold)");
    const std::string m = message_of([] { (void)parse_param_value("no-such-key", "true"); });
    EXPECT_NE(m.find("unknown parameter no-such-key (known: harris-window"), std::string::npos) << m;

    // Commands running several detectors: a key none of them takes.
    ParamValues v;
    v.set("harris-nl", std::int64_t{20});
    const std::vector<std::string> both{"efast", "harris-global"};
    EXPECT_NE(message_of([&] { check_params_taken(both, v, "--"); }).find("--harris-nl"), std::string::npos);
    const std::vector<std::string> with_harris{"efast", "harris"};
    EXPECT_NO_THROW(check_params_taken(with_harris, v));
}

TEST(Registry, SharedKeysHaveOneType) {
    const std::vector<ParamKeyInfo> keys = parameter_keys();
    std::set<std::string_view> seen;
    for (const ParamKeyInfo& k : keys) {
        EXPECT_TRUE(seen.insert(k.key).second) << k.key;
        ASSERT_EQ(k.detectors.size(), k.defaults.size());
        for (const auto& d : k.detectors) EXPECT_EQ(detector_info(d).param(k.key)->type, k.type) << k.key << " " << d;
    }
    const auto window = std::find_if(keys.begin(), keys.end(), [](const auto& k) { return k.key == "harris-window"; });
    ASSERT_NE(window, keys.end());
    EXPECT_EQ(window->detectors, (std::vector<std::string_view>{"harris", "harris-global", "fa-harris", "efast-harris"}));
}

TEST(Registry, LocalityComesFromTheEntries) {
    EXPECT_EQ(detector_radius({"efast", {}}), kCircleMargin);
    EXPECT_EQ(detector_radius({"harris", {}}), 4);
    ParamValues v;
    v.set("harris-window", std::int64_t{13});
    EXPECT_EQ(detector_radius({"harris", v}), 6);
    EXPECT_EQ(detector_radius({"harris-global", {}}), std::nullopt);
    EXPECT_EQ(detector_info("efast").split, Split::by_polarity);
    EXPECT_EQ(detector_info("harris").split, Split::by_polarity);
    EXPECT_FALSE(detector_info("harris-global").local());
}

TEST(Registry, WithDetectorEntryHandsTheConcreteType) {
    const bool efast_is_efast = with_detector_entry("efast", [](const auto& e) {
        return std::is_same_v<typename std::remove_cvref_t<decltype(e)>::Detector, EFast>;
    });
    EXPECT_TRUE(efast_is_efast);
    EXPECT_THROW(with_detector_entry("x", [](const auto&) { return 0; }), std::invalid_argument);
    int visited = 0;
    for_each_detector_entry([&](const auto&) { ++visited; });
    EXPECT_EQ(static_cast<std::size_t>(visited), detector_infos().size());
}

}  // namespace
}  // namespace evcorner
