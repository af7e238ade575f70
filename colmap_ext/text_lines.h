// Line-oriented text files (KITTI calibration, poses, times and OXTS packets; TUM trajectories):
// every reader reports a bad value as "FILE:LINE: problem", one helper for all of them.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace colmap_lidar {

// Calls `visit(line, line_number)` for every line of `path` that is neither blank nor a '#' comment
// (a trailing '\r' removed; numbers count from 1). Throws std::runtime_error when the file cannot
// be opened.
void ForEachDataLine(const std::string& path,
                     const std::function<void(const std::string& line, size_t line_number)>& visit);

// The whitespace-separated numbers of `text`; `expected_count` > 0 demands exactly that many. Throws
// std::runtime_error "PATH:LINE: ..." for a token that is not a finite number or a wrong count.
std::vector<double> ParseNumberLine(const std::string& text,
                                    const std::string& path,
                                    size_t line_number,
                                    size_t expected_count);

// For files whose line k serves frame k: throws "PATH:LAST_LINE: the file ends after COUNT WHAT, but
// frame MIN_COUNT-1 needs one" when COUNT < MIN_COUNT.
void CheckEnoughLines(const std::string& path,
                      size_t last_line,
                      size_t count,
                      size_t min_count,
                      const std::string& what);

// "PATH:LINE: problem" as a std::runtime_error.
[[noreturn]] void FailAtLine(const std::string& path,
                             size_t line_number,
                             const std::string& problem);

}  // namespace colmap_lidar
