#include "evcorner/sim/scene.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "evcorner/error.hpp"
#include "evcorner/sim/geometry.hpp"
#include "evcorner/sim/motion.hpp"

namespace evcorner::sim {

std::int64_t Scene::duration_us() const noexcept { return std::llround(duration_s * 1e6); }

namespace {

using json = nlohmann::json;

// A JSON value with the pointer that reached it, for errors that name the key.
class Node {
public:
    Node(const json& j, std::string path, const std::string& source) : j_(j), path_(std::move(path)), source_(source) {}

    [[noreturn]] void fail(const std::string& why) const {
        throw InputError(source_, (path_.empty() ? std::string("/") : path_) + ": " + why);
    }
    [[nodiscard]] const json& value() const noexcept { return j_; }
    [[nodiscard]] const std::string& path() const noexcept { return path_; }

    [[nodiscard]] bool has(const char* key) const { return j_.is_object() && j_.contains(key); }
    [[nodiscard]] Node at(const char* key) const {
        if (!has(key)) fail(std::string("missing key \"") + key + "\"");
        return {j_.at(key), path_ + "/" + key, source_};
    }
    [[nodiscard]] Node at(std::size_t i) const { return {j_.at(i), path_ + "/" + std::to_string(i), source_}; }

    void object_with(std::initializer_list<const char*> allowed) const {
        if (!j_.is_object()) fail("expected an object, got " + type());
        for (auto it = j_.begin(); it != j_.end(); ++it) {
            bool ok = false;
            for (const char* k : allowed) ok = ok || it.key() == k;
            if (!ok) {
                std::string list;
                for (const char* k : allowed) list += (list.empty() ? "" : ", ") + std::string(k);
                Node(it.value(), path_ + "/" + escape(it.key()), source_).fail("unknown key (known here: " + list + ")");
            }
        }
    }
    [[nodiscard]] std::size_t array(std::size_t min_size, std::size_t max_size = SIZE_MAX) const {
        if (!j_.is_array()) fail("expected an array, got " + type());
        if (j_.size() < min_size || j_.size() > max_size) {
            if (min_size == max_size) fail("expected " + std::to_string(min_size) + " elements, got " + std::to_string(j_.size()));
            fail("expected at least " + std::to_string(min_size) + " elements, got " + std::to_string(j_.size()));
        }
        return j_.size();
    }
    [[nodiscard]] double number(double lo, double hi) const {
        if (!j_.is_number()) fail("expected a number, got " + type());
        const double v = j_.get<double>();
        if (!std::isfinite(v) || v < lo || v > hi) fail(fmt_range(v, lo, hi));
        return v;
    }
    [[nodiscard]] std::int64_t integer(std::int64_t lo, std::int64_t hi) const {
        if (!j_.is_number_integer()) fail("expected an integer, got " + type());
        if (j_.is_number_unsigned() && j_.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX))
            fail("out of range");
        const std::int64_t v = j_.get<std::int64_t>();
        if (v < lo || v > hi) fail(fmt_range(static_cast<double>(v), static_cast<double>(lo), static_cast<double>(hi)));
        return v;
    }
    [[nodiscard]] Vec2 point(double lim) const {
        (void)array(2, 2);
        return {at(std::size_t{0}).number(-lim, lim), at(1).number(-lim, lim)};
    }

private:
    [[nodiscard]] std::string type() const {
        std::string t = j_.type_name();
        return t;
    }
    static std::string fmt_range(double v, double lo, double hi) {
        std::ostringstream s;
        s.precision(10);
        s << v << " is out of range [" << lo << ", " << hi << "]";
        return s.str();
    }
    // A key as a JSON pointer token, non-printable bytes escaped.
    static std::string escape(const std::string& key) {
        std::string out;
        for (const unsigned char c : key) {
            if (c == '~') out += "~0";
            else if (c == '/') out += "~1";
            else if (c < 0x20 || c >= 0x7f) {
                char buf[8];
                std::snprintf(buf, sizeof buf, "\\x%02x", c);
                out += buf;
            } else out += static_cast<char>(c);
        }
        return out;
    }
    const json& j_;
    std::string path_;
    const std::string& source_;
};

constexpr double kCoordLimit = 1e6;  // px: far beyond any sensor, small enough for exact-ish doubles

CameraParams parse_camera(const Node& n) {
    n.object_with({"contrast", "contrast_sigma", "refractory_us", "noise_hz", "hot_pixels"});
    CameraParams c;
    if (n.has("contrast")) c.contrast = n.at("contrast").number(0.01, 5.0);
    if (n.has("contrast_sigma")) c.contrast_sigma = n.at("contrast_sigma").number(0.0, 1.0);
    if (n.has("refractory_us")) c.refractory_us = n.at("refractory_us").number(0.0, 1e7);
    if (n.has("noise_hz")) c.noise_hz = n.at("noise_hz").number(0.0, 1e4);
    if (n.has("hot_pixels")) {
        const Node h = n.at("hot_pixels");
        h.object_with({"count", "rate_hz"});
        c.hot_pixels = static_cast<int>(h.at("count").integer(0, 1000000));
        c.hot_pixel_hz = h.at("rate_hz").number(0.0, 1e6);
    }
    return c;
}

Background parse_background(const Node& n) {
    Background b;
    if (n.value().is_number()) {
        b.intensity = n.number(0.0, 1.0);
        return b;
    }
    n.object_with({"texture"});
    const Node t = n.at("texture");
    t.object_with({"mean", "amplitude", "scale_px", "octaves"});
    b.textured = true;
    b.intensity = t.at("mean").number(0.0, 1.0);
    b.amplitude = t.at("amplitude").number(0.0, 1.0);
    if (t.has("scale_px")) b.scale_px = t.at("scale_px").number(1.0, 1e4);
    if (t.has("octaves")) b.octaves = static_cast<int>(t.at("octaves").integer(1, 8));
    return b;
}

SpeedProfile parse_profile(const Node& n) {
    SpeedProfile p;
    if (n.value().is_string()) {
        const std::string s = n.value().get<std::string>();
        if (s == "constant") return p;
        if (s == "ramp") {
            p.ramp = true;
            return p;
        }
        n.fail("unknown profile (known: \"constant\", \"ramp\", or {\"ramp\": {\"from\": F, \"to\": T}})");
    }
    n.object_with({"ramp"});
    const Node r = n.at("ramp");
    r.object_with({"from", "to"});
    p.ramp = true;
    if (r.has("from")) p.from = r.at("from").number(0.0, 100.0);
    if (r.has("to")) p.to = r.at("to").number(0.0, 100.0);
    return p;
}

Motion parse_motion(const Node& n, Vec2 default_center) {
    n.object_with({"velocity", "rotation_deg_s", "center", "scaling_per_s", "profile"});
    Motion m;
    m.center = default_center;
    if (n.has("velocity")) m.velocity = n.at("velocity").point(1e6);
    if (n.has("rotation_deg_s")) m.rotation_deg_s = n.at("rotation_deg_s").number(-1e6, 1e6);
    if (n.has("center")) m.center = n.at("center").point(kCoordLimit);
    if (n.has("scaling_per_s")) m.scaling_per_s = n.at("scaling_per_s").number(-100.0, 100.0);
    if (n.has("profile")) m.profile = parse_profile(n.at("profile"));
    return m;
}

std::vector<Vec2> parse_polygon(const Node& n) {
    const std::size_t count = n.array(3, 100000);
    std::vector<Vec2> poly;
    poly.reserve(count);
    for (std::size_t i = 0; i < count; ++i) poly.push_back(n.at(i).point(kCoordLimit));
    for (std::size_t i = 0; i < count; ++i) {
        const Vec2 a = poly[i], b = poly[(i + 1) % count];
        if (a.x == b.x && a.y == b.y) n.at(i).fail("repeats the next vertex");
    }
    if (std::abs(signed_area(poly)) < 1e-9) n.fail("has no area");
    if (const auto bad = first_self_intersection(poly))
        n.fail("is not simple: edge " + std::to_string(bad->first) + " crosses edge " + std::to_string(bad->second));
    if (signed_area(poly) < 0) std::reverse(poly.begin(), poly.end());
    return poly;
}

Object parse_object(const Node& n) {
    n.object_with({"polygon", "checkerboard", "intensity", "motion"});
    Object o;
    if (n.has("polygon") == n.has("checkerboard")) n.fail("needs exactly one of \"polygon\" and \"checkerboard\"");
    Vec2 center;
    if (n.has("polygon")) {
        o.kind = "polygon";
        Piece p;
        p.polygon = parse_polygon(n.at("polygon"));
        p.intensity = n.at("intensity").number(0.0, 1.0);
        const std::size_t k = p.polygon.size();
        for (std::size_t i = 0; i < k; ++i) {
            center.x += p.polygon[i].x / static_cast<double>(k);
            center.y += p.polygon[i].y / static_cast<double>(k);
            o.corners.push_back({p.polygon[i], interior_angle_deg(p.polygon[(i + k - 1) % k], p.polygon[i], p.polygon[(i + 1) % k])});
        }
        o.pieces.push_back(std::move(p));
    } else {
        o.kind = "checkerboard";
        const Node c = n.at("checkerboard");
        c.object_with({"origin", "square", "cols", "rows"});
        const Vec2 origin = c.at("origin").point(kCoordLimit);
        const double sq = c.at("square").number(0.5, 1e4);
        const int cols = static_cast<int>(c.at("cols").integer(1, 1000));
        const int rows = static_cast<int>(c.at("rows").integer(1, 1000));
        const Node in = n.at("intensity");
        if (!in.value().is_array()) in.fail("a checkerboard takes two intensities [first, second]");
        (void)in.array(2, 2);
        const double ia = in.at(std::size_t{0}).number(0.0, 1.0), ib = in.at(1).number(0.0, 1.0);
        for (int r = 0; r < rows; ++r)
            for (int q = 0; q < cols; ++q) {
                const double x0 = origin.x + q * sq, y0 = origin.y + r * sq;
                Piece p;
                p.polygon = {{x0, y0}, {x0 + sq, y0}, {x0 + sq, y0 + sq}, {x0, y0 + sq}};
                p.intensity = (r + q) % 2 == 0 ? ia : ib;
                o.pieces.push_back(std::move(p));
            }
        for (int r = 0; r <= rows; ++r)
            for (int q = 0; q <= cols; ++q) o.corners.push_back({{origin.x + q * sq, origin.y + r * sq}, 90.0});
        center = {origin.x + cols * sq / 2, origin.y + rows * sq / 2};
    }
    o.motion = n.has("motion") ? parse_motion(n.at("motion"), center) : Motion{{}, 0, center, 0, {}};
    return o;
}

SimulationParams parse_simulation(const Node& n) {
    n.object_with({"step_fraction", "max_step_us", "min_step_us"});
    SimulationParams s;
    if (n.has("step_fraction")) s.step_fraction = n.at("step_fraction").number(0.01, 1.0);
    if (n.has("max_step_us")) s.max_step_us = n.at("max_step_us").number(1.0, 1e6);
    if (n.has("min_step_us")) s.min_step_us = n.at("min_step_us").number(0.01, 1e6);
    if (s.min_step_us > s.max_step_us) n.at("min_step_us").fail("is larger than max_step_us");
    return s;
}

}  // namespace

Scene parse_scene(std::string_view text, const std::string& source) {
    json j;
    try {
        j = json::parse(text.begin(), text.end());
    } catch (const json::parse_error& e) {
        // e.byte is 1-based, the byte after the error; report the 0-based offset of the bad byte.
        const std::uint64_t at = e.byte > 0 ? e.byte - 1 : 0;
        std::string what = e.what();
        // nlohmann's message: "[json.exception.parse_error.101] parse error at line L, column C: ..."
        const auto colon = what.find(": ");
        throw InputError(source, InputError::Unit::byte, at,
                         "JSON syntax error" + (colon == std::string::npos ? std::string() : what.substr(colon)));
    }
    const Node root(j, "", source);
    root.object_with({"sensor", "duration_s", "seed", "camera", "background", "objects", "simulation", "name", "description"});
    Scene s;
    const Node sensor = root.at("sensor");
    (void)sensor.array(2, 2);
    s.sensor.width = static_cast<int>(sensor.at(std::size_t{0}).integer(1, kMaxSensorSide));
    s.sensor.height = static_cast<int>(sensor.at(1).integer(1, kMaxSensorSide));
    s.duration_s = root.at("duration_s").number(1e-6, 3600.0);
    if (root.has("seed")) s.seed = static_cast<std::uint64_t>(root.at("seed").integer(0, INT64_MAX));
    if (root.has("camera")) s.camera = parse_camera(root.at("camera"));
    if (s.camera.hot_pixels > s.sensor.pixels()) root.at("camera").at("hot_pixels").at("count").fail("exceeds the sensor's pixels");
    if (root.has("background")) s.background = parse_background(root.at("background"));
    if (root.has("simulation")) s.simulation = parse_simulation(root.at("simulation"));
    if (root.has("name") && !root.at("name").value().is_string()) root.at("name").fail("expected a string");
    if (root.has("description") && !root.at("description").value().is_string()) root.at("description").fail("expected a string");
    const Node objects = root.at("objects");
    const std::size_t n = objects.array(0, 100000);
    for (std::size_t i = 0; i < n; ++i) {
        Object o = parse_object(objects.at(i));
        // The scale must stay positive: s(tau) = 1 + scaling tau over the whole motion time.
        const double tau_end = motion_time(o.motion.profile, s.duration_s, s.duration_s);
        if (1.0 + o.motion.scaling_per_s * tau_end < 0.01)
            objects.at(i).at("motion").at("scaling_per_s").fail("shrinks the object to nothing before the end");
        s.objects.push_back(std::move(o));
    }
    return s;
}

Scene load_scene_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "cannot open: " + std::string(std::strerror(errno)));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw InputError(path, "read failed");
    return parse_scene(text, path);
}

}  // namespace evcorner::sim
