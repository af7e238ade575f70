#include "colmap_ext/sqlite_connection.h"

#include <sqlite3.h>

#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <thread>

namespace colmap_lidar {

SqliteConnection::SqliteConnection(const std::string& path, Mode mode, int busy_timeout_ms)
    : path_(path), mode_(mode) {
  if (!std::filesystem::is_regular_file(path)) {
    throw std::runtime_error("Database file does not exist: " + path);
  }
  const int flags = mode == Mode::kReadOnly ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE;
  const int rc = sqlite3_open_v2(path.c_str(), &db_, flags, nullptr);
  if (rc != SQLITE_OK) {
    const std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw std::runtime_error("Cannot open database " + path + ": " + message);
  }
  sqlite3_busy_timeout(db_, busy_timeout_ms);
  sqlite3_extended_result_codes(db_, 1);
  try {
    // Foreign keys are per connection in SQLite; COLMAP enables them on its own.
    Execute("PRAGMA foreign_keys=ON");
    // Fails early, with a clear message, on a file that is not an SQLite database.
    Check(sqlite3_exec(db_, "SELECT count(*) FROM sqlite_master", nullptr, nullptr, nullptr),
          "Reading the schema");
  } catch (...) {
    // A constructor that throws runs no destructor: close the handle here (AddressSanitizer's leak
    // check found it open after "file is not a database").
    sqlite3_close_v2(db_);
    db_ = nullptr;
    throw;
  }
}

SqliteConnection::~SqliteConnection() { sqlite3_close_v2(db_); }

void SqliteConnection::Check(int rc, const std::string& what) const {
  if (rc == SQLITE_OK || rc == SQLITE_ROW || rc == SQLITE_DONE) return;
  std::string message = sqlite3_errmsg(db_);
  if ((rc & 0xff) == SQLITE_BUSY || (rc & 0xff) == SQLITE_LOCKED) {
    message += " (another process holds a lock on the database; close it and retry)";
  } else if ((rc & 0xff) == SQLITE_READONLY) {
    message += " (the database is read-only)";
  }
  throw std::runtime_error(what + " failed on " + path_ + ": " + message);
}

void SqliteConnection::Execute(const std::string& sql) const {
  char* error = nullptr;
  const int rc = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error);
  sqlite3_free(error);
  Check(rc, "'" + sql.substr(0, 60) + "'");
}

bool SqliteConnection::TableExists(const std::string& table) const {
  SqliteStatement stmt(*this, "SELECT 1 FROM sqlite_master WHERE type='table' AND name=?");
  stmt.BindText(1, table);
  return stmt.Step();
}

bool SqliteConnection::HasTables() const {
  SqliteStatement stmt(*this, "SELECT 1 FROM sqlite_master WHERE type='table' LIMIT 1");
  return stmt.Step();
}

SqliteStatement::SqliteStatement(const SqliteConnection& connection, const std::string& sql)
    : connection_(connection) {
  connection_.Check(sqlite3_prepare_v2(connection_.Handle(), sql.c_str(), -1, &stmt_, nullptr),
                    "Preparing '" + sql.substr(0, 60) + "'");
}

SqliteStatement::~SqliteStatement() { sqlite3_finalize(stmt_); }

void SqliteStatement::BindInt64(int index, int64_t value) {
  connection_.Check(sqlite3_bind_int64(stmt_, index, value), "Binding");
}

void SqliteStatement::BindDouble(int index, double value) {
  connection_.Check(sqlite3_bind_double(stmt_, index, value), "Binding");
}

void SqliteStatement::BindText(int index, const std::string& value) {
  connection_.Check(sqlite3_bind_text(stmt_, index, value.c_str(), -1, SQLITE_TRANSIENT),
                    "Binding");
}

void SqliteStatement::BindBlob(int index, const void* data, int num_bytes) {
  connection_.Check(sqlite3_bind_blob(stmt_, index, data, num_bytes, SQLITE_TRANSIENT), "Binding");
}

void SqliteStatement::BindNull(int index) {
  connection_.Check(sqlite3_bind_null(stmt_, index), "Binding");
}

bool SqliteStatement::Step() {
  const int rc = sqlite3_step(stmt_);
  connection_.Check(rc, "Executing '" + std::string(sqlite3_sql(stmt_)).substr(0, 60) + "'");
  return rc == SQLITE_ROW;
}

void SqliteStatement::Execute() {
  while (Step()) {
  }
}

void SqliteStatement::Reset() {
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
}

int64_t SqliteStatement::ColumnInt64(int column) const {
  return sqlite3_column_int64(stmt_, column);
}

double SqliteStatement::ColumnDouble(int column) const {
  return sqlite3_column_double(stmt_, column);
}

std::string SqliteStatement::ColumnText(int column) const {
  const unsigned char* text = sqlite3_column_text(stmt_, column);
  return text ? reinterpret_cast<const char*>(text) : "";
}

std::vector<double> SqliteStatement::ColumnDoubleBlob(int column) const {
  const int num_bytes = sqlite3_column_bytes(stmt_, column);
  std::vector<double> values(num_bytes / sizeof(double));
  if (!values.empty()) {
    const auto* data = static_cast<const double*>(sqlite3_column_blob(stmt_, column));
    std::copy(data, data + values.size(), values.begin());
  }
  return values;
}

bool SqliteStatement::ColumnIsNull(int column) const {
  return sqlite3_column_type(stmt_, column) == SQLITE_NULL;
}

SqliteTransaction::SqliteTransaction(const SqliteConnection& connection) : connection_(connection) {
  connection_.Execute("BEGIN IMMEDIATE");
}

SqliteTransaction::~SqliteTransaction() {
  if (!committed_) {
    sqlite3_exec(connection_.Handle(), "ROLLBACK", nullptr, nullptr, nullptr);
  }
}

void SqliteTransaction::Commit() {
  connection_.Execute("COMMIT");
  committed_ = true;
}

void CopySqliteDatabase(const std::string& from, const std::string& to, int busy_timeout_ms) {
  const SqliteConnection source(from, SqliteConnection::Mode::kReadOnly, busy_timeout_ms);
  sqlite3* destination = nullptr;
  if (sqlite3_open_v2(
          to.c_str(), &destination, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
      SQLITE_OK) {
    const std::string message = destination ? sqlite3_errmsg(destination) : "out of memory";
    sqlite3_close(destination);
    throw std::runtime_error("Cannot open " + to + ": " + message);
  }
  sqlite3_busy_timeout(destination, busy_timeout_ms);
  sqlite3_backup* backup = sqlite3_backup_init(destination, "main", source.Handle(), "main");
  if (backup == nullptr) {
    const std::string message = sqlite3_errmsg(destination);
    sqlite3_close(destination);
    throw std::runtime_error("Cannot copy " + from + " to " + to + ": " + message);
  }
  const auto start = std::chrono::steady_clock::now();
  int status = SQLITE_OK;
  while (true) {
    status = sqlite3_backup_step(backup, -1);
    if (status != SQLITE_BUSY && status != SQLITE_LOCKED) break;
    if (std::chrono::steady_clock::now() - start > std::chrono::milliseconds(busy_timeout_ms)) {
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  sqlite3_backup_finish(backup);
  const std::string message = sqlite3_errmsg(destination);
  sqlite3_close(destination);
  if (status == SQLITE_BUSY || status == SQLITE_LOCKED) {
    throw std::runtime_error("Database is locked by another process: " + from + " -> " + to);
  }
  if (status != SQLITE_DONE) {
    throw std::runtime_error("Cannot copy " + from + " to " + to + ": " + message);
  }
}

}  // namespace colmap_lidar
