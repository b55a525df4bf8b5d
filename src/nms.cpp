// AsyncNms (nms.hpp): the per-corner decision over the square neighbourhood.

#include "evcorner/nms.hpp"

#include <algorithm>
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
      cells_(static_cast<std::size_t>(planes_) * static_cast<std::size_t>(size.pixels())) {}

bool AsyncNms::keep(const Event& e, double score) noexcept {
    const double s = std::isnan(score) ? -std::numeric_limits<double>::infinity() : score;
    const std::size_t W = static_cast<std::size_t>(size_.width);
    Cell* plane = cells_.data() + static_cast<std::size_t>(planes_ == 2 && (e.p & 1)) * static_cast<std::size_t>(size_.pixels());
    const int r = params_.radius;
    const int x0 = std::max(0, e.x - r), x1 = std::min(size_.width - 1, e.x + r);
    const int y0 = std::max(0, e.y - r), y1 = std::min(size_.height - 1, e.y + r);
    const std::int64_t now = e.t + kBias;
    bool suppressed = false;
    if (params_.rule == NmsRule::window) {
        // dt <= T  <=>  stored tc >= now - T; a never-used cell (0) is older than any.
        const std::int64_t oldest = now - params_.time_us;
        for (int y = y0; y <= y1 && !suppressed; ++y) {
            const Cell* row = plane + static_cast<std::size_t>(y) * W;
            for (int x = x0; x <= x1; ++x) suppressed |= (row[x].t != 0) & (row[x].t >= oldest) & (row[x].score >= s);
        }
    } else {
        for (int y = y0; y <= y1 && !suppressed; ++y) {
            const Cell* row = plane + static_cast<std::size_t>(y) * W;
            for (int x = x0; x <= x1 && !suppressed; ++x) {
                const Cell c = row[x];
                // decayed(sc, dt) <= sc: only a neighbour at least as strong can suppress.
                if (c.t == 0 || !(c.score >= s)) continue;
                const std::int64_t dt = now - c.t;
                if (dt <= 0) {
                    suppressed = true;
                    continue;
                }
                // Beyond 700 time constants the weight is 0 (below the normal doubles,
                // where exp() is slow): the decayed score is 0, or -infinity for sc < 0.
                const double ages = static_cast<double>(dt) * inv_time_;
                double d;
                if (ages > 700.0) {
                    d = c.score >= 0 ? 0.0 : -std::numeric_limits<double>::infinity();
                } else {
                    const double w = std::exp(-ages);
                    d = c.score >= 0 ? c.score * w : c.score / w;
                }
                suppressed = d >= s;
            }
        }
    }
    plane[static_cast<std::size_t>(e.y) * W + e.x] = {now, s};
    return !suppressed;
}

std::size_t AsyncNms::filter(std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<const double> score) noexcept {
    std::size_t kept = 0;
    for (std::size_t i = 0; i < events.size(); ++i) {
        if (!is_corner[i]) continue;
        const bool k = keep(events[i], score[i]);
        is_corner[i] = static_cast<std::uint8_t>(k);
        kept += k;
    }
    return kept;
}

}  // namespace evcorner
