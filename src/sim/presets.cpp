#include "evcorner/sim/presets.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>

#include "evcorner/sim/random.hpp"

namespace evcorner::sim {

namespace {

using json = nlohmann::json;

json poly(std::initializer_list<std::pair<double, double>> pts, double ox, double oy, double s) {
    json a = json::array();
    for (const auto& [x, y] : pts) a.push_back({ox + s * x, oy + s * y});
    return a;
}

json orbit(double deg_s, double cx, double cy) { return {{"rotation_deg_s", deg_s}, {"center", {cx, cy}}}; }

// Four shapes (a triangle, a square, an L, a pentagon) on a 240x180 layout scaled by `s`,
// each orbiting the sensor's centre or spinning about its own; `k` multiplies every rate.
json shape_objects(double s, double k, const json& profile) {
    const double cx = 120 * s, cy = 90 * s;
    json objs = json::array();
    auto add = [&](json polygon, double intensity, json motion) {
        if (!profile.is_null()) motion["profile"] = profile;
        objs.push_back({{"polygon", std::move(polygon)}, {"intensity", intensity}, {"motion", std::move(motion)}});
    };
    add(poly({{0, 0}, {34, 6}, {10, 30}}, 40 * s, 70 * s, s), 0.12, orbit(40 * k, cx, cy));
    add(poly({{0, 0}, {28, 0}, {28, 28}, {0, 28}}, 160 * s, 40 * s, s), 0.85, orbit(-30 * k, cx, cy));
    add(poly({{0, 0}, {30, 0}, {30, 12}, {12, 12}, {12, 36}, {0, 36}}, 100 * s, 110 * s, s), 0.25,
        {{"rotation_deg_s", 60 * k}, {"velocity", {0, 0}}});
    json pent = json::array();
    for (int i = 0; i < 5; ++i) {
        const double a = 2 * std::numbers::pi * i / 5 - std::numbers::pi / 2;
        pent.push_back({s * (120 + 16 * std::cos(a)), s * (36 + 16 * std::sin(a))});
    }
    add(pent, 0.7, {{"rotation_deg_s", -90 * k}});
    return objs;
}

// A scene with its sensor, duration, seed, name, description and background, seen by the
// usual camera (contrast 0.25, spread 0.03); the caller adds the objects.
json scene(int w, int h, double duration, int seed, const char* name, const char* description, json background) {
    json j = {{"sensor", {w, h}}, {"duration_s", duration}, {"seed", seed}};
    j["name"] = name;
    j["description"] = description;
    j["camera"] = {{"contrast", 0.25}, {"contrast_sigma", 0.03}};
    j["background"] = std::move(background);
    return j;
}

json texture(double mean, double amplitude, double scale) {
    return {{"texture", {{"mean", mean}, {"amplitude", amplitude}, {"scale_px", scale}, {"octaves", 3}}}};
}

json checkerboard(double x, double y, double sq, int cols, int rows, json motion) {
    return {{"checkerboard", {{"origin", {x, y}}, {"square", sq}, {"cols", cols}, {"rows", rows}}},
            {"intensity", {0.15, 0.85}},
            {"motion", std::move(motion)}};
}

// Renders 2.5 ms apart at most (the default is 1 ms): the shapes and polygons move slowly
// (15-120 px/s), so most of their edge pixels keep the step fraction over 2.5 ms and those
// that do not are sampled on their own, for less than the renders saved (docs/simulate.md,
// "Speed"). The busier scenes keep the default: for them the samples would cost more.
json coarse_steps() {
    return {{"max_step_us", 2500}};
}

json scene_shapes() {
    json j = scene(240, 180, 6.0, 1, "shapes",
                   "four shapes (one not convex) orbiting and spinning at 20-90 px/s over a faint texture",
                   texture(0.5, 0.04, 24));
    j["objects"] = shape_objects(1, 1, nullptr);
    j["simulation"] = coarse_steps();
    return j;
}

json scene_checkerboard() {
    json j = scene(240, 180, 6.0, 2, "checkerboard",
                   "a 7x5 checkerboard of 16 px squares turning at 45 deg/s and growing by 5 %/s", 0.5);
    j["objects"] = json::array({checkerboard(64, 50, 16, 7, 5, {{"rotation_deg_s", 45}, {"scaling_per_s", 0.05}})});
    return j;
}

json scene_polygons() {
    json j = scene(240, 180, 6.0, 3, "polygons",
                   "16 random polygons (4-7 vertices, many not convex) orbiting at 15-120 px/s over a strong texture",
                   texture(0.5, 0.25, 12));
    Random rng(3, 0x9017);
    json objs = json::array();
    for (int i = 0; i < 16; ++i) {
        const int n = 4 + static_cast<int>(rng.below(4));
        const double cx = 20 + 200 * rng.uniform(), cy = 15 + 150 * rng.uniform();
        const double radius = 8 + 10 * rng.uniform();
        // A star-shaped polygon: vertices at increasing angles are always simple.
        std::vector<double> angles;
        for (int k = 0; k < n; ++k) angles.push_back(2 * std::numbers::pi * (k + 0.15 + 0.7 * rng.uniform()) / n);
        json p = json::array();
        for (double a : angles) {
            const double r = radius * (0.45 + 0.55 * rng.uniform());
            p.push_back({std::round((cx + r * std::cos(a)) * 1000) / 1000, std::round((cy + r * std::sin(a)) * 1000) / 1000});
        }
        const double w = (rng.uniform() < 0.5 ? -1 : 1) * (20 + 30 * rng.uniform());
        objs.push_back({{"polygon", p},
                        {"intensity", std::round((0.05 + 0.9 * rng.uniform()) * 1000) / 1000},
                        {"motion", orbit(std::round(w * 10) / 10, 120, 90)}});
    }
    j["objects"] = objs;
    j["simulation"] = coarse_steps();
    return j;
}

json scene_ramp() {
    json j = scene(240, 180, 8.0, 4, "ramp",
                   "the shapes and a small checkerboard turning faster and faster: corner speeds ramp from 0 to about "
                   "1000 px/s",
                   texture(0.5, 0.04, 24));
    // The farthest corner (about 85 px from the centre) reaches 1000 px/s at 675 deg/s.
    const json ramp = {{"ramp", {{"from", 0.0}, {"to", 1.0}}}};
    json objs = json::array();
    for (json& o : shape_objects(1, 1, ramp)) {
        o["motion"] = orbit(675, 120, 90);
        o["motion"]["profile"] = ramp;
        objs.push_back(o);
    }
    json board = checkerboard(104, 74, 8, 4, 4, orbit(-675, 120, 90));
    board["motion"]["profile"] = ramp;
    objs.push_back(board);
    j["objects"] = objs;
    return j;
}

json scene_noisy() {
    json j = scene_shapes();
    j["name"] = "noisy";
    j["seed"] = 5;
    j["description"] = "the shapes scene through a poor camera: sigma 0.06, 1 Hz noise per pixel, 300 us refractory, 12 hot pixels";
    j["camera"] = {{"contrast", 0.25},
                   {"contrast_sigma", 0.06},
                   {"refractory_us", 300},
                   {"noise_hz", 1.0},
                   {"hot_pixels", {{"count", 12}, {"rate_hz", 50}}}};
    return j;
}

json scene_hd() {
    json j = scene(1280, 720, 5.0, 6, "hd",
                   "1280x720: the shapes at 4x and a 9x6 checkerboard of 40 px squares, 30-400 px/s, over a texture",
                   texture(0.5, 0.1, 64));
    json objs = shape_objects(4, 1, nullptr);
    // Shift the 960x720 layout to the middle of the wider sensor.
    for (json& o : objs) {
        for (json& v : o["polygon"]) v[0] = v[0].get<double>() + 160;
        if (o["motion"].contains("center")) o["motion"]["center"][0] = o["motion"]["center"][0].get<double>() + 160;
    }
    objs.insert(objs.begin(), checkerboard(840, 420, 40, 9, 6, {{"velocity", {-40, -25}}, {"rotation_deg_s", 12}}));
    j["objects"] = objs;
    return j;
}

json scene_square() {
    json j = scene(240, 180, 0.4, 0, "square",
                   "the analytic test: a 40x40 square of 0.1 on 0.5 moving its own width at 100 px/s; 9600 ON, 9600 OFF",
                   0.5);
    j["camera"] = {{"contrast", 0.25}};  // no contrast spread
    j["objects"] = json::array(
        {{{"polygon", {{60, 70}, {100, 70}, {100, 110}, {60, 110}}}, {"intensity", 0.1}, {"motion", {{"velocity", {100, 0}}}}}});
    return j;
}

struct Entry {
    PresetInfo info;
    json (*make)();
};

const std::vector<Entry>& entries() {
    static const std::vector<Entry> e{
        {{"shapes", "few shapes, low texture (240x180, 6 s)", true}, scene_shapes},
        {{"checkerboard", "a turning, growing checkerboard (240x180, 6 s)", true}, scene_checkerboard},
        {{"polygons", "many polygons on a textured background (240x180, 6 s)", true}, scene_polygons},
        {{"ramp", "speeds ramping up to 1000 px/s (240x180, 8 s)", true}, scene_ramp},
        {{"noisy", "the shapes through a noisy camera (240x180, 6 s)", true}, scene_noisy},
        {{"hd", "shapes and a checkerboard at 1280x720 (5 s)", true}, scene_hd},
        {{"square", "the analytic square of the tests (240x180, 0.4 s)", false}, scene_square},
    };
    return e;
}

}  // namespace

const std::vector<PresetInfo>& presets() {
    static const std::vector<PresetInfo> list = [] {
        std::vector<PresetInfo> l;
        for (const Entry& e : entries()) l.push_back(e.info);
        return l;
    }();
    return list;
}

std::string preset_scene_json(std::string_view name) {
    std::string known;
    for (const Entry& e : entries()) {
        if (e.info.name == name) return e.make().dump(2) + "\n";
        known += (known.empty() ? "" : ", ") + e.info.name;
    }
    throw std::invalid_argument("unknown preset '" + std::string(name) + "' (known: " + known + ")");
}

}  // namespace evcorner::sim
