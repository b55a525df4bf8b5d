#include "evcorner/sim/simulator.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <set>

#include "evcorner/sim/coverage.hpp"
#include "evcorner/sim/motion.hpp"
#include "evcorner/sim/texture.hpp"

namespace evcorner::sim {

namespace {
// Coverage within this of 0 or 1 is 0 or 1: the running sums of a pixel inside a polygon
// give 1 - 1e-16 now and then, and a steady pixel must not change.
constexpr double kSnap = 1e-12;
// Largest move of any vertex in one step, px (mark_edges needs less than 1).
constexpr double kMaxMove = 0.75;
constexpr std::uint64_t kSaltThresholds = 1, kSaltNoise = 2, kSaltHot = 3;

// Sorts a row's spans and merges those that overlap or touch: the canonical form of the set
// of columns they cover (the same set gives the same spans, whatever the order given).
void canonical_spans(std::vector<std::pair<int, int>>& row) {
    if (row.size() < 2) return;
    std::sort(row.begin(), row.end());
    std::size_t k = 0;
    for (std::size_t i = 1; i < row.size(); ++i) {
        if (row[i].first <= row[k].second + 1)
            row[k].second = std::max(row[k].second, row[i].second);
        else
            row[++k] = row[i];
    }
    row.resize(k + 1);
}
}  // namespace

Simulator::Simulator(Scene scene)
    : scene_(std::move(scene)),
      w_(scene_.sensor.width),
      h_(scene_.sensor.height),
      stride_(static_cast<std::size_t>(w_) + 2),
      dt_(scene_.simulation.max_step_us),
      end_(static_cast<double>(scene_.duration_us())),
      noise_rng_(scene_.seed, kSaltNoise) {
    const std::size_t n = static_cast<std::size_t>(scene_.sensor.pixels());
    bg_ = background_image(scene_.background, scene_.sensor, scene_.seed);
    cur_.assign(n, 0.0);
    next_.assign(n, 0.0);
    acc_cov_.assign(stride_ * static_cast<std::size_t>(h_), 0.0);
    acc_int_.assign(stride_ * static_cast<std::size_t>(h_), 0.0);
    spans_.resize(static_cast<std::size_t>(h_));
    polys_.resize(scene_.objects.size());
    for (std::size_t o = 0; o < scene_.objects.size(); ++o) polys_[o].resize(scene_.objects[o].pieces.size());
    rects_.resize(scene_.objects.size());

    // The image at t = 0, every row dirty.
    place_objects(0.0);
    prev_rects_ = rects_;
    prev_polys_ = polys_;
    moving_.resize(scene_.objects.size());
    for (std::size_t o = 0; o < scene_.objects.size(); ++o) {
        const Motion& m = scene_.objects[o].motion;
        moving_[o] = m.velocity.x != 0 || m.velocity.y != 0 || m.rotation_deg_s != 0 || m.scaling_per_s != 0;
    }
    render(true);
    cur_ = next_;
    cur_marks_.resize(static_cast<std::size_t>(h_));
    prev_marks_.resize(static_cast<std::size_t>(h_));
    for (std::size_t o = 0; o < scene_.objects.size(); ++o)
        if (moving_[o]) mark_edges(polys_[o], prev_marks_);
    for (auto& row : prev_marks_) canonical_spans(row);

    const CameraParams& cam = scene_.camera;
    lref_.resize(n);
    ion_.resize(n);
    ioff_.resize(n);
    con_.resize(n);
    coff_.resize(n);
    Random thr(scene_.seed, kSaltThresholds);
    // A threshold below 1 % of C would fire on rounding noise; the normal's far tail is cut there.
    const double floor_c = 0.01 * cam.contrast;
    for (std::size_t i = 0; i < n; ++i) {
        double a = cam.contrast, b = cam.contrast;
        if (cam.contrast_sigma > 0) {
            a = std::max(floor_c, cam.contrast + cam.contrast_sigma * thr.normal());
            b = std::max(floor_c, cam.contrast + cam.contrast_sigma * thr.normal());
        }
        con_[i] = static_cast<float>(a);
        coff_[i] = static_cast<float>(b);
        lref_[i] = std::log(kLogEps + cur_[i]);
        ion_[i] = std::exp(lref_[i] + con_[i]) - kLogEps;
        ioff_[i] = std::exp(lref_[i] - coff_[i]) - kLogEps;
    }
    last_.assign(n, INT64_MIN / 2);

    const double noise_rate = cam.noise_hz * static_cast<double>(n) + cam.hot_pixel_hz * cam.hot_pixels;
    noise_rate_per_us_ = noise_rate / 1e6;
    if (cam.hot_pixels > 0) {
        Random hot(scene_.seed, kSaltHot);
        std::set<std::uint32_t> chosen;
        while (chosen.size() < static_cast<std::size_t>(cam.hot_pixels))
            chosen.insert(static_cast<std::uint32_t>(hot.below(n)));
        hot_.assign(chosen.begin(), chosen.end());
    }
    next_noise_ = noise_rate_per_us_ > 0 ? noise_rng_.exponential(1.0 / noise_rate_per_us_) : end_ + 1.0;
}

void Simulator::place_objects(double t_us) {
    const double t_s = t_us / 1e6;
    for (std::size_t o = 0; o < scene_.objects.size(); ++o) {
        const Object& obj = scene_.objects[o];
        const Pose pose(obj.motion, t_s, scene_.duration_s);
        double minx = INFINITY, maxx = -INFINITY, miny = INFINITY, maxy = -INFINITY;
        for (std::size_t k = 0; k < obj.pieces.size(); ++k) {
            const auto& src = obj.pieces[k].polygon;
            auto& dst = polys_[o][k];
            dst.resize(src.size());
            for (std::size_t v = 0; v < src.size(); ++v) {
                const Vec2 p = pose.apply(src[v]);
                dst[v] = p;
                minx = std::min(minx, p.x);
                maxx = std::max(maxx, p.x);
                miny = std::min(miny, p.y);
                maxy = std::max(maxy, p.y);
            }
        }
        Rect r;
        // Pixels with any part of the object: columns floor(minx) .. floor(maxx) (the last may
        // be touched at its left side only, harmless), and everything left of the sensor
        // counts for column 0.
        if (maxx >= 0 && minx < w_ && maxy >= 0 && miny < h_) {
            r.x0 = static_cast<int>(std::max(0.0, std::floor(minx)));
            r.x1 = static_cast<int>(std::min(w_ - 1.0, std::floor(maxx)));
            r.y0 = static_cast<int>(std::max(0.0, std::floor(miny)));
            r.y1 = static_cast<int>(std::min(h_ - 1.0, std::floor(maxy)));
        }
        rects_[o] = r;
    }
}


void Simulator::mark_edges(const std::vector<std::vector<Vec2>>& pieces, std::vector<std::vector<std::pair<int, int>>>& spans) {
    // Every cell an edge touches, widened by one pixel on each side and one row up and down:
    // with edges moving less than a pixel per step (step()), every pixel whose coverage
    // changes touches an edge before or after the step.
    for (const auto& poly : pieces) {
        const std::size_t n = poly.size();
        for (std::size_t i = 0; i < n; ++i) {
            Vec2 a = poly[i], b = poly[(i + 1) % n];
            if (a.y > b.y) std::swap(a, b);
            const int r0 = std::max(0, static_cast<int>(std::floor(a.y)) - 1);
            const int r1 = std::min(h_ - 1, static_cast<int>(std::floor(b.y)) + 1);
            const double dxdy = b.y > a.y ? (b.x - a.x) / (b.y - a.y) : 0.0;
            for (int r = r0; r <= r1; ++r) {
                double xa, xb;
                if (b.y > a.y) {
                    const double ya = std::clamp(static_cast<double>(r - 1), a.y, b.y);
                    const double yb = std::clamp(static_cast<double>(r + 2), a.y, b.y);
                    xa = a.x + (ya - a.y) * dxdy;
                    xb = a.x + (yb - a.y) * dxdy;
                } else {
                    xa = a.x;
                    xb = b.x;
                }
                const double lo_x = std::min(xa, xb), hi_x = std::max(xa, xb);
                if (hi_x < -1 || lo_x >= w_ + 1) continue;
                const int lo = std::max(0, static_cast<int>(std::floor(std::max(lo_x, -2.0))) - 1);
                const int hi = std::min(w_ - 1, static_cast<int>(std::floor(std::min(hi_x, w_ + 1.0))) + 1);
                if (lo <= hi) spans[static_cast<std::size_t>(r)].push_back({lo, hi});
            }
        }
    }
}

double Simulator::render(bool all_rows) {
    for (auto& row : spans_) row.clear();
    if (all_rows) {
        for (auto& row : spans_) row.push_back({0, w_ - 1});
    } else {
        // The pixels near the moving edges now (cur_marks_) and at time_us() (prev_marks_,
        // kept from the step that reached it): sorted, disjoint spans per row.
        for (auto& row : cur_marks_) row.clear();
        for (std::size_t o = 0; o < rects_.size(); ++o)
            if (moving_[o]) mark_edges(polys_[o], cur_marks_);
        for (std::size_t y = 0; y < spans_.size(); ++y) {
            canonical_spans(cur_marks_[y]);
            auto& row = spans_[y];
            row.insert(row.end(), cur_marks_[y].begin(), cur_marks_[y].end());
            row.insert(row.end(), prev_marks_[y].begin(), prev_marks_[y].end());
            if (!cur_marks_[y].empty() && !prev_marks_[y].empty()) canonical_spans(row);
        }
    }
    const std::size_t w = static_cast<std::size_t>(w_);
    for (int y = 0; y < h_; ++y) {
        const std::size_t base = static_cast<std::size_t>(y) * w;
        for (const auto& [lo, hi] : spans_[static_cast<std::size_t>(y)])
            std::copy(bg_.begin() + static_cast<std::ptrdiff_t>(base + static_cast<std::size_t>(lo)),
                      bg_.begin() + static_cast<std::ptrdiff_t>(base + static_cast<std::size_t>(hi) + 1),
                      next_.begin() + static_cast<std::ptrdiff_t>(base + static_cast<std::size_t>(lo)));
    }
    // Each object over what lies behind it: I = I (1 - b) + sum_k b_k I_k, b = sum_k b_k, its
    // pieces' coverages (they never overlap, so b is the object's own coverage), evaluated only
    // at the dirty pixels.
    for (std::size_t o = 0; o < rects_.size(); ++o) {
        const Rect& r = rects_[o];
        if (r.empty()) continue;
        bool touches = false;
        for (int y = r.y0; y <= r.y1 && !touches; ++y)
            for (const auto& [lo, hi] : spans_[static_cast<std::size_t>(y)]) touches = touches || (hi >= r.x0 && lo <= r.x1);
        if (!touches) continue;
        const Object& obj = scene_.objects[o];
        const bool multi = obj.pieces.size() > 1;
        for (std::size_t k = 0; k < obj.pieces.size(); ++k) {
            if (multi)
                accumulate_polygon2(polys_[o][k], 1.0, acc_cov_.data(), obj.pieces[k].intensity, acc_int_.data(),
                                    stride_, w_, h_);
            else
                accumulate_polygon(polys_[o][k], 1.0, acc_cov_.data(), stride_, w_, h_);
        }
        const double level = obj.pieces[0].intensity;
        const int xend = std::min(r.x1 + 1, w_);
        for (int y = r.y0; y <= r.y1; ++y) {
            double* ac = &acc_cov_[static_cast<std::size_t>(y) * stride_];
            double* ai = &acc_int_[static_cast<std::size_t>(y) * stride_];
            double* out = &next_[static_cast<std::size_t>(y) * w];
            // The running sums over the object's columns, composited where the row is dirty.
            double b = 0, s = 0;
            int x = r.x0;
            for (const auto& [lo, hi] : spans_[static_cast<std::size_t>(y)]) {
                if (hi < r.x0) continue;
                if (lo > r.x1) break;
                // Adding 0 leaves a sum as it is: only the columns an edge wrote are read.
                if (multi) {
                    for (; x < lo; ++x) {
                        if (ac[x] != 0) b += ac[x], ac[x] = 0;
                        if (ai[x] != 0) s += ai[x], ai[x] = 0;
                    }
                } else {
                    for (; x < lo; ++x)
                        if (ac[x] != 0) b += ac[x], ac[x] = 0;
                }
                const int last = std::min(hi, r.x1);
                for (; x <= last; ++x) {
                    b += ac[x];
                    ac[x] = 0;
                    if (multi) {
                        s += ai[x];
                        ai[x] = 0;
                    }
                    if (b <= kSnap) continue;
                    const double bc = b >= 1.0 - kSnap ? 1.0 : b;
                    out[x] = out[x] * (1.0 - bc) + (multi ? s : bc * level);
                }
            }
            // Clear what the edges left to the right of the last dirty column.
            if (x <= xend) {
                std::fill(ac + x, ac + xend + 1, 0.0);
                if (multi) std::fill(ai + x, ai + xend + 1, 0.0);
            }
        }
    }
    if (all_rows) return 0;
    // max |dL| over the dirty pixels, bounded by |dI| / (eps + min I) (log is concave).
    double worst = 0;
    for (int y = 0; y < h_; ++y) {
        const std::size_t base = static_cast<std::size_t>(y) * w;
        for (const auto& [lo, hi] : spans_[static_cast<std::size_t>(y)])
            for (int x = lo; x <= hi; ++x) {
                const double a = cur_[base + static_cast<std::size_t>(x)], b = next_[base + static_cast<std::size_t>(x)];
                if (a == b) continue;
                worst = std::max(worst, std::abs(a - b) / (kLogEps + std::min(a, b)));
            }
    }
    return worst;
}

double Simulator::max_displacement() const noexcept {
    double worst = 0;
    for (std::size_t o = 0; o < polys_.size(); ++o) {
        if (!moving_[o]) continue;
        for (std::size_t k = 0; k < polys_[o].size(); ++k)
            for (std::size_t v = 0; v < polys_[o][k].size(); ++v) {
                const Vec2 a = polys_[o][k][v], b = prev_polys_[o][k][v];
                worst = std::max(worst, std::max(std::abs(a.x - b.x), std::abs(a.y - b.y)));
            }
    }
    return worst;
}

void Simulator::emit_crossings(double t0, double t1, std::vector<Event>& ev) {
    const double dt = t1 - t0;
    const double refractory = scene_.camera.refractory_us;
    const std::size_t w = static_cast<std::size_t>(w_);
    auto emit = [&](std::size_t p, double tc, int x, int y, std::uint8_t pol) {
        const std::int64_t ts = std::max<std::int64_t>(1, std::llround(tc));
        if (refractory > 0 && static_cast<double>(ts - last_[p]) < refractory) {
            ++stats_.refractory;
            return;
        }
        last_[p] = ts;
        ev.push_back({ts, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), pol});
    };
    for (int y = 0; y < h_; ++y) {
        const std::size_t base = static_cast<std::size_t>(y) * w;
        for (const auto& [lo, hi] : spans_[static_cast<std::size_t>(y)])
        for (int x = lo; x <= hi; ++x) {
            const std::size_t p = base + static_cast<std::size_t>(x);
            const double a = cur_[p], b = next_[p];
            if (a == b) continue;
            cur_[p] = b;
            if (b > a) {
                while (b >= ion_[p]) {
                    emit(p, t0 + (ion_[p] - a) / (b - a) * dt, x, y, 1);
                    lref_[p] += con_[p];
                    ion_[p] = std::exp(lref_[p] + con_[p]) - kLogEps;
                    ioff_[p] = std::exp(lref_[p] - coff_[p]) - kLogEps;
                }
            } else {
                while (b <= ioff_[p]) {
                    emit(p, t0 + (ioff_[p] - a) / (b - a) * dt, x, y, 0);
                    lref_[p] -= coff_[p];
                    ion_[p] = std::exp(lref_[p] + con_[p]) - kLogEps;
                    ioff_[p] = std::exp(lref_[p] - coff_[p]) - kLogEps;
                }
            }
        }
    }
}

void Simulator::emit_noise(double t1, std::vector<Event>& ev) {
    const double bg_rate = scene_.camera.noise_hz * static_cast<double>(scene_.sensor.pixels());
    const double total = bg_rate + scene_.camera.hot_pixel_hz * scene_.camera.hot_pixels;
    const std::uint64_t n = static_cast<std::uint64_t>(scene_.sensor.pixels());
    while (next_noise_ <= t1) {
        std::uint32_t p;
        std::uint8_t pol;
        if (noise_rng_.uniform() * total < bg_rate) {
            p = static_cast<std::uint32_t>(noise_rng_.below(n));
            pol = static_cast<std::uint8_t>(noise_rng_.next() >> 63);
        } else {
            p = hot_[noise_rng_.below(hot_.size())];
            pol = 1;
        }
        const std::int64_t ts = std::max<std::int64_t>(1, std::llround(next_noise_));
        ev.push_back({ts, static_cast<std::uint16_t>(p % static_cast<std::uint32_t>(w_)),
                      static_cast<std::uint16_t>(p / static_cast<std::uint32_t>(w_)), pol});
        ++stats_.noise;
        next_noise_ += noise_rng_.exponential(1.0 / noise_rate_per_us_);
    }
}

bool Simulator::step(std::vector<Event>& out) {
    if (t_ >= end_) return false;
    const SimulationParams& sp = scene_.simulation;
    const double limit = sp.step_fraction * scene_.camera.contrast;
    double dt = dt_;
    for (;;) {
        const double t1 = std::min(end_, t_ + dt);
        place_objects(t1);
        const double taken = t1 - t_;
        // Edges move less than a pixel per step, so that the pixels near them are all that
        // can change (mark_edges).
        const double moved = max_displacement();
        if (moved > kMaxMove && taken > sp.min_step_us) {
            ++stats_.rejected_steps;
            dt = std::max(sp.min_step_us, taken * 0.9 * kMaxMove / moved);
            continue;
        }
        const double change = render(false);
        if (change > limit && taken > sp.min_step_us) {
            ++stats_.rejected_steps;
            dt = std::max(sp.min_step_us, taken * std::max(0.1, 0.9 * limit / change));
            continue;
        }
        step_events_.clear();
        emit_crossings(t_, t1, step_events_);
        emit_noise(t1, step_events_);
        std::sort(step_events_.begin(), step_events_.end(), [](const Event& a, const Event& b) {
            if (a.t != b.t) return a.t < b.t;
            if (a.y != b.y) return a.y < b.y;
            if (a.x != b.x) return a.x < b.x;
            return a.p < b.p;
        });
        for (const Event& e : step_events_) ++(e.p ? stats_.on : stats_.off);
        out.insert(out.end(), step_events_.begin(), step_events_.end());
        prev_rects_ = rects_;
        prev_polys_ = polys_;
        prev_marks_.swap(cur_marks_);
        ++stats_.steps;
        stats_.max_step_change = std::max(stats_.max_step_change, change / scene_.camera.contrast);
        dt_ = std::min(sp.max_step_us, change > 0 ? taken * std::clamp(0.9 * limit / change, 0.5, 2.0) : 2.0 * taken);
        if (moved > 0) dt_ = std::min(dt_, taken * 0.9 * kMaxMove / moved * 2.0);
        dt_ = std::max(dt_, sp.min_step_us);
        t_ = t1;
        return true;
    }
}

std::vector<Event> simulate(const Scene& scene) {
    Simulator sim(scene);
    std::vector<Event> out;
    while (sim.step(out)) {
    }
    return out;
}

}  // namespace evcorner::sim
