#include "saloam/io/db3.hpp"

#include <sqlite3.h>

#include <map>

#include <fmt/format.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

/// A prepared statement, finalised when it goes.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql, const fs::path& file) : file_(file) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK) {
      throw InputError(file, fmt::format("not a rosbag2 database: {}", sqlite3_errmsg(db)));
    }
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  void bind(int index, std::int64_t value) { sqlite3_bind_int64(stmt_, index, value); }
  void bind(int index, const std::string& value) {
    sqlite3_bind_text(stmt_, index, value.c_str(), static_cast<int>(value.size()), SQLITE_TRANSIENT);
  }
  void bind(int index, std::span<const std::byte> value) {
    sqlite3_bind_blob64(stmt_, index, value.data(), value.size(), SQLITE_STATIC);
  }
  /// True while there is a row; InputError for a corrupt database, or when
  /// the work was cut short (bounded_work: stopped, or beyond its budget).
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    if (rc == SQLITE_INTERRUPT) {
      throw InputError(file_, stop_requested() ? "reading the rosbag2 database stopped (interrupted)"
                                               : "reading the rosbag2 database stopped: it needs more work than a bag "
                                                 "of its size (its index is read with bounded work)");
    }
    throw InputError(file_, fmt::format("corrupt rosbag2 database: {}", sqlite3_errmsg(sqlite3_db_handle(stmt_))));
  }
  void reset() { sqlite3_reset(stmt_); }
  [[nodiscard]] std::int64_t integer(int column) const { return sqlite3_column_int64(stmt_, column); }
  [[nodiscard]] std::string text(int column) const {
    const auto* p = sqlite3_column_text(stmt_, column);
    return p ? std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(sqlite3_column_bytes(stmt_, column))) : std::string();
  }

 private:
  sqlite3_stmt* stmt_ = nullptr;
  const fs::path& file_;
};

void execute(sqlite3* db, const char* sql, const fs::path& file) {
  char* message = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string text = message ? message : "unknown error";
    sqlite3_free(message);
    throw InputError(file, fmt::format("cannot write the rosbag2 database: {}", text));
  }
}

// SQLite calls the progress handler every kProgressOpcodes virtual-machine
// instructions; a read is interrupted on Ctrl-C or when it has taken
// kOpcodesPerByte instructions per byte of the file beyond kBaseOpcodes:
// listing and sorting the messages of a real bag takes far fewer, a query
// that never ends (a view's endless recursion) is cut off.
constexpr int kProgressOpcodes = 1000;
constexpr std::uint64_t kOpcodesPerByte = 64;
constexpr std::uint64_t kBaseOpcodes = 1'000'000'000;

struct WorkBudget {
  std::uint64_t calls_left = 0;
};

int bounded_work(void* budget) {
  auto* b = static_cast<WorkBudget*>(budget);
  if (stop_requested() || b->calls_left == 0) return 1;
  --b->calls_left;
  return 0;
}

// A bag's data are read from its tables only: `messages` or `topics` as a
// view (which may compute anything, forever) is refused.
void require_tables(sqlite3* db, const fs::path& file) {
  for (const char* name : {"messages", "topics"}) {
    Statement kind(db, "SELECT type FROM sqlite_master WHERE name = ?", file);
    kind.bind(1, std::string(name));
    if (!kind.step()) throw InputError(file, fmt::format("not a rosbag2 database: no table '{}'", name));
    if (kind.text(0) != "table") {
      throw InputError(file, fmt::format("not a rosbag2 database: '{}' is a {}, not a table (a bag is read from its "
                                         "tables only)", name, kind.text(0)));
    }
  }
}

std::uint64_t size_of(const fs::path& file) {
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (ec) throw InputError(file, fmt::format("cannot read size: {}", ec.message()));
  return size;
}

}  // namespace

struct Db3Reader::Impl {
  sqlite3* db = nullptr;
  std::uint64_t file_size = 0;
  WorkBudget budget;
  std::vector<std::int64_t> rows;  ///< of the selected topic, in log-time order
  ~Impl() { sqlite3_close(db); }
};

Db3Reader::Db3Reader(fs::path file) : file_(std::move(file)), impl_(std::make_unique<Impl>()) {
  require_file(file_, "rosbag2 database");
  impl_->file_size = size_of(file_);
  if (sqlite3_open_v2(file_.c_str(), &impl_->db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    throw InputError(file_, fmt::format("cannot open the rosbag2 database: {}", sqlite3_errmsg(impl_->db)));
  }
  sqlite3_db_config(impl_->db, SQLITE_DBCONFIG_DEFENSIVE, 1, nullptr);
  impl_->budget.calls_left = (kBaseOpcodes + kOpcodesPerByte * impl_->file_size) / kProgressOpcodes;
  sqlite3_progress_handler(impl_->db, kProgressOpcodes, bounded_work, &impl_->budget);
  require_tables(impl_->db, file_);
  std::map<std::int64_t, std::size_t> counts;
  Statement count(impl_->db, "SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id", file_);
  while (count.step()) counts[count.integer(0)] = static_cast<std::size_t>(count.integer(1));
  Statement topics(impl_->db, "SELECT id, name, type, serialization_format FROM topics ORDER BY name", file_);
  while (topics.step()) {
    topics_.push_back({topics.text(1), topics.text(2), topics.text(3), counts[topics.integer(0)]});
  }
}

Db3Reader::~Db3Reader() = default;

std::vector<std::int64_t> Db3Reader::select(const std::string& topic) {
  Statement query(impl_->db,
                  "SELECT messages.id, messages.timestamp FROM messages JOIN topics ON messages.topic_id = topics.id "
                  "WHERE topics.name = ? ORDER BY messages.timestamp, messages.id",
                  file_);
  query.bind(1, topic);
  std::vector<std::int64_t> times;
  impl_->rows.clear();
  while (query.step()) {
    impl_->rows.push_back(query.integer(0));
    times.push_back(query.integer(1));
  }
  return times;
}

std::vector<std::byte> Db3Reader::message(std::size_t k, std::size_t max_bytes) {
  sqlite3_blob* blob = nullptr;
  if (sqlite3_blob_open(impl_->db, "main", "messages", "data", impl_->rows.at(k), 0, &blob) != SQLITE_OK) {
    const std::string why = sqlite3_errmsg(impl_->db);
    sqlite3_blob_close(blob);
    throw InputError(file_, fmt::format("corrupt rosbag2 database: message {}: {}", impl_->rows[k], why));
  }
  const auto size = static_cast<std::uint64_t>(sqlite3_blob_bytes(blob));
  if (size > impl_->file_size) {
    sqlite3_blob_close(blob);
    throw InputError(file_, fmt::format("corrupt rosbag2 database: message {} of {} bytes in a file of {}", impl_->rows[k], size, impl_->file_size));
  }
  std::vector<std::byte> bytes(std::min<std::uint64_t>(size, max_bytes));
  const int rc = sqlite3_blob_read(blob, bytes.data(), static_cast<int>(bytes.size()), 0);
  sqlite3_blob_close(blob);
  if (rc != SQLITE_OK) {
    throw InputError(file_, fmt::format("corrupt rosbag2 database: message {}: {}", impl_->rows[k], sqlite3_errstr(rc)));
  }
  return bytes;
}

struct Db3Writer::Impl {
  sqlite3* db = nullptr;
  std::unique_ptr<Statement> insert;
  bool open = true;
  ~Impl() {
    insert.reset();
    sqlite3_close(db);
  }
};

Db3Writer::Db3Writer(fs::path file) : file_(std::move(file)), impl_(std::make_unique<Impl>()) {
  std::error_code ec;
  if (fs::exists(file_, ec)) throw InputError(file_, "exists: write a rosbag2 database into a new file");
  if (sqlite3_open_v2(file_.c_str(), &impl_->db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) != SQLITE_OK) {
    throw InputError(file_, fmt::format("cannot create the rosbag2 database: {}", sqlite3_errmsg(impl_->db)));
  }
  execute(impl_->db,
          "PRAGMA journal_mode=MEMORY; PRAGMA synchronous=OFF; BEGIN;"
          "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
          "INSERT INTO schema VALUES(3, 'humble');"
          "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);"
          "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
          "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
          "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
          "data BLOB NOT NULL);"
          "CREATE INDEX timestamp_idx ON messages (timestamp ASC);",
          file_);
  impl_->insert = std::make_unique<Statement>(impl_->db, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?, ?, ?)", file_);
}

Db3Writer::~Db3Writer() {
  try {
    if (impl_->open) close("");
  } catch (const std::exception&) {
    // A destructor must not throw; close() explicitly to see the error.
  }
}

std::int64_t Db3Writer::add_topic(const std::string& name, const std::string& type) {
  Statement insert(impl_->db, "INSERT INTO topics(name, type, serialization_format, offered_qos_profiles) VALUES(?, ?, 'cdr', '')", file_);
  insert.bind(1, name);
  insert.bind(2, type);
  insert.step();
  return sqlite3_last_insert_rowid(impl_->db);
}

void Db3Writer::write(std::int64_t topic_id, std::int64_t time_ns, std::span<const std::byte> data) {
  Statement& insert = *impl_->insert;
  insert.reset();
  insert.bind(1, topic_id);
  insert.bind(2, time_ns);
  insert.bind(3, data);
  insert.step();
}

void Db3Writer::close(const std::string& metadata_yaml) {
  if (!impl_->open) return;
  impl_->open = false;
  impl_->insert.reset();
  Statement insert(impl_->db, "INSERT INTO metadata(metadata_version, metadata) VALUES(5, ?)", file_);
  insert.bind(1, metadata_yaml);
  insert.step();
  execute(impl_->db, "COMMIT;", file_);
}

}  // namespace saloam
