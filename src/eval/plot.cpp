#include "taiga/eval/plot.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

extern char** environ;

namespace taiga::eval {
namespace {

constexpr const char* kPython = "/usr/bin/python3";
constexpr int kExitNoMatplotlib = 3;  // scripts/plot_eval.py's exit code without matplotlib

// In the source tree the library was compiled from: TAIGA_SOURCE_DIR, which CMakeLists.txt
// defines for this file (not __FILE__, which the compiler cache makes relative to the tree).
std::filesystem::path sourceTreeScript() {
  return std::filesystem::path(TAIGA_SOURCE_DIR) / "scripts" / "plot_eval.py";
}

std::string readAll(const std::filesystem::path& path) {
  std::ifstream stream(path);
  std::stringstream text;
  text << stream.rdbuf();
  return text.str();
}

}  // namespace

std::optional<std::filesystem::path> findPlotScript() {
  std::error_code error;
  if (const char* env = std::getenv("TAIGA_PLOT_SCRIPT"); env != nullptr && *env != '\0') {
    if (std::filesystem::is_regular_file(env, error)) return std::filesystem::path(env);
    return std::nullopt;
  }
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    const std::filesystem::path installed =
        exe.parent_path().parent_path() / "share" / "taiga" / "plot_eval.py";
    if (std::filesystem::is_regular_file(installed, error)) return installed;
  }
  const std::filesystem::path source = sourceTreeScript();
  if (source.is_absolute() && std::filesystem::is_regular_file(source, error)) return source;
  return std::nullopt;
}

PlotOutcome makePlots(const std::string& data_json, const std::filesystem::path& out_dir,
                      const std::string& data_name) {
  PlotOutcome outcome;
  std::error_code error;
  std::filesystem::create_directories(out_dir, error);
  if (error) {
    outcome.message =
        fmt::format("{}: cannot create the plot directory: {}", out_dir.string(), error.message());
    return outcome;
  }
  const std::filesystem::path data_path = out_dir / data_name;
  {
    std::ofstream data(data_path);
    data << data_json;
    if (!data) {
      outcome.message = fmt::format("{}: cannot write the plot data", data_path.string());
      return outcome;
    }
  }
  const std::optional<std::filesystem::path> script = findPlotScript();
  if (!script) {
    outcome.message =
        "plots not made: scripts/plot_eval.py not found (set TAIGA_PLOT_SCRIPT to its path)";
    return outcome;
  }
  if (::access(kPython, X_OK) != 0) {
    outcome.message = fmt::format(
        "plots not made: {} not found; install python3 and python3-matplotlib (apt install "
        "python3-matplotlib)",
        kPython);
    return outcome;
  }
  // The script prints the names of the files it wrote, one per line, into a listing file.
  const std::filesystem::path listing = out_dir / (data_name + ".written");
  std::filesystem::remove(listing, error);
  const std::string script_arg = script->string(), data_arg = data_path.string(),
                    out_arg = out_dir.string(), listing_arg = listing.string();
  std::vector<char*> argv{const_cast<char*>(kPython),
                          const_cast<char*>(script_arg.c_str()),
                          const_cast<char*>(data_arg.c_str()),
                          const_cast<char*>(out_arg.c_str()),
                          const_cast<char*>(listing_arg.c_str()),
                          nullptr};
  pid_t pid = 0;
  const int spawn_error = ::posix_spawn(&pid, kPython, nullptr, nullptr, argv.data(), environ);
  if (spawn_error != 0) {
    outcome.message =
        fmt::format("plots not made: cannot run {}: {}", kPython, std::strerror(spawn_error));
    return outcome;
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      outcome.message = fmt::format("plots not made: waiting for {} failed", kPython);
      return outcome;
    }
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    outcome.message =
        code == kExitNoMatplotlib
            ? "plots not made: python3-matplotlib is not installed (apt install "
              "python3-matplotlib)"
            : fmt::format("plots not made: {} {} failed (exit {}); its message is above", kPython,
                          script_arg, code);
    return outcome;
  }
  std::istringstream lines(readAll(listing));
  for (std::string line; std::getline(lines, line);)
    if (!line.empty()) outcome.files.emplace_back(line);
  std::filesystem::remove(listing, error);
  outcome.ok = true;
  return outcome;
}

}  // namespace taiga::eval
