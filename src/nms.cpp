// AsyncNms (nms.hpp): the per-corner decision over the square neighbourhood.

#include "evcorner/nms.hpp"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "evcorner/cpu_paths.hpp"

namespace evcorner {

namespace {
constexpr std::int64_t kBias = std::int64_t{1} << 62;

using WindowFn = bool (*)(const std::int64_t*, const std::int64_t*, std::size_t, int, int, int, int, std::int64_t,
                          double) noexcept;

// The window rule's neighbourhood test, three ways. Each cell is (time >= oldest) and
// (score >= s); the scores of cells too old are not read (a row at a time on the
// portable path, a lane at a time on the vector paths).
bool window_portable(const std::int64_t* times, const std::int64_t* scores, std::size_t W, int x0, int x1, int y0,
                     int y1, std::int64_t oldest, double s) noexcept {
    bool suppressed = false;
    for (int y = y0; y <= y1 && !suppressed; ++y) {
        const std::size_t row = static_cast<std::size_t>(y) * W;
        bool recent = false;
        for (int x = x0; x <= x1; ++x) recent |= times[row + x] >= oldest;
        if (!recent) continue;  // no corner in the window on this row: its scores unread
        for (int x = x0; x <= x1; ++x)
            suppressed |= (times[row + x] >= oldest) & (std::bit_cast<double>(scores[row + x]) >= s);
    }
    return suppressed;
}

#ifdef EVCORNER_HAVE_AVX2_SEARCH
// Four cells per vector; the last chunk of a row masked (masked loads do not touch the
// lanes left out, so nothing past the row's end is read).
[[gnu::target("avx2")]] bool window_avx2(const std::int64_t* times, const std::int64_t* scores, std::size_t W, int x0,
                                         int x1, int y0, int y1, std::int64_t oldest, double s) noexcept {
    const __m256i before = _mm256_set1_epi64x(oldest - 1);  // time > oldest - 1: oldest >= 1, no overflow
    const __m256d vs = _mm256_set1_pd(s);
    const __m256i lane = _mm256_setr_epi64x(0, 1, 2, 3);
    __m256i hit = _mm256_setzero_si256();
    for (int xs = x0; xs <= x1; xs += 4) {
        const __m256i in = _mm256_cmpgt_epi64(_mm256_set1_epi64x(x1 - xs + 1), lane);  // lanes within the row
        for (int y = y0; y <= y1; ++y) {
            const std::size_t at = static_cast<std::size_t>(y) * W + static_cast<std::size_t>(xs);
            const __m256i t = _mm256_maskload_epi64(reinterpret_cast<const long long*>(times + at), in);
            const __m256i recent = _mm256_and_si256(in, _mm256_cmpgt_epi64(t, before));
            const __m256d sc = _mm256_maskload_pd(reinterpret_cast<const double*>(scores + at), recent);
            const __m256d ge = _mm256_cmp_pd(sc, vs, _CMP_GE_OQ);
            hit = _mm256_or_si256(hit, _mm256_and_si256(recent, _mm256_castpd_si256(ge)));
        }
    }
    return !_mm256_testz_si256(hit, hit);
}

// Eight cells per vector (a whole row for radius <= 3).
[[gnu::target(EVCORNER_AVX512_TARGET)]] bool window_avx512(const std::int64_t* times,
                                                                          const std::int64_t* scores, std::size_t W,
                                                                          int x0, int x1, int y0, int y1,
                                                                          std::int64_t oldest, double s) noexcept {
    const __m512i vold = _mm512_set1_epi64(oldest);
    const __m512d vs = _mm512_set1_pd(s);
    __mmask8 hit = 0;
    for (int xs = x0; xs <= x1; xs += 8) {
        const int n = std::min(8, x1 - xs + 1);
        const __mmask8 in = static_cast<__mmask8>((1u << n) - 1u);
        for (int y = y0; y <= y1; ++y) {
            const std::size_t at = static_cast<std::size_t>(y) * W + static_cast<std::size_t>(xs);
            const __m512i t = _mm512_maskz_loadu_epi64(in, times + at);
            const __mmask8 recent = _mm512_mask_cmpge_epi64_mask(in, t, vold);
            const __m512d sc = _mm512_maskz_loadu_pd(recent, scores + at);
            hit |= _mm512_mask_cmp_pd_mask(recent, sc, vs, _CMP_GE_OQ);
        }
    }
    return hit != 0;
}
#endif

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



// The per-path bodies: keep() and filter() with one path's window test inlined (each
// compiled for its path's instruction set below).
struct NmsPath {
    template <WindowFn Test>
    [[gnu::always_inline]] static inline bool keep(AsyncNms& n, const Event& e, double score) noexcept {
        const double s = std::isnan(score) ? -std::numeric_limits<double>::infinity() : score;
        const std::size_t W = static_cast<std::size_t>(n.size_.width);
        std::int64_t* const times = n.times(e);
        std::int64_t* const scores = n.score_bits(e);
        const auto score_at = [scores](std::size_t i) { return std::bit_cast<double>(scores[i]); };
        const int r = n.params_.radius;
        const int x0 = std::max(0, e.x - r), x1 = std::min(n.size_.width - 1, e.x + r);
        const int y0 = std::max(0, e.y - r), y1 = std::min(n.size_.height - 1, e.y + r);
        const std::int64_t now = e.t + kBias;
        bool suppressed = false;
        if (n.params_.rule == NmsRule::window) {
            // dt <= T  <=>  stored tc >= now - T; a never-used cell (0) is older than any:
            // both at once as tc >= max(now - T, 1) (stored times are at least 1).
            const std::int64_t oldest = std::max<std::int64_t>(now - n.params_.time_us, 1);
            suppressed = Test(times, scores, W, x0, x1, y0, y1, oldest, s);
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
                    const double ages = static_cast<double>(dt) * n.inv_time_;
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

    template <WindowFn Test>
    [[gnu::always_inline]] static inline std::size_t filter(AsyncNms& n, std::span<const Event> events,
                                                            std::span<std::uint8_t> is_corner,
                                                            std::span<const double> score) noexcept {
        // The corners in event order, found eight flags at a time (corners are rare).
        // (Prefetching the neighbourhoods of the next corners was measured and bought
        // nothing once the detector and the stage run a chunk at a time: nms.hpp.)
        std::size_t kept = 0;
        const auto decide = [&](std::size_t k) {
            const bool kp = keep<Test>(n, events[k], score[k]);
            is_corner[k] = static_cast<std::uint8_t>(kp);
            kept += kp;
        };
        std::size_t i = 0;
        for (; i + 8 <= events.size(); i += 8) {
            std::uint64_t w;
            std::memcpy(&w, is_corner.data() + i, 8);
            while (w != 0) {  // little-endian: the lowest byte is the first flag
                const int bit = std::countr_zero(w) & ~7;
                decide(i + static_cast<std::size_t>(bit / 8));
                w &= ~(std::uint64_t{0xff} << bit);
            }
        }
        for (; i < events.size(); ++i)
            if (is_corner[i] != 0) decide(i);
        return kept;
    }
};

namespace {
bool keep_portable(AsyncNms& n, const Event& e, double s) noexcept { return NmsPath::keep<window_portable>(n, e, s); }
std::size_t filter_portable(AsyncNms& n, std::span<const Event> ev, std::span<std::uint8_t> c,
                            std::span<const double> s) noexcept {
    return NmsPath::filter<window_portable>(n, ev, c, s);
}
#ifdef EVCORNER_HAVE_AVX2_SEARCH
[[gnu::target("avx2"), gnu::flatten]] bool keep_avx2(AsyncNms& n, const Event& e, double s) noexcept {
    return NmsPath::keep<window_avx2>(n, e, s);
}
[[gnu::target("avx2"), gnu::flatten]] std::size_t filter_avx2(AsyncNms& n, std::span<const Event> ev,
                                                               std::span<std::uint8_t> c,
                                                               std::span<const double> s) noexcept {
    return NmsPath::filter<window_avx2>(n, ev, c, s);
}
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::flatten]] bool keep_avx512(AsyncNms& n, const Event& e, double s) noexcept {
    return NmsPath::keep<window_avx512>(n, e, s);
}
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::flatten]] std::size_t filter_avx512(AsyncNms& n, std::span<const Event> ev,
                                                                             std::span<std::uint8_t> c,
                                                                             std::span<const double> s) noexcept {
    return NmsPath::filter<window_avx512>(n, ev, c, s);
}
#endif

struct WindowPath {
    const char* name;
    bool (*keep)(AsyncNms&, const Event&, double) noexcept;
    std::size_t (*filter)(AsyncNms&, std::span<const Event>, std::span<std::uint8_t>, std::span<const double>) noexcept;
};

// The paths this CPU runs, fastest first.
const std::vector<WindowPath>& window_paths() {
    static const std::vector<WindowPath> paths = [] {
        std::vector<WindowPath> p;
#ifdef EVCORNER_HAVE_AVX2_SEARCH
        if (cpu_runs_avx512())
            p.push_back({"avx512", keep_avx512, filter_avx512});
        if (cpu_runs_avx2()) p.push_back({"avx2", keep_avx2, filter_avx2});
#endif
        p.push_back({"portable", keep_portable, filter_portable});
        return p;
    }();
    return paths;
}

const WindowPath& default_window_path() noexcept {
    // EVCORNER_NMS_PATH=portable (or avx2, avx512) forces a path this CPU runs.
    static const WindowPath& c = forced_or_fastest(window_paths(), "EVCORNER_NMS_PATH");
    return c;
}
}  // namespace

AsyncNms::AsyncNms(SensorSize size, const NmsParams& params, int planes)
    : params_((check_nms_params(params), params)), size_(checked_sensor_size(size, "NMS")),
      keep_(default_window_path().keep), filter_(default_window_path().filter), path_name_(default_window_path().name),
      planes_(planes == 1 ? 1 : 2), inv_time_(1.0 / static_cast<double>(params.time_us)),
      cells_(2 * static_cast<std::size_t>(planes_) * static_cast<std::size_t>(size.pixels())) {}

std::vector<std::string> AsyncNms::code_paths() {
    std::vector<std::string> names;
    for (const WindowPath& p : window_paths()) names.emplace_back(p.name);
    return names;
}

void AsyncNms::use_code_path(std::string_view name) {
    for (const WindowPath& p : window_paths())
        if (name == p.name) {
            keep_ = p.keep;
            filter_ = p.filter;
            path_name_ = p.name;
            return;
        }
    throw std::invalid_argument("NMS code path '" + std::string(name) + "' does not run on this CPU");
}

}  // namespace evcorner
