#pragma once
// A plain oracle of the "corners" tracker (src/track/corner_tracker.hpp), written from that
// header's rules: every track in one list, scanned whole for every corner event; no grid.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/track/track_seed.hpp"
#include "evcorner/track/track_state.hpp"

namespace evcorner::test {

struct CornerTrackerReference {
    int width, height;
    float radius;
    std::int64_t max_idle_us;
    double min_separation;
    bool seed_from_corners;
    std::size_t max_tracks;
    std::vector<TrackSeed> seeds;  // in time order

    static constexpr float kAlpha = 0.5f, kBeta = kAlpha * kAlpha / (2 - kAlpha);

    struct Track {
        std::uint64_t id;
        float x, y, vx, vy;
        std::int64_t t_last;
        bool live;
    };
    std::vector<Track> tracks;  // in id order of creation (ids increase)
    std::size_t next_seed = 0;
    std::uint64_t next_id = 0;
    std::int64_t next_sweep = INT64_MIN;

    std::vector<TrackState> process(const Event& e, bool corner) {
        std::vector<TrackState> out;
        if (next_id == 0)
            for (const auto& s : seeds) next_id = std::max(next_id, s.id + 1);
        auto by_id = [&](std::vector<Track*> v) {
            std::sort(v.begin(), v.end(), [](const Track* a, const Track* b) { return a->id < b->id; });
            return v;
        };
        auto stop = [&](Track& t) {
            t.live = false;
            out.push_back({e.t, t.x, t.y, 0.0f, t.id, TrackChange::stopped});
        };
        if (e.t >= next_sweep) {
            std::vector<Track*> expired;
            for (auto& t : tracks)
                if (t.live && e.t - t.t_last > max_idle_us) expired.push_back(&t);
            for (Track* t : by_id(expired)) stop(*t);
            next_sweep = e.t + std::max<std::int64_t>(max_idle_us / 8, 1);
        }
        auto start = [&](float x, float y, std::uint64_t id) {
            tracks.push_back({id, x, y, 0, 0, e.t, true});
            out.push_back({e.t, x, y, 0.0f, id, TrackChange::initialised});
        };
        while (next_seed < seeds.size() && seeds[next_seed].t <= e.t) {
            const auto& s = seeds[next_seed++];
            start(s.x, s.y, s.id);
        }
        if (!corner) return out;
        const float zx = static_cast<float>(e.x), zy = static_cast<float>(e.y);
        const float reach = std::max(8.f, std::ceil(radius));  // how far a track's last position may be
        Track* best = nullptr;
        float best_d2 = radius * radius;
        for (Track* t : by_id([&] {
                 std::vector<Track*> v;
                 for (auto& t : tracks) v.push_back(&t);
                 return v;
             }())) {
            if (!t->live || e.t - t->t_last > max_idle_us) continue;
            if (std::fabs(t->x - zx) > reach || std::fabs(t->y - zy) > reach) continue;
            const float dt = static_cast<float>(e.t - t->t_last) * 1e-6f;
            const float px = t->x + t->vx * dt, py = t->y + t->vy * dt;
            const float d2 = (px - zx) * (px - zx) + (py - zy) * (py - zy);
            if (d2 < best_d2) {
                best_d2 = d2;
                best = t;
            }
        }
        if (best == nullptr) {
            std::size_t live = 0;
            for (const auto& t : tracks) live += t.live;
            if (seed_from_corners && live < max_tracks) start(zx, zy, next_id++);
            return out;
        }
        Track& t = *best;
        const float dt = static_cast<float>(e.t - t.t_last) * 1e-6f;
        const float px = t.x + t.vx * dt, py = t.y + t.vy * dt;
        const float rx = zx - px, ry = zy - py;
        t.x = px + kAlpha * rx;
        t.y = py + kAlpha * ry;
        if (dt > 0) {
            t.vx += kBeta * rx / dt;
            t.vy += kBeta * ry / dt;
        }
        t.t_last = e.t;
        out.push_back({e.t, t.x, t.y, 0.0f, t.id, TrackChange::moved});
        if (!(t.x >= 0 && t.y >= 0 && t.x < static_cast<float>(width) && t.y < static_cast<float>(height))) {
            stop(t);
            return out;
        }
        if (min_separation > 0) {
            std::vector<Track*> near;
            for (auto& o : tracks) {
                if (&o == &t || !o.live) continue;
                const double dx = t.x - o.x, dy = t.y - o.y;
                if (dx * dx + dy * dy < min_separation * min_separation) near.push_back(&o);
            }
            bool older = false;
            for (Track* o : near) older = older || o->id < t.id;
            if (older)
                stop(t);
            else
                for (Track* o : by_id(near)) stop(*o);
        }
        return out;
    }
};

}  // namespace evcorner::test
