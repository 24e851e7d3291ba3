// rosbag2 databases are data (issue #53): read from their tables only, with
// bounded work, and Ctrl-C answered.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <chrono>
#include <string>

#include "saloam/core/cancellation.hpp"
#include "saloam/io/db3.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

void make_database(const std::filesystem::path& file, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  char* message = nullptr;
  const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &message);
  const std::string error = message ? message : "";
  sqlite3_free(message);
  sqlite3_close(db);
  ASSERT_EQ(rc, SQLITE_OK) << error;
}

std::string error_opening(const std::filesystem::path& file) {
  return testing::input_error_of([&] { Db3Reader reader(file); });
}

const std::string kTables =
    "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, serialization_format TEXT, "
    "offered_qos_profiles TEXT);"
    "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, data BLOB);"
    "INSERT INTO topics VALUES(1, '/points', 'sensor_msgs/msg/PointCloud2', 'cdr', '');";

TEST(Db3, ViewsInPlaceOfTheTablesAreRefusedAtOnce) {
  testing::TempDir dir("saloam_db3");
  // The probe's bag: `topics` an endless recursive view (it never returned).
  make_database(dir.path() / "view.db3",
                "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, data BLOB);"
                "CREATE VIEW topics AS WITH RECURSIVE c(x) AS (SELECT 1 UNION ALL SELECT x + 1 FROM c) "
                "SELECT x id, '/p' || x name, 'sensor_msgs/msg/PointCloud2' type, 'cdr' serialization_format FROM c;");
  const auto start = std::chrono::steady_clock::now();
  const std::string error = error_opening(dir.path() / "view.db3");
  EXPECT_NE(error.find("view.db3: not a rosbag2 database: 'topics' is a view, not a table"), std::string::npos) << error;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  make_database(dir.path() / "none.db3", "CREATE TABLE other(x INTEGER);");
  EXPECT_NE(error_opening(dir.path() / "none.db3").find("no table 'messages'"), std::string::npos);
  make_database(dir.path() / "good.db3", kTables);
  EXPECT_EQ(error_opening(dir.path() / "good.db3"), "no error");
}

// Ctrl-C while the index is read: the work stops with an error naming the file.
TEST(Db3, CtrlCStopsReadingTheIndex) {
  testing::TempDir dir("saloam_db3_stop");
  make_database(dir.path() / "big.db3",
                kTables + "WITH RECURSIVE c(x) AS (SELECT 1 UNION ALL SELECT x + 1 FROM c WHERE x < 20000) "
                          "INSERT INTO messages SELECT x, 1, x, zeroblob(8) FROM c;");
  Db3Reader reader(dir.path() / "big.db3");
  ASSERT_EQ(reader.topics().size(), 1u);
  EXPECT_EQ(reader.topics()[0].messages, 20000u);
  request_stop();
  const std::string error = testing::input_error_of([&] { (void)reader.select("/points"); });
  clear_stop();
  EXPECT_NE(error.find("big.db3: reading the rosbag2 database stopped (interrupted)"), std::string::npos) << error;
  EXPECT_EQ(reader.select("/points").size(), 20000u);
}

}  // namespace
}  // namespace saloam
