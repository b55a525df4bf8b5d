#include "evcorner/track/track_seed.hpp"

#include <charconv>
#include <cmath>
#include <string>

#include "../io/decimal_time.hpp"
#include "evcorner/io/line_source.hpp"

namespace evcorner {

namespace {

bool parse_real(const char* b, const char* e, double& v) {
    if (b < e && *b == '+') ++b;
    const auto r = std::from_chars(b, e, v);
    return r.ec == std::errc{} && r.ptr == e && std::isfinite(v);
}

}  // namespace

std::vector<TrackSeed> read_seeds_file(const std::string& path) {
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
