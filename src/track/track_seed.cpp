#include "evcorner/track/track_seed.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <set>
#include <string>

#include "../io/decimal_time.hpp"
#include "evcorner/io/line_source.hpp"
#include "evcorner/track/track_file.hpp"

namespace evcorner {

namespace {

bool parse_real(const char* b, const char* e, double& v) {
    if (b < e && *b == '+') ++b;
    const auto r = std::from_chars(b, e, v);
    return r.ec == std::errc{} && r.ptr == e && std::isfinite(v);
}

// Whether the file's first line that is not blank (or a '#' comment) has no comma: a track
// file in the `id t x y` layout rather than HASTE seeds.
bool is_track_file(const std::string& path) {
    io::LineSource src(path);
    const char *b, *e;
    while (src.next(b, e)) {
        while (b < e && (*b == ' ' || *b == '\t')) ++b;
        if (b == e || *b == '#') continue;
        return std::memchr(b, ',', static_cast<std::size_t>(e - b)) == nullptr;
    }
    return false;
}

// Each track's first row, in the order tracks first appear.
std::vector<TrackSeed> seeds_from_tracks(const std::string& path) {
    std::vector<TrackSeed> seeds;
    std::set<std::uint64_t> seen;
    for (const TrackPoint& p : read_track_points(path))
        if (seen.insert(p.id).second)
            seeds.push_back({std::llround(p.t * 1e6), static_cast<float>(p.x), static_cast<float>(p.y), 0.0f, p.id});
    return seeds;
}

}  // namespace

std::vector<TrackSeed> read_seeds_file(const std::string& path) {
    if (path != "-" && is_track_file(path)) return seeds_from_tracks(path);
    io::LineSource src(path);
    std::vector<TrackSeed> seeds;
    const char *b, *e;
    while (src.next(b, e)) {
        const char* p = b;
        for (;;) {
            while (p < e && (*p == ' ' || *p == '\t')) ++p;
            if (p == e) break;
            const char* tok = p;
            while (p < e && *p != ' ' && *p != '\t') ++p;
            // t,x,y,theta[,id]
            const char* f[6];
            int n = 0;
            f[n++] = tok;
            for (const char* c = tok; c < p && n < 6; ++c)
                if (*c == ',') f[n++] = c + 1;
            if (n != 4 && n != 5)
                src.fail(b, e, "a seed is t,x,y,theta or t,x,y,theta,id (" + std::to_string(n) + " fields)");
            const auto end_of = [&](int i) { return i + 1 < n ? f[i + 1] - 1 : p; };
            const io::detail::DecimalTime t = io::detail::parse_decimal_time(f[0], end_of(0), io::TimeUnit::s, false);
            if (t.error) src.fail(b, e, std::string("seed time: ") + t.error);
            double x, y, theta;
            if (!parse_real(f[1], end_of(1), x) || !parse_real(f[2], end_of(2), y) || !parse_real(f[3], end_of(3), theta))
                src.fail(b, e, "seed x, y and theta must be finite numbers");
            std::uint64_t id = 0;
            if (n == 5) {
                const auto r = std::from_chars(f[4], end_of(4), id);
                if (r.ec != std::errc{} || r.ptr != end_of(4)) src.fail(b, e, "seed id must be a whole number >= 0");
            }
            seeds.push_back({t.us, static_cast<float>(x), static_cast<float>(y), static_cast<float>(theta), id});
        }
    }
    return seeds;
}

}  // namespace evcorner
