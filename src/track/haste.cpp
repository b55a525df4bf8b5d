#include "evcorner/track/haste.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_set>

#include "haste_track.hpp"

namespace evcorner {

namespace {

constexpr std::string_view kMethodNames[] = {"correlation", "haste-correlation", "haste-correlation-star",
                                             "haste-difference", "haste-difference-star"};

constexpr int kCellShift = 4;  // grid cells of 16 x 16 pixels

}  // namespace

std::string_view haste_method_name(HasteMethod m) noexcept { return kMethodNames[static_cast<int>(m)]; }

std::optional<HasteMethod> parse_haste_method(std::string_view name) noexcept {
    for (int i = 0; i < 5; ++i)
        if (kMethodNames[i] == name) return static_cast<HasteMethod>(i);
    return std::nullopt;
}

/// What the five methods share: seeds, the grid, the look-back for centered starts, the
/// stopping rules. The tracks themselves live in ImplOf<M>.
struct Haste::Impl {
    struct Pending {
        TrackSeed seed;
        double due_s;  // authors_seed_time: double(float(seed t in seconds))
    };
    struct Past {
        std::int64_t index;
        Event e;
    };

    SensorSize size;
    HasteParams params;
    int cells_x, cells_y;
    std::vector<std::vector<std::uint32_t>> cells;  // track slots whose range square meets the cell
    std::vector<Pending> seeds;                     // by time
    std::size_t next_seed = 0;
    std::vector<TrackSeed> start_now;  // start() since the last event
    std::unordered_set<std::uint64_t> ids;
    std::vector<Past> past;  // centered: the last lookback events, a ring
    std::int64_t events = 0;
    std::int64_t last_t = std::numeric_limits<std::int64_t>::min();
    std::uint64_t skipped = 0;
    std::uint64_t updates = 0;
    std::size_t live = 0, pending = 0, collecting = 0;
    std::int64_t next_idle_sweep = std::numeric_limits<std::int64_t>::min();
    std::vector<TrackState> out;
    std::vector<std::uint32_t> candidates;

    static constexpr std::size_t kLookback = std::size_t{1} << 20;

    Impl(SensorSize s, const HasteParams& p) : size(checked_sensor_size(s, "haste")), params(p) {
        cells_x = (size.width + (1 << kCellShift) - 1) >> kCellShift;
        cells_y = (size.height + (1 << kCellShift) - 1) >> kCellShift;
        cells.resize(static_cast<std::size_t>(cells_x) * cells_y);
        if (params.stop.max_idle_us < 0) throw std::invalid_argument("haste: max idle time must not be negative");
        if (!(params.stop.min_separation >= 0)) throw std::invalid_argument("haste: min separation must not be negative");
    }
    virtual ~Impl() = default;

    void check_seed(const TrackSeed& s) {
        if (!(s.x >= 0 && s.y >= 0 && s.x < static_cast<float>(size.width) && s.y < static_cast<float>(size.height)) ||
            !std::isfinite(s.theta))
            throw std::invalid_argument("seed " + std::to_string(s.id) + " at (" + std::to_string(s.x) + ", " +
                                        std::to_string(s.y) + ") is off the " + std::to_string(size.width) + "x" +
                                        std::to_string(size.height) + " sensor");
        if (!ids.insert(s.id).second)
            throw std::invalid_argument("seed id " + std::to_string(s.id) + " is used twice");
    }

    void add_seeds(std::vector<TrackSeed> list) {
        for (const auto& s : list) check_seed(s);
        std::stable_sort(list.begin(), list.end(), [](const TrackSeed& a, const TrackSeed& b) { return a.t < b.t; });
        for (const auto& s : list)
            seeds.push_back({s, static_cast<double>(static_cast<float>(static_cast<double>(s.t) / 1e6))});
        pending = seeds.size();
    }

    [[nodiscard]] bool due(const Pending& p, const Event& e) const noexcept {
        return params.authors_seed_time ? static_cast<double>(e.t) / 1e6 >= p.due_s : e.t >= p.seed.t;
    }

    void cell_rect(float x, float y, int r[4]) const noexcept {
        const auto clamp = [](float v, int hi) {
            const int c = static_cast<int>(std::floor(v)) >> kCellShift;
            return std::clamp(c, 0, hi);
        };
        r[0] = clamp(x - kMargin, cells_x - 1);
        r[1] = clamp(y - kMargin, cells_y - 1);
        r[2] = clamp(x + kMargin, cells_x - 1);
        r[3] = clamp(y + kMargin, cells_y - 1);
    }
    void enter(std::uint32_t slot, const int r[4]) {
        for (int cy = r[1]; cy <= r[3]; ++cy)
            for (int cx = r[0]; cx <= r[2]; ++cx) cells[static_cast<std::size_t>(cy) * cells_x + cx].push_back(slot);
    }
    void leave(std::uint32_t slot, const int r[4]) {
        for (int cy = r[1]; cy <= r[3]; ++cy)
            for (int cx = r[0]; cx <= r[2]; ++cx) {
                auto& c = cells[static_cast<std::size_t>(cy) * cells_x + cx];
                c.erase(std::find(c.begin(), c.end(), slot));
            }
    }

    /// The 96 newest events up to this one (index >= 1) in range of (x, y), newest first:
    /// what the authors' centered start walks back for, in the order it pushes them (the
    /// goldens show that order: oldest first matches 56 % of their states, this 100 %).
    /// Fewer when there are not as many within the look-back.
    std::vector<Event> look_back(float x, float y) const {
        std::vector<Event> found;
        const std::int64_t n = std::min<std::int64_t>(events, static_cast<std::int64_t>(past.size()));
        for (std::int64_t i = 0; i < n && found.size() < detail::kHasteMiddle; ++i) {
            const Past& p = past[static_cast<std::size_t>((events - 1 - i) % static_cast<std::int64_t>(past.size()))];
            if (p.index < 1) break;
            const float du = static_cast<float>(p.e.x) - x, dv = static_cast<float>(p.e.y) - y;
            if (du * du + dv * dv < kRangeSquared) found.push_back(p.e);
        }
        return found;
    }

    std::span<const TrackState> process(const Event& e) {
        if (!size.contains(e) || e.p > 1) throw InvalidEvent(e, EventLimits{size});
        if (e.t < last_t)
            throw std::invalid_argument("haste: event at t = " + std::to_string(e.t) + " us comes after one at t = " +
                                        std::to_string(last_t) + " us (events must be in time order)");
        last_t = e.t;
        out.clear();
        const std::int64_t index = events++;
        if (params.init == HasteInit::centered) {
            if (past.size() < kLookback)
                past.push_back({index, e});
            else
                past[static_cast<std::size_t>(index % static_cast<std::int64_t>(past.size()))] = {index, e};
        }
        for (const auto& s : start_now) begin(s);
        start_now.clear();
        while (next_seed < seeds.size() && due(seeds[next_seed], e)) {
            --pending;
            begin(seeds[next_seed++].seed);
        }
        run(e);
        if (params.stop.max_idle_us > 0 && e.t >= next_idle_sweep) {
            stop_idle(e.t);
            next_idle_sweep = e.t + std::max<std::int64_t>(1, params.stop.max_idle_us / 4);
        }
        if (out.size() > 1)
            std::stable_sort(out.begin(), out.end(), [](const TrackState& a, const TrackState& b) { return a.id < b.id; });
        return out;
    }

    /// Starts a track at seed s (centered: with its look-back pushed, or skipped).
    virtual void begin(const TrackSeed& s) = 0;
    /// Every track in range of e takes it.
    virtual void run(const Event& e) = 0;
    virtual void stop_idle(std::int64_t now) = 0;
    [[nodiscard]] virtual bool near(float x, float y, float r) const noexcept = 0;
};

namespace {

template <HasteMethod M>
struct ImplOf final : Haste::Impl {
    using Track = detail::HasteTrack<M>;
    struct Slot {
        std::unique_ptr<Track> track;
        int rect[4];
        std::int64_t last_change = 0;
        std::uint64_t order = 0;  // start order: the older of two tracks has the lower one
    };
    std::vector<Slot> slots;
    std::vector<std::uint32_t> free_slots;
    std::uint64_t started = 0;

    using Impl::Impl;

    void begin(const TrackSeed& s) override {
        auto track = std::make_unique<Track>();
        track->id = s.id;
        track->x = s.x;
        track->y = s.y;
        track->theta = s.theta;
        if (params.init == HasteInit::centered) {
            const std::vector<Event> back = look_back(s.x, s.y);
            if (back.size() < static_cast<std::size_t>(detail::kHasteMiddle)) {
                ++skipped;
                return;
            }
            for (const Event& e : back)
                track->push_initial({e.t, static_cast<float>(e.x), static_cast<float>(e.y)});
        }
        std::uint32_t slot;
        if (!free_slots.empty()) {
            slot = free_slots.back();
            free_slots.pop_back();
        } else {
            slot = static_cast<std::uint32_t>(slots.size());
            slots.emplace_back();
        }
        Slot& sl = slots[slot];
        sl.track = std::move(track);
        sl.order = started++;
        ++collecting;
        cell_rect(s.x, s.y, sl.rect);
        enter(slot, sl.rect);
    }

    void end(std::uint32_t slot) {
        leave(slot, slots[slot].rect);
        slots[slot].track.reset();
        free_slots.push_back(slot);
        --live;
    }

    void emit(const Track& tr, TrackChange why) {
        out.push_back({tr.t, tr.x, tr.y, tr.theta, tr.id, why});
    }

    void run(const Event& e) override {
        const auto& cell = cells[static_cast<std::size_t>(e.y >> kCellShift) * cells_x + (e.x >> kCellShift)];
        if (cell.empty()) return;
        candidates.assign(cell.begin(), cell.end());
        const detail::WindowEvent we{e.t, static_cast<float>(e.x), static_cast<float>(e.y)};
        for (const std::uint32_t slot : candidates) {
            Slot& sl = slots[slot];
            if (!sl.track) continue;  // stopped by a rule earlier in this event
            Track& tr = *sl.track;
            if (!tr.in_range(we.x, we.y)) continue;
            ++updates;
            if (!tr.initialised) {
                if (!tr.push_initial(we)) continue;
                --collecting;
                ++live;
                sl.last_change = e.t;
                emit(tr, TrackChange::initialised);
                // The initialising event is pushed once more, as the first running event.
            }
            if (!tr.push(we)) continue;
            sl.last_change = e.t;
            const bool inside = tr.x >= static_cast<float>(Haste::kMargin) && tr.y >= static_cast<float>(Haste::kMargin) &&
                                tr.x + static_cast<float>(Haste::kMargin) < static_cast<float>(size.width) &&
                                tr.y + static_cast<float>(Haste::kMargin) < static_cast<float>(size.height);
            if (!inside) {
                emit(tr, TrackChange::stopped);
                end(slot);
                continue;
            }
            emit(tr, TrackChange::moved);
            int r[4];
            cell_rect(tr.x, tr.y, r);
            if (!std::equal(r, r + 4, sl.rect)) {
                leave(slot, sl.rect);
                std::copy(r, r + 4, sl.rect);
                enter(slot, sl.rect);
            }
            if (params.stop.min_separation > 0) separate(slot, e.t);
        }
    }

    /// The younger of `slot` and any live track closer than min_separation stops.
    void separate(std::uint32_t slot, std::int64_t now) {
        const Track& a = *slots[slot].track;
        const float r2 = static_cast<float>(params.stop.min_separation * params.stop.min_separation);
        const auto& cell = cells[static_cast<std::size_t>(std::clamp(static_cast<int>(a.y) >> kCellShift, 0, cells_y - 1)) * cells_x +
                                 std::clamp(static_cast<int>(a.x) >> kCellShift, 0, cells_x - 1)];
        for (const std::uint32_t other : std::vector<std::uint32_t>(cell)) {
            if (other == slot || !slots[other].track || !slots[other].track->initialised || !slots[slot].track) continue;
            const Track& b = *slots[other].track;
            const float dx = a.x - b.x, dy = a.y - b.y;
            if (dx * dx + dy * dy >= r2) continue;
            const std::uint32_t younger = slots[other].order > slots[slot].order ? other : slot;
            stop_at(younger, now);
            if (younger == slot) return;
        }
    }

    void stop_at(std::uint32_t slot, std::int64_t now) {
        Track& tr = *slots[slot].track;
        out.push_back({now, tr.x, tr.y, tr.theta, tr.id, TrackChange::stopped});
        end(slot);
    }

    void stop_idle(std::int64_t now) override {
        for (std::uint32_t s = 0; s < slots.size(); ++s)
            if (slots[s].track && slots[s].track->initialised && now - slots[s].last_change > params.stop.max_idle_us)
                stop_at(s, now);
    }

    [[nodiscard]] bool near(float x, float y, float r) const noexcept override {
        const float r2 = r * r;
        int rect[4];
        // A track is registered in the cell of its own position, among others.
        const float reach = std::min<float>(r, 1e6f);
        const auto clamp_cell = [](float v, int hi) { return std::clamp(static_cast<int>(std::floor(v)) >> kCellShift, 0, hi); };
        rect[0] = clamp_cell(x - reach, cells_x - 1);
        rect[1] = clamp_cell(y - reach, cells_y - 1);
        rect[2] = clamp_cell(x + reach, cells_x - 1);
        rect[3] = clamp_cell(y + reach, cells_y - 1);
        for (int cy = rect[1]; cy <= rect[3]; ++cy)
            for (int cx = rect[0]; cx <= rect[2]; ++cx)
                for (const std::uint32_t s : cells[static_cast<std::size_t>(cy) * cells_x + cx]) {
                    const Track& tr = *slots[s].track;
                    const float dx = tr.x - x, dy = tr.y - y;
                    if (dx * dx + dy * dy < r2) return true;
                }
        return false;
    }
};

std::unique_ptr<Haste::Impl> make_impl(SensorSize size, const HasteParams& p) {
    switch (p.method) {
        case HasteMethod::correlation: return std::make_unique<ImplOf<HasteMethod::correlation>>(size, p);
        case HasteMethod::haste_correlation: return std::make_unique<ImplOf<HasteMethod::haste_correlation>>(size, p);
        case HasteMethod::haste_correlation_star:
            return std::make_unique<ImplOf<HasteMethod::haste_correlation_star>>(size, p);
        case HasteMethod::haste_difference: return std::make_unique<ImplOf<HasteMethod::haste_difference>>(size, p);
        case HasteMethod::haste_difference_star:
            return std::make_unique<ImplOf<HasteMethod::haste_difference_star>>(size, p);
    }
    throw std::invalid_argument("haste: unknown method");
}

}  // namespace

Haste::Haste(SensorSize size, const HasteParams& params, std::vector<TrackSeed> seeds)
    : impl_(make_impl(size, params)) {
    impl_->add_seeds(std::move(seeds));
}
Haste::~Haste() = default;
Haste::Haste(Haste&&) noexcept = default;
Haste& Haste::operator=(Haste&&) noexcept = default;

std::span<const TrackState> Haste::process(const Event& e) { return impl_->process(e); }

void Haste::start(const TrackSeed& seed) {
    impl_->check_seed(seed);
    impl_->start_now.push_back(seed);
}
bool Haste::track_near(float x, float y, float radius) const noexcept { return impl_->near(x, y, radius); }
std::size_t Haste::live_tracks() const noexcept { return impl_->live; }
std::size_t Haste::pending_tracks() const noexcept {
    return impl_->pending + impl_->start_now.size() + impl_->collecting;
}
std::uint64_t Haste::skipped_seeds() const noexcept { return impl_->skipped; }
std::uint64_t Haste::track_updates() const noexcept { return impl_->updates; }
EventLimits Haste::limits() const noexcept { return EventLimits{impl_->size}; }
const HasteParams& Haste::params() const noexcept { return impl_->params; }

}  // namespace evcorner
