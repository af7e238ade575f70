// Runs a shell command for integration tests and captures its exit code and combined output.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace colmap_lidar {
namespace testing {

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

inline CommandResult RunCommand(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) {
    result.output.append(buffer.data(), n);
  }
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// For steps inside helpers that return a value (where ASSERT_* cannot stop the test): a failed step
// throws, GoogleTest reports the exception with the command and its output, and the test stops there
// instead of failing later in confusing ways.
inline CommandResult RunStep(const std::string& command) {
  CommandResult result = RunCommand(command);
  if (result.exit_code != 0) {
    throw std::runtime_error("step failed (exit " + std::to_string(result.exit_code) +
                             "): " + command + "\n" + result.output);
  }
  return result;
}

}  // namespace testing
}  // namespace colmap_lidar
