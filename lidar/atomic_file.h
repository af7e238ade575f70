// Files written whole or not at all: through a temporary file in the same folder and a rename, so that
// a reader (or a run killed halfway) sees either the old file or the complete new one. (colmap_ext/ has
// the same helper, colmap_ext/atomic_file.h: the layers may not include each other; the bridge uses
// that one.)
#pragma once

#include <functional>
#include <string>

namespace colmap_lidar {

// `write` writes the file at the temporary path it is given (which keeps `path`'s extension, for
// writers that choose the format by it) and returns false or throws on failure; the temporary is then
// removed and std::runtime_error names `path`.
void WriteLidarFileAtomically(const std::string& path,
                              const std::function<bool(const std::string& temporary_path)>& write);

}  // namespace colmap_lidar
