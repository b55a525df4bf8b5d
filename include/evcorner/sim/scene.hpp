#pragma once
// A scene for the event-camera simulator: a sensor, a camera, a static background and
// moving objects with analytically known corners. Read from JSON (docs/simulate.md lists
// every key); validated once here, so the simulator never meets a bad value.
//
// Geometry: pixel (x, y) is the unit square [x, x+1) x [y, y+1) of the image plane, x to the
// right, y down; positions are in pixels, time in seconds in the file and microseconds inside.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/sensor.hpp"

namespace evcorner::sim {

struct Vec2 {
    double x = 0;
    double y = 0;
};

/// The camera's pixel model (ESIM / v2e style, docs/simulate.md).
struct CameraParams {
    double contrast = 0.25;       ///< C: log-intensity step per event
    double contrast_sigma = 0.0;  ///< per-pixel spread of C (normal, drawn once per pixel and polarity)
    double refractory_us = 0.0;   ///< a pixel emits nothing for this long after an event
    double noise_hz = 0.0;        ///< background activity, Poisson, per pixel
    int hot_pixels = 0;           ///< pixels (drawn at random) firing ON events at hot_pixel_hz
    double hot_pixel_hz = 0.0;
};

/// Intensity of the static background: uniform, or a seeded value-noise texture.
struct Background {
    double intensity = 0.5;  ///< uniform level, or the texture's mean
    bool textured = false;
    double amplitude = 0.0;  ///< texture: largest deviation from the mean
    double scale_px = 16.0;  ///< texture: size of its coarsest blobs
    int octaves = 3;         ///< texture: finer layers, each half the size and half the amplitude
};

/// How fast an object's motion runs over the sequence: the motion below is evaluated at the
/// motion time tau(t) = integral of factor(t) dt, factor(t) = from + (to - from) t / duration
/// for a ramp, 1 for constant.
struct SpeedProfile {
    bool ramp = false;
    double from = 0.0;
    double to = 1.0;
};

/// Similarity motion about `center` (a point of the object, moving with it):
/// p(tau) = center + velocity tau + s(tau) R(rotation tau) (p0 - center), s(tau) = 1 + scaling tau.
struct Motion {
    Vec2 velocity;              ///< px/s
    double rotation_deg_s = 0;  ///< positive turns +x towards +y (clockwise on screen, y down)
    Vec2 center;                ///< rotation and scaling centre at t = 0 (default: the vertices' mean)
    double scaling_per_s = 0;   ///< scale grows by this much per second of motion time
    SpeedProfile profile;
};

/// One uniformly bright simple polygon (convex or not) of an object.
struct Piece {
    std::vector<Vec2> polygon;  ///< vertices at t = 0, reordered on loading to a positive shoelace area
    double intensity = 0.0;
};

/// A truth corner of an object: a point of its pieces, with its interior angle.
struct CornerDef {
    Vec2 position;     ///< at t = 0
    double angle_deg;  ///< interior angle of the polygon at the vertex (> 180 for a reflex vertex)
};

/// An object: a polygon, or a checkerboard (its squares as pieces, which never overlap).
/// Objects later in the list are in front.
struct Object {
    std::string kind;  ///< "polygon" or "checkerboard"
    std::vector<Piece> pieces;
    std::vector<CornerDef> corners;
    Motion motion;
};

/// Numerical settings of the simulation (rarely changed).
struct SimulationParams {
    double step_fraction = 0.5;   ///< no pixel's log intensity changes by more than this times C between two of its samples
    double max_step_us = 1000.0;  ///< longest step (between two renders of the whole image)
    double min_step_us = 1.0;     ///< shortest step or pixel sample interval (the fraction may be exceeded only at this size)
};

struct Scene {
    SensorSize sensor{240, 180};
    double duration_s = 1.0;
    std::uint64_t seed = 0;
    CameraParams camera;
    Background background;
    std::vector<Object> objects;
    SimulationParams simulation;

    [[nodiscard]] std::int64_t duration_us() const noexcept;
};

/// Parses and validates a scene. `source` names it in errors: InputError
/// "SOURCE: /objects/2/polygon/1: reason" (the JSON pointer of the bad key), or
/// "SOURCE: byte N: JSON syntax error ..." for text that is not JSON.
Scene parse_scene(std::string_view json_text, const std::string& source);
/// Reads and parses a scene file (InputError naming the file).
Scene load_scene_file(const std::string& path);

}  // namespace evcorner::sim
