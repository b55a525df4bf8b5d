#pragma once
// Helpers for the reader tests: crafted files in a temp folder, reading a whole
// stream, the summary figures the data READMEs give for each real recording.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>
#include <unistd.h>

#include "evcorner/error.hpp"
#include "evcorner/event.hpp"
#include "evcorner/io/event_reader.hpp"
#include "npy_bytes.hpp"

namespace evcorner::test {

/// A file in a fresh per-test temp folder, removed at the end of the test.
class TempDir {
public:
    TempDir() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = std::filesystem::temp_directory_path() /
               (std::string("evcorner-") + info->test_suite_name() + "-" + info->name() + "-" +
                std::to_string(::getpid()));
        std::filesystem::create_directories(dir_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(dir_, ec);
    }
    [[nodiscard]] std::string path(const std::string& name) const { return (dir_ / name).string(); }
    std::string write(const std::string& name, const std::string& bytes) const {
        const auto p = path(name);
        std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        return p;
    }

private:
    std::filesystem::path dir_;
};

/// Everything a reader gives until the end or an error; the error, if any, is kept.
struct ReadResult {
    std::vector<Event> events;
    std::uint64_t skipped = 0;
    bool failed = false;
    std::string error;
    std::uint64_t error_position = 0;
    InputError::Unit error_unit = InputError::Unit::none;
};

inline ReadResult read_all(io::EventReader& r, std::size_t batch = 4096) {
    ReadResult res;
    std::vector<Event> buf(batch);
    try {
        for (;;) {
            const std::size_t n = r.read(buf);
            if (n == 0 && r.skipped_in_batch().empty()) break;
            res.events.insert(res.events.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
        }
    } catch (const InputError& e) {
        res.failed = true;
        res.error = e.what();
        res.error_position = e.position();
        res.error_unit = e.unit();
    }
    res.skipped = r.skipped();
    return res;
}

/// The "Verified contents" figures of a data README row.
struct Figures {
    std::uint64_t events;
    std::int64_t t_min, t_max;
    int x_min, x_max, y_min, y_max;
    std::uint64_t on, off;
};

inline void expect_figures(const std::vector<Event>& ev, const Figures& f, const std::string& what) {
    SCOPED_TRACE(what);
    ASSERT_EQ(ev.size(), f.events);
    if (ev.empty()) return;
    std::int64_t tmin = ev.front().t, tmax = ev.front().t;
    int xmin = 1 << 30, xmax = -1, ymin = 1 << 30, ymax = -1;
    std::uint64_t on = 0;
    bool sorted = true;
    for (std::size_t i = 0; i < ev.size(); ++i) {
        const Event& e = ev[i];
        tmin = std::min(tmin, e.t);
        tmax = std::max(tmax, e.t);
        xmin = std::min<int>(xmin, e.x);
        xmax = std::max<int>(xmax, e.x);
        ymin = std::min<int>(ymin, e.y);
        ymax = std::max<int>(ymax, e.y);
        on += e.p != 0;
        if (i > 0 && e.t < ev[i - 1].t) sorted = false;
    }
    EXPECT_EQ(tmin, f.t_min);
    EXPECT_EQ(tmax, f.t_max);
    EXPECT_EQ(xmin, f.x_min);
    EXPECT_EQ(xmax, f.x_max);
    EXPECT_EQ(ymin, f.y_min);
    EXPECT_EQ(ymax, f.y_max);
    EXPECT_EQ(on, f.on);
    EXPECT_EQ(ev.size() - on, f.off);
    EXPECT_TRUE(sorted);
}

/// Big- and little-endian byte packing for crafted files.
inline void put_be32(std::string& s, std::uint32_t v) {
    for (int k = 3; k >= 0; --k) s.push_back(static_cast<char>((v >> (8 * k)) & 0xFF));
}
inline void put_le32(std::string& s, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) s.push_back(static_cast<char>((v >> (8 * k)) & 0xFF));
}
inline void put_le16(std::string& s, std::uint16_t v) {
    s.push_back(static_cast<char>(v & 0xFF));
    s.push_back(static_cast<char>(v >> 8));
}

}  // namespace evcorner::test
