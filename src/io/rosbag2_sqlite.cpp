// rosbag2's SQLite storage (.db3), read through Debian's libsqlite3: the topics table
// gives the topics, the messages table their CDR payloads, read in row-id order.

#include <sqlite3.h>

#include <fmt/format.h>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <map>

#include "bag_source.hpp"

namespace evcorner::io::detail {

namespace {

std::uint32_t be(const unsigned char* p, int n) {
    std::uint32_t v = 0;
    for (int i = 0; i < n; ++i) v = v << 8 | p[i];
    return v;
}

// SQLite reads a file cut short as if its missing pages were there (zero rows): the
// header's page count (when valid: bytes 24..27 equal bytes 92..95) says how long the
// file must be.
void check_length(const std::string& name, const unsigned char* h, std::size_t have, std::uint64_t size) {
    if (have < 100) throw InputError(name, InputError::Unit::byte, have, "the file ends inside the SQLite header: it is cut short");
    const std::uint32_t page = be(h + 16, 2) == 1 ? 65536 : be(h + 16, 2);
    const std::uint32_t pages = be(h + 28, 4);
    if (pages == 0 || be(h + 24, 4) != be(h + 92, 4)) return;
    const std::uint64_t want = std::uint64_t{pages} * page;
    if (want > size)
        throw InputError(name, InputError::Unit::byte, size,
                         fmt::format("the file ends here, but its SQLite header declares {} pages of {} bytes ({} bytes): "
                                     "it is cut short", pages, page, want));
}

class SqliteBag final : public BagSource {
public:
    SqliteBag(std::string name, std::span<const unsigned char> image) : name_(std::move(name)) {
        if (image.data() == nullptr) {
            unsigned char h[100] = {};
            std::ifstream in(name_, std::ios::binary);
            in.read(reinterpret_cast<char*>(h), sizeof h);
            std::error_code ec;
            check_length(name_, h, static_cast<std::size_t>(in.gcount()), std::filesystem::file_size(name_, ec));
            if (sqlite3_open_v2(name_.c_str(), &db_.p, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) fail("cannot open");
            // Pages read through a memory map: no read() and copy per page of a message's
            // overflow chain (faster: docs/formats.md, Speed).
            sqlite3_exec(db_.p, "PRAGMA mmap_size=1073741824", nullptr, nullptr, nullptr);
        } else {
            // The fuzz targets: an image in memory, read-only, not copied.
            check_length(name_, image.data(), image.size(), image.size());
            if (sqlite3_open_v2(":memory:", &db_.p, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK) fail("cannot open");
            auto* bytes = const_cast<unsigned char*>(image.data());
            const auto n = static_cast<sqlite3_int64>(image.size());
            if (sqlite3_deserialize(db_.p, "main", bytes, n, n, SQLITE_DESERIALIZE_READONLY) != SQLITE_OK)
                fail("cannot read the image");
            total_ = image.size();
        }
        if (image.data() == nullptr) {
            sqlite3_int64 pages = 0, page = 0;
            query1("PRAGMA page_count", pages);
            query1("PRAGMA page_size", page);
            total_ = static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page);
        }
        // The tables rosbag2 writes: anything else is some other SQLite database.
        sqlite3_int64 tables = 0;
        query1("SELECT count(*) FROM sqlite_master WHERE type='table' AND name IN ('topics','messages')", tables);
        if (tables != 2)
            throw InputError(name_, "an SQLite database without the tables 'topics' and 'messages': not a rosbag2 bag");
        Stmt s(*this, "SELECT id, name, type, serialization_format FROM topics ORDER BY id");
        while (s.step()) {
            const sqlite3_int64 id = sqlite3_column_int64(s.s, 0);
            BagTopic t{text(s.s, 1), text(s.s, 2), text(s.s, 3), 0};
            bool merged = false;
            for (std::size_t i = 0; i < topics_.size(); ++i)
                if (topics_[i].name == t.name) {
                    ids_[i].push_back(id);
                    merged = true;
                }
            if (!merged) {
                topics_.push_back(std::move(t));
                ids_.push_back({id});
            }
        }
    }
    ~SqliteBag() override {
        if (read_) sqlite3_finalize(read_);
    }
    SqliteBag(const SqliteBag&) = delete;
    SqliteBag& operator=(const SqliteBag&) = delete;

    // Counting reads every row's header (a pass over the table): only when asked for.
    [[nodiscard]] const std::vector<BagTopic>& topics() const noexcept override {
        if (counted_) return topics_;
        counted_ = true;
        sqlite3_stmt* s = nullptr;
        if (sqlite3_prepare_v2(db_.p, "SELECT topic_id, count(*) FROM messages GROUP BY topic_id", -1, &s, nullptr) !=
            SQLITE_OK)
            return topics_;
        // A damaged table leaves the counts found so far; reading the messages reports it.
        while (sqlite3_step(s) == SQLITE_ROW) {
            const sqlite3_int64 id = sqlite3_column_int64(s, 0);
            for (std::size_t i = 0; i < topics_.size(); ++i)
                for (const auto t : ids_[i])
                    if (t == id) topics_[i].messages += static_cast<std::uint64_t>(sqlite3_column_int64(s, 1));
        }
        sqlite3_finalize(s);
        return topics_;
    }
    [[nodiscard]] const std::vector<BagTopic>& topic_types() const noexcept override { return topics_; }
    void select(const std::string& topic) override {
        if (read_) sqlite3_finalize(read_);
        read_ = nullptr;
        std::string ids;
        for (std::size_t i = 0; i < topics_.size(); ++i)
            if (topics_[i].name == topic) {
                for (const auto id : ids_[i]) ids += fmt::format("{}{}", ids.empty() ? "" : ",", id);
            }
        if (ids.empty()) ids = "-1";
        sqlite3_int64 last = 0;
        query1("SELECT max(id) FROM messages", last);
        max_id_ = static_cast<std::uint64_t>(std::max<sqlite3_int64>(last, 0));
        const std::string sql = "SELECT data, id FROM messages WHERE topic_id IN (" + ids + ") ORDER BY id";
        if (sqlite3_prepare_v2(db_.p, sql.c_str(), -1, &read_, nullptr) != SQLITE_OK) fail("cannot read the messages");
        index_ = 0;
        topic_ = topic;
    }
    bool next(BagMessage& m) override {
        const int rc = sqlite3_step(read_);
        if (rc == SQLITE_DONE) return false;
        if (rc != SQLITE_ROW) fail(fmt::format("reading message {} of topic {}", index_ + 1, escaped(topic_)));
        const void* blob = sqlite3_column_blob(read_, 0);
        const int size = sqlite3_column_bytes(read_, 0);
        m.data = {static_cast<const unsigned char*>(blob), static_cast<std::size_t>(size)};
        m.index = index_++;
        row_ = static_cast<std::uint64_t>(std::max<sqlite3_int64>(sqlite3_column_int64(read_, 1), 0));
        m.offset.reset();
        m.where = "SQLite";
        return true;
    }
    [[nodiscard]] std::string_view format() const noexcept override { return "rosbag2"; }
    [[nodiscard]] const std::string& name() const noexcept override { return name_; }
    // SQLite does not say where it reads: the share of the rows passed, of the file's size.
    [[nodiscard]] std::uint64_t bytes_consumed() const noexcept override {
        if (max_id_ == 0) return 0;
        return static_cast<std::uint64_t>(static_cast<double>(total_) * static_cast<double>(std::min(row_, max_id_)) /
                                          static_cast<double>(max_id_));
    }
    [[nodiscard]] std::optional<std::uint64_t> bytes_total() const noexcept override { return total_; }

private:
    struct Stmt {
        Stmt(SqliteBag& b, const char* sql) : bag(b) {
            if (sqlite3_prepare_v2(b.db_.p, sql, -1, &s, nullptr) != SQLITE_OK) b.fail("cannot read the bag's tables");
        }
        ~Stmt() { sqlite3_finalize(s); }
        Stmt(const Stmt&) = delete;
        Stmt& operator=(const Stmt&) = delete;
        bool step() {
            const int rc = sqlite3_step(s);
            if (rc == SQLITE_ROW) return true;
            if (rc != SQLITE_DONE) bag.fail("cannot read the bag's tables");
            return false;
        }
        SqliteBag& bag;
        sqlite3_stmt* s = nullptr;
    };

    static std::string text(sqlite3_stmt* s, int col) {
        const unsigned char* t = sqlite3_column_text(s, col);
        return t ? std::string(reinterpret_cast<const char*>(t), static_cast<std::size_t>(sqlite3_column_bytes(s, col)))
                 : std::string();
    }
    void query1(const char* sql, sqlite3_int64& v) {
        Stmt s(*this, sql);
        if (s.step()) v = sqlite3_column_int64(s.s, 0);
    }
    [[noreturn]] void fail(const std::string& what) const {
        const char* why = db_.p ? sqlite3_errmsg(db_.p) : "out of memory";
        throw InputError(name_, fmt::format("{}: SQLite: {}", what, escaped(why ? why : "unknown error")));
    }

    // Closed however the constructor ends.
    struct Db {
        sqlite3* p = nullptr;
        ~Db() { sqlite3_close(p); }
    };

    std::string name_;
    Db db_;
    sqlite3_stmt* read_ = nullptr;
    mutable std::vector<BagTopic> topics_;
    mutable bool counted_ = false;
    std::vector<std::vector<sqlite3_int64>> ids_;
    std::string topic_;
    std::uint64_t index_ = 0;
    std::uint64_t row_ = 0;     // the row id of the last message read
    std::uint64_t max_id_ = 0;  // the largest row id
    std::uint64_t total_ = 0;
};

}  // namespace

std::unique_ptr<BagSource> open_sqlite_bag(const std::string& path) {
    return std::make_unique<SqliteBag>(path, std::span<const unsigned char>{});
}

std::unique_ptr<BagSource> sqlite_bag_from_memory(std::span<const unsigned char> bytes, std::string name) {
    static const unsigned char kEmpty = 0;
    // A zero-length image is still an image (an empty database), not a path.
    if (bytes.data() == nullptr) bytes = {&kEmpty, 0};
    return std::make_unique<SqliteBag>(std::move(name), bytes);
}

}  // namespace evcorner::io::detail
