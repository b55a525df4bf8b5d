#include "evcorner/sim/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace evcorner::sim {

double signed_area(std::span<const Vec2> poly) noexcept {
    double a = 0;
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Vec2 p = poly[i], q = poly[(i + 1) % n];
        a += p.x * q.y - q.x * p.y;
    }
    return a / 2;
}

namespace {
double cross(Vec2 o, Vec2 a, Vec2 b) noexcept { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }
bool on_segment(Vec2 p, Vec2 q, Vec2 r) noexcept {  // r collinear with pq: within its box?
    return std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) && std::min(p.y, q.y) <= r.y && r.y <= std::max(p.y, q.y);
}
bool segments_touch(Vec2 a, Vec2 b, Vec2 c, Vec2 d) noexcept {
    const double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
    if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
    return (d1 == 0 && on_segment(c, d, a)) || (d2 == 0 && on_segment(c, d, b)) || (d3 == 0 && on_segment(a, b, c)) ||
           (d4 == 0 && on_segment(a, b, d));
}
}  // namespace

std::optional<std::pair<std::size_t, std::size_t>> first_self_intersection(std::span<const Vec2> poly) noexcept {
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j) {
            const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
            const Vec2 a = poly[i], b = poly[(i + 1) % n], c = poly[j], d = poly[(j + 1) % n];
            if (adjacent) {
                // Adjacent edges share one vertex; they may not fold back onto each other.
                const Vec2 shared = j == i + 1 ? b : a;
                const Vec2 u = j == i + 1 ? a : b, v = j == i + 1 ? d : c;
                if (cross(shared, u, v) == 0 && (u.x - shared.x) * (v.x - shared.x) + (u.y - shared.y) * (v.y - shared.y) > 0)
                    return std::pair{i, j};
                continue;
            }
            if (segments_touch(a, b, c, d)) return std::pair{i, j};
        }
    return std::nullopt;
}

double interior_angle_deg(Vec2 prev, Vec2 v, Vec2 next) noexcept {
    const double e1x = prev.x - v.x, e1y = prev.y - v.y, e2x = next.x - v.x, e2y = next.y - v.y;
    double a = std::atan2(e2x * e1y - e2y * e1x, e2x * e1x + e2y * e1y) * 180.0 / std::numbers::pi;
    if (a <= 0) a += 360.0;
    return a;
}

bool inside(std::span<const Vec2> poly, Vec2 p) noexcept {
    bool in = false;
    const std::size_t n = poly.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
        const Vec2 a = poly[i], b = poly[j];
        if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x) in = !in;
    }
    return in;
}

}  // namespace evcorner::sim
