// AsyncNms (nms.hpp): the per-corner decision over the square neighbourhood.

#include "evcorner/nms.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>

namespace evcorner {

namespace {
constexpr std::int64_t kBias = std::int64_t{1} << 62;
}  // namespace

const char* nms_rule_name(NmsRule r) noexcept { return r == NmsRule::decay ? "decay" : "window"; }

NmsRule parse_nms_rule(std::string_view name) {
    if (name == "window") return NmsRule::window;
    if (name == "decay") return NmsRule::decay;
    throw std::invalid_argument("NMS rule must be window or decay (got '" + std::string(name) + "')");
}

void check_nms_params(const NmsParams& p) {
    if (p.radius < 0 || p.radius > NmsParams::kMaxRadius)
        throw std::invalid_argument("nms radius must be within 0.." + std::to_string(NmsParams::kMaxRadius) + " (got " +
                                    std::to_string(p.radius) + ")");
    if (p.time_us < 1 || p.time_us > NmsParams::kMaxTimeUs)
        throw std::invalid_argument("nms time must be within 1.." + std::to_string(NmsParams::kMaxTimeUs) +
                                    " us (got " + std::to_string(p.time_us) + ")");
    if (p.rule != NmsRule::window && p.rule != NmsRule::decay) throw std::invalid_argument("nms rule unknown");
}

AsyncNms::AsyncNms(SensorSize size, const NmsParams& params, int planes)
    : params_((check_nms_params(params), params)), size_(checked_sensor_size(size, "NMS")),
      planes_(planes == 1 ? 1 : 2), inv_time_(1.0 / static_cast<double>(params.time_us)),
      cells_(2 * static_cast<std::size_t>(planes_) * static_cast<std::size_t>(size.pixels())) {}

bool AsyncNms::keep(const Event& e, double score) noexcept {
    const double s = std::isnan(score) ? -std::numeric_limits<double>::infinity() : score;
    const std::size_t W = static_cast<std::size_t>(size_.width);
    std::int64_t* const times = this->times(e);
    std::int64_t* const scores = score_bits(e);
    const auto score_at = [scores](std::size_t i) { return std::bit_cast<double>(scores[i]); };
    const int r = params_.radius;
    const int x0 = std::max(0, e.x - r), x1 = std::min(size_.width - 1, e.x + r);
    const int y0 = std::max(0, e.y - r), y1 = std::min(size_.height - 1, e.y + r);
    const std::int64_t now = e.t + kBias;
    bool suppressed = false;
    if (params_.rule == NmsRule::window) {
        // dt <= T  <=>  stored tc >= now - T; a never-used cell (0) is older than any:
        // both at once as tc >= max(now - T, 1) (stored times are at least 1).
        const std::int64_t oldest = std::max<std::int64_t>(now - params_.time_us, 1);
        for (int y = y0; y <= y1 && !suppressed; ++y) {
            const std::int64_t* trow = times + static_cast<std::size_t>(y) * W;
            bool recent = false;
            for (int x = x0; x <= x1; ++x) recent |= trow[x] >= oldest;
            if (!recent) continue;  // no corner in the window on this row: its scores unread
            const std::size_t row = static_cast<std::size_t>(y) * W;
            for (int x = x0; x <= x1; ++x) suppressed |= (trow[x] >= oldest) & (score_at(row + x) >= s);
        }
    } else {
        for (int y = y0; y <= y1 && !suppressed; ++y) {
            const std::int64_t* trow = times + static_cast<std::size_t>(y) * W;
            const std::size_t row = static_cast<std::size_t>(y) * W;
            for (int x = x0; x <= x1 && !suppressed; ++x) {
                const std::int64_t tc = trow[x];
                const double sc = score_at(row + x);
                // decayed(sc, dt) <= sc: only a neighbour at least as strong can suppress.
                if (tc == 0 || !(sc >= s)) continue;
                const std::int64_t dt = now - tc;
                if (dt <= 0) {
                    suppressed = true;
                    continue;
                }
                // Beyond 700 time constants the weight is 0 (below the normal doubles,
                // where exp() is slow): the decayed score is 0, or -infinity for sc < 0.
                const double ages = static_cast<double>(dt) * inv_time_;
                double d;
                if (ages > 700.0) {
                    d = sc >= 0 ? 0.0 : -std::numeric_limits<double>::infinity();
                } else {
                    const double w = std::exp(-ages);
                    d = sc >= 0 ? sc * w : sc / w;
                }
                suppressed = d >= s;
            }
        }
    }
    const std::size_t at = static_cast<std::size_t>(e.y) * W + e.x;
    times[at] = now;
    scores[at] = std::bit_cast<std::int64_t>(s);
    return !suppressed;
}

void AsyncNms::prefetch(const Event& e) const noexcept {
    const std::size_t W = static_cast<std::size_t>(size_.width);
    const std::int64_t* times = this->times(e);
    const int r = params_.radius;
    const int x0 = std::max(0, e.x - r), x1 = std::min(size_.width - 1, e.x + r);
    const int y0 = std::max(0, e.y - r), y1 = std::min(size_.height - 1, e.y + r);
    for (int y = y0; y <= y1; ++y) {
        const char* a = reinterpret_cast<const char*>(times + static_cast<std::size_t>(y) * W + x0);
        const char* b = reinterpret_cast<const char*>(times + static_cast<std::size_t>(y) * W + x1);
        for (; a < b; a += 64) __builtin_prefetch(a, 1);
        __builtin_prefetch(b, 1);
    }
    __builtin_prefetch(times + cells_.size() / 2 + static_cast<std::size_t>(e.y) * W + e.x, 1);  // its score
}

namespace {
// The first corner flag at or after i (n if none), eight flags at a time: corners are rare.
std::size_t next_corner(std::span<const std::uint8_t> flags, std::size_t i) noexcept {
    const std::size_t n = flags.size();
    for (; i + 8 <= n; i += 8) {
        std::uint64_t w;
        std::memcpy(&w, flags.data() + i, 8);
        if (w != 0) return i + static_cast<std::size_t>(std::countr_zero(w) / 8);  // little-endian: lowest byte first
    }
    while (i < n && flags[i] == 0) ++i;
    return i;
}
}  // namespace

std::size_t AsyncNms::filter(std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<const double> score) noexcept {
    // The neighbourhoods of the next kAhead corners are prefetched while one is decided: a
    // batch's corners are known before the first is decided, and their cells, scattered over
    // the sensor and often cold, would otherwise cost a memory latency one after another.
    // Decisions are made in event order as keep() makes them; flags are only read ahead.
    constexpr int kAhead = 4;
    const std::span<const std::uint8_t> flags(is_corner.data(), events.size());
    std::size_t ahead = 0;  // the flags before `ahead` are scanned (and their corners prefetched)
    int pending = 0;        // corners prefetched and not yet decided
    std::size_t kept = 0;
    for (std::size_t i = next_corner(flags, 0); i < events.size(); i = next_corner(flags, i + 1)) {
        if (ahead <= i) {
            ahead = i;
            pending = 0;
        }
        for (; pending < kAhead && (ahead = next_corner(flags, ahead)) < events.size(); ++ahead) {
            prefetch(events[ahead]);
            ++pending;
        }
        --pending;  // corner i, prefetched
        const bool k = keep(events[i], score[i]);
        is_corner[i] = static_cast<std::uint8_t>(k);
        kept += k;
    }
    return kept;
}

}  // namespace evcorner
