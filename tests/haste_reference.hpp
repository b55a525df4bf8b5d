#pragma once
// A plain HASTE, written from docs/tracking.md the way the authors' app runs: one seed
// after another, each over the whole stream, the window a deque, the template a 31x31
// array P[px][py], every formula spelled out where it is used. The oracle the one-pass
// tracker (src/track/haste.cpp) is tested against; slow on purpose.

#include <cmath>
#include <cstdint>
#include <deque>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/track/haste.hpp"
#include "../src/track/haste_weights.hpp"

namespace evcorner::reference {

struct RefHyp {
    float x, y, th, c, s;
};
struct RefEvent {
    std::int64_t t;
    float x, y;
};
using Patch = float[31][31];

inline bool ref_coords(const RefHyp& h, float u, float v, float& px, float& py) {
    float du = u - h.x;
    float dv = v - h.y;
    float rx = du * h.c;
    float ry = dv * h.s;
    px = (rx + ry) + 15.0f;
    float qx = (-du) * h.s;
    float qy = dv * h.c;
    py = (qx + qy) + 15.0f;
    return px >= 0.0f && px < 30.0f && py >= 0.0f && py < 30.0f;
}

inline void ref_splat(Patch& p, float px, float py, float w) {
    int i = static_cast<int>(px), j = static_cast<int>(py);
    float a = px - static_cast<float>(i), b = py - static_cast<float>(j), ab = a * b;
    p[i + 1][j + 1] += ab * w;
    p[i][j + 1] += (b - ab) * w;
    p[i + 1][j] += (a - ab) * w;
    p[i][j] += (((1.0f - a) - b) + ab) * w;
}
inline float ref_scalar(const Patch& p, float px, float py) {
    int i = static_cast<int>(px), j = static_cast<int>(py);
    float a = px - static_cast<float>(i), b = py - static_cast<float>(j), ab = a * b;
    float s = ab * p[i + 1][j + 1];
    s = s + (b - ab) * p[i][j + 1];
    s = s + (a - ab) * p[i + 1][j];
    s = s + (((1.0f - a) - b) + ab) * p[i][j];
    return s;
}
inline float ref_vector(const Patch& p, float px, float py) {
    int i = static_cast<int>(px), j = static_cast<int>(py);
    float a = px - static_cast<float>(i), b = py - static_cast<float>(j);
    float s = p[i][j] * ((1.0f - a) * (1.0f - b));
    s = s + p[i][j + 1] * ((1.0f - a) * b);
    s = s + p[i + 1][j] * (a * (1.0f - b));
    s = s + (p[i + 1][j + 1] * a) * b;
    return s;
}
// Cell sums go column by column (j outer), as the fast path stores them.
inline float ref_patch_sum(const Patch& p) {
    float s = 0;
    for (int j = 0; j < 31; ++j)
        for (int i = 0; i < 31; ++i) s += p[i][j];
    return s;
}

class RefTracker {
public:
    RefTracker(HasteMethod m, float x, float y, float th) : m_(m), x_(x), y_(y), th_(th) {}

    bool initialised() const { return init_; }
    TrackState state(std::uint64_t id, TrackChange why) const { return {t_, x_, y_, th_, id, why}; }
    float x() const { return x_; }
    float y() const { return y_; }

    bool in_range(float u, float v) const {
        float du = u - x_, dv = v - y_;
        return du * du + dv * dv < 225.0f;
    }

    // 0: nothing, 1: regular, 2: state change (initialisation included).
    int push(const RefEvent& e) {
        if (!in_range(e.x, e.y)) return 0;
        if (!init_) {
            win_.push_back(e);
            if (win_.size() < 193) return 0;
            t_ = win_[96].t;
            RefHyp h = hyp(x_, y_, th_);
            for (auto& row : T_)
                for (float& c : row) c = 0;
            for (int k = 0; k < 193; ++k) {
                float px, py;
                if (ref_coords(h, win_[k].x, win_[k].y, px, py)) ref_splat(T_, px, py, weight(k));
            }
            init_ = true;
            renew();
            return 2;
        }
        RefEvent old = win_.front();
        win_.pop_front();
        win_.push_back(e);
        if (m_ == HasteMethod::haste_correlation) {
            for (int n = 0; n < 11; ++n) {
                Q_[n].pop_front();
                float px, py;
                Q_[n].push_back(ref_coords(H_[n], e.x, e.y, px, py) ? ref_scalar(T_, px, py) : 0.0f);
            }
        }
        RefEvent mid = win_[96];
        scores(e, old);
        bool changed = false;
        int best = 0;
        float hi = S_[0], lo = S_[0];
        for (int n = 1; n < 11; ++n) {
            if (S_[n] > hi) {
                hi = S_[n];
                best = n;
            }
            if (S_[n] < lo) lo = S_[n];
        }
        if (S_[0] < hi) {
            float q = (S_[0] - lo) / (hi - lo);
            float margin = 1.0f - q;
            if (static_cast<double>(margin) > 0.05) {
                x_ = H_[best].x;
                y_ = H_[best].y;
                th_ = H_[best].th;
                t_ = mid.t;
                renew();
                changed = true;
            }
        }
        RefHyp h = hyp(x_, y_, th_);
        float px, py;
        if (ref_coords(h, mid.x, mid.y, px, py)) ref_splat(T_, px, py, weight(96) * 0.1f);
        return changed ? 2 : 1;
    }

private:
    bool gaussian() const { return m_ == HasteMethod::correlation || m_ == HasteMethod::haste_correlation; }
    float weight(int k) const { return gaussian() ? detail::kHasteGaussianWeights[k] : 1.0f / 193.0f; }
    static RefHyp hyp(float x, float y, float th) { return {x, y, th, std::cos(th), std::sin(th)}; }

    void normalised(Patch& out) const {
        float sum = ref_patch_sum(T_);
        for (int i = 0; i < 31; ++i)
            for (int j = 0; j < 31; ++j) out[i][j] = T_[i][j] / sum;
    }
    float difference(const Patch& norm, const RefHyp& h, Patch& d) const {
        Patch m{};
        for (int k = 0; k < 193; ++k) {
            float px, py;
            if (ref_coords(h, win_[k].x, win_[k].y, px, py)) ref_splat(m, px, py, 1.0f / 193.0f);
        }
        float s = 0;
        for (int j = 0; j < 31; ++j)
            for (int i = 0; i < 31; ++i) {
                d[i][j] = norm[i][j] - m[i][j] / 1.0f;
                s += d[i][j] * d[i][j];
            }
        return -s;
    }

    void renew() {
        const float dth = 0x1.1df46ap-4f;
        const float ox[11] = {0, 1, -1, 0, 0, 1, -1, -1, 1, 0, 0};
        const float oy[11] = {0, 0, 0, 1, -1, 1, 1, -1, -1, 0, 0};
        const float ot[11] = {0, 0, 0, 0, 0, 0, 0, 0, 0, dth, -dth};
        for (int n = 0; n < 11; ++n) H_[n] = hyp(x_ + ox[n], y_ + oy[n], th_ + ot[n]);
        if (m_ == HasteMethod::haste_correlation) {
            for (int n = 0; n < 11; ++n) {
                Q_[n].clear();
                for (int k = 0; k < 193; ++k) {
                    float px, py;
                    Q_[n].push_back(ref_coords(H_[n], win_[k].x, win_[k].y, px, py) ? ref_vector(T_, px, py) : 0.0f);
                }
            }
        }
        if (m_ == HasteMethod::haste_correlation_star) {
            normalised(N_);
            for (int n = 0; n < 11; ++n) {
                float s = 0;
                for (int k = 0; k < 193; ++k) {
                    float px, py;
                    float v = ref_coords(H_[n], win_[k].x, win_[k].y, px, py) ? ref_vector(N_, px, py) : 0.0f;
                    s += (1.0f / 193.0f) * v;
                }
                S_[n] = s;
            }
        }
        if (m_ == HasteMethod::haste_difference_star) {
            normalised(N_);
            for (int n = 0; n < 11; ++n) S_[n] = difference(N_, H_[n], D_[n]);
        }
    }

    void block(int n, const RefEvent& e, float sign) {
        float px, py;
        if (!ref_coords(H_[n], e.x, e.y, px, py)) return;
        int i = static_cast<int>(px), j = static_cast<int>(py);
        float a = px - static_cast<float>(i), b = py - static_cast<float>(j), ab = a * b;
        Patch& d = D_[n];
        float before = (d[i][j] * d[i][j] + d[i + 1][j] * d[i + 1][j]) + (d[i][j + 1] * d[i][j + 1] + d[i + 1][j + 1] * d[i + 1][j + 1]);
        S_[n] = S_[n] + before;
        const float w = 1.0f / 193.0f;
        d[i][j] += ((((1.0f - a) - b) + ab) * sign) * w;
        d[i][j + 1] += ((b - ab) * sign) * w;
        d[i + 1][j] += ((a - ab) * sign) * w;
        d[i + 1][j + 1] += (ab * sign) * w;
        float after = (d[i][j] * d[i][j] + d[i + 1][j] * d[i + 1][j]) + (d[i][j + 1] * d[i][j + 1] + d[i + 1][j + 1] * d[i + 1][j + 1]);
        S_[n] = S_[n] - after;
    }

    void scores(const RefEvent& e_new, const RefEvent& e_old) {
        for (int n = 0; n < 11; ++n) {
            switch (m_) {
                case HasteMethod::correlation: {
                    float s = 0;
                    for (int k = 0; k < 193; ++k) {
                        float px, py;
                        float v = ref_coords(H_[n], win_[k].x, win_[k].y, px, py) ? ref_vector(T_, px, py) : 0.0f;
                        s += detail::kHasteGaussianWeights[k] * v;
                    }
                    S_[n] = s;
                    break;
                }
                case HasteMethod::haste_correlation: {
                    float s = 0;
                    for (int k = 0; k < 193; ++k) s += Q_[n][k] * detail::kHasteGaussianWeights[k];
                    S_[n] = s;
                    break;
                }
                case HasteMethod::haste_correlation_star: {
                    float px, py;
                    float a = ref_coords(H_[n], e_new.x, e_new.y, px, py) ? ref_scalar(N_, px, py) : 0.0f;
                    float b = ref_coords(H_[n], e_old.x, e_old.y, px, py) ? ref_scalar(N_, px, py) : 0.0f;
                    S_[n] += (1.0f / 193.0f) * (a - b);
                    break;
                }
                case HasteMethod::haste_difference: {
                    Patch norm, d;
                    normalised(norm);
                    S_[n] = difference(norm, H_[n], d);
                    break;
                }
                case HasteMethod::haste_difference_star:
                    block(n, e_new, -1.0f);
                    block(n, e_old, +1.0f);
                    break;
            }
        }
    }

    HasteMethod m_;
    float x_, y_, th_;
    std::int64_t t_ = 0;
    bool init_ = false;
    std::deque<RefEvent> win_;
    Patch T_{};
    Patch N_{};
    Patch D_[11]{};
    std::deque<float> Q_[11];
    RefHyp H_[11]{};
    float S_[11]{};
};

/// The authors' app over `events` (already in memory, in order): each seed in turn over
/// the whole stream. Returns the states seed by seed, chronological within one.
inline std::vector<TrackState> reference_haste(const std::vector<Event>& events, const std::vector<TrackSeed>& seeds,
                                               SensorSize size, HasteMethod m, bool centered, bool authors_time) {
    std::vector<TrackState> out;
    const auto ev = [&](std::size_t i) {
        return RefEvent{events[i].t, static_cast<float>(events[i].x), static_cast<float>(events[i].y)};
    };
    for (const TrackSeed& s : seeds) {
        std::size_t i0 = 0;
        const double due = static_cast<double>(static_cast<float>(static_cast<double>(s.t) / 1e6));
        while (i0 < events.size() &&
               (authors_time ? static_cast<double>(events[i0].t) / 1e6 < due : events[i0].t < s.t))
            ++i0;
        RefTracker tr(m, s.x, s.y, s.theta);
        if (centered) {
            std::vector<std::size_t> back;
            for (std::size_t i = std::min(i0, events.size() - 1); i >= 1 && back.size() < 96; --i)
                if (i < events.size() && tr.in_range(ev(i).x, ev(i).y)) back.push_back(i);
            if (back.size() < 96) continue;
            for (const std::size_t i : back) tr.push(ev(i));  // in the order found: newest first
        }
        std::size_t i = i0;
        for (; i < events.size() && !tr.initialised(); ++i)
            if (tr.push(ev(i)) == 2) break;
        if (!tr.initialised()) continue;
        out.push_back(tr.state(s.id, TrackChange::initialised));
        for (; i < events.size(); ++i) {
            if (tr.push(ev(i)) != 2) continue;
            const bool inside = tr.x() >= 15.0f && tr.y() >= 15.0f && tr.x() + 15.0f < static_cast<float>(size.width) &&
                                tr.y() + 15.0f < static_cast<float>(size.height);
            out.push_back(tr.state(s.id, inside ? TrackChange::moved : TrackChange::stopped));
            if (!inside) break;
        }
    }
    return out;
}

}  // namespace evcorner::reference
