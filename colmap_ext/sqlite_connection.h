// A small RAII layer over one SQLite connection: errors become exceptions that name the database file,
// statements are finalized automatically, and transactions roll back unless committed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace colmap_lidar {

class SqliteConnection;

// A prepared statement. Bind*() indices are 1-based as in SQLite.
class SqliteStatement {
 public:
  SqliteStatement(const SqliteConnection& connection, const std::string& sql);
  ~SqliteStatement();
  SqliteStatement(const SqliteStatement&) = delete;
  SqliteStatement& operator=(const SqliteStatement&) = delete;

  void BindInt64(int index, int64_t value);
  void BindDouble(int index, double value);
  void BindText(int index, const std::string& value);
  void BindBlob(int index, const void* data, int num_bytes);
  void BindNull(int index);

  // Steps once. Returns true while a row is available, false when done.
  bool Step();
  // Steps to completion of a statement that returns no rows.
  void Execute();
  void Reset();

  int64_t ColumnInt64(int column) const;
  double ColumnDouble(int column) const;
  std::string ColumnText(int column) const;
  std::vector<double> ColumnDoubleBlob(int column) const;
  bool ColumnIsNull(int column) const;

 private:
  const SqliteConnection& connection_;
  sqlite3_stmt* stmt_ = nullptr;
};

class SqliteConnection {
 public:
  enum class Mode { kReadWrite, kReadOnly };

  // Opens an existing database file; never creates one. Throws std::runtime_error naming the file.
  SqliteConnection(const std::string& path, Mode mode, int busy_timeout_ms);
  ~SqliteConnection();
  SqliteConnection(const SqliteConnection&) = delete;
  SqliteConnection& operator=(const SqliteConnection&) = delete;

  void Execute(const std::string& sql) const;
  bool TableExists(const std::string& table) const;
  // Whether the database holds any table (an empty file holds none).
  bool HasTables() const;
  // Throws std::runtime_error "<what> failed on <path>: <sqlite message>" when rc is an error.
  void Check(int rc, const std::string& what) const;

  const std::string& Path() const { return path_; }
  Mode OpenMode() const { return mode_; }
  sqlite3* Handle() const { return db_; }

 private:
  std::string path_;
  Mode mode_;
  sqlite3* db_ = nullptr;
};

// BEGIN IMMEDIATE on construction (takes the write lock up front, so a locked database fails before
// anything is written); ROLLBACK on destruction unless Commit() was called.
class SqliteTransaction {
 public:
  explicit SqliteTransaction(const SqliteConnection& connection);
  ~SqliteTransaction();
  SqliteTransaction(const SqliteTransaction&) = delete;
  SqliteTransaction& operator=(const SqliteTransaction&) = delete;

  void Commit();

 private:
  const SqliteConnection& connection_;
  bool committed_ = false;
};

// Copies the whole database `from` into `to` with SQLite's online backup API: a consistent snapshot of
// `from` (its write-ahead log included, which a file copy would lose: COLMAP databases are in WAL mode),
// written into `to` as one transaction (created if absent). Retries while either is locked, up to
// `busy_timeout_ms`, then throws naming the locked file.
void CopySqliteDatabase(const std::string& from, const std::string& to, int busy_timeout_ms = 5000);

}  // namespace colmap_lidar
