#include "colmap_ext/text_lines.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {

void FailAtLine(const std::string& path, size_t line_number, const std::string& problem) {
  throw std::runtime_error(path + ":" + std::to_string(line_number) + ": " + problem);
}

void CheckEnoughLines(const std::string& path,
                      size_t last_line,
                      size_t count,
                      size_t min_count,
                      const std::string& what) {
  if (count >= min_count) return;
  FailAtLine(path,
             last_line,
             "the file ends after " + std::to_string(count) + " " + what + ", but frame " +
                 std::to_string(min_count - 1) + " needs one");
}

void ForEachDataLine(
    const std::string& path,
    const std::function<void(const std::string& line, size_t line_number)>& visit) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot open " + path);
  std::string line;
  for (size_t number = 1; std::getline(file, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    visit(line, number);
  }
}

std::vector<double> ParseNumberLine(const std::string& text,
                                    const std::string& path,
                                    size_t line_number,
                                    size_t expected_count) {
  std::istringstream tokens(text);
  std::vector<double> numbers;
  std::string token;
  while (tokens >> token) {
    size_t used = 0;
    double value = NAN;
    try {
      value = std::stod(token, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != token.size() || !std::isfinite(value)) {
      FailAtLine(path, line_number, "'" + token + "' is not a finite number");
    }
    numbers.push_back(value);
  }
  if (expected_count > 0 && numbers.size() != expected_count) {
    FailAtLine(path,
               line_number,
               std::to_string(numbers.size()) + " values where " + std::to_string(expected_count) +
                   " are expected");
  }
  return numbers;
}

}  // namespace colmap_lidar
