// Outputs written whole or not at all. Files: through a temporary file in the same folder and a
// rename, so that a reader (or a run killed halfway) sees either the old file or the complete new one.
// Folders: everything into OUTPUT.partial, renamed to OUTPUT at the end. The one writer of every
// layer (lidar/util is the base colmap_ext may use too).
#pragma once

#include <functional>
#include <string>

namespace colmap_lidar {

// `write` writes the file at the temporary path it is given (which keeps `path`'s extension, for
// writers that choose the format by it) and returns false or throws on failure; the temporary is then
// removed and std::runtime_error names `path`.
void WriteAtomically(const std::string& path,
                     const std::function<bool(const std::string& temporary_path)>& write);

// Writes `contents` to `path` atomically.
void WriteFileAtomically(const std::string& path, const std::string& contents);

// An output folder built as OUTPUT.partial and put in place by Commit(). Destroyed without Commit()
// (an exception on the way), it removes OUTPUT.partial: OUTPUT is never half-written, and a failed
// run leaves no partial folder behind.
class PartialOutputFolder {
 public:
  // Removes a stale OUTPUT.partial and creates it empty.
  explicit PartialOutputFolder(const std::string& output_path);
  ~PartialOutputFolder();
  PartialOutputFolder(const PartialOutputFolder&) = delete;
  PartialOutputFolder& operator=(const PartialOutputFolder&) = delete;

  // OUTPUT.partial, and a file in it.
  const std::string& Path() const { return partial_path_; }
  std::string File(const std::string& name) const;

  // Replaces OUTPUT (if it exists) by the folder.
  void Commit();

 private:
  const std::string output_path_;
  const std::string partial_path_;
  bool committed_ = false;
};

}  // namespace colmap_lidar
