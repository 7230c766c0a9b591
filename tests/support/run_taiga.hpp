#pragma once
// Runs the `taiga` executable under test through the shell, as users and scripts run it. The
// path comes from TAIGA_EXECUTABLE, which taiga_add_cli_test (tests/CMakeLists.txt) defines.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace taiga::test {

struct TaigaResult {
  int exit_code = -1;  ///< -1 when the command could not be started or did not exit normally
  std::string output;  ///< standard output, and standard error unless dropped
};

/// A shell command's exit code and standard output.
inline TaigaResult runCommand(const std::string& command) {
  TaigaResult result;
  std::FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) result.output += buffer.data();
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

/// `taiga ARGUMENTS`, with `environment` (e.g. "MPLBACKEND=Agg") set for it.
inline TaigaResult runTaiga(const std::string& arguments, bool keep_stderr = true,
                            const std::string& environment = "") {
  return runCommand(environment + " " + std::string(TAIGA_EXECUTABLE) + " " + arguments +
                    (keep_stderr ? " 2>&1" : " 2>/dev/null"));
}

}  // namespace taiga::test
