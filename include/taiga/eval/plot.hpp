#pragma once
// PNG plots, drawn by scripts/plot_eval.py with Debian's python3-matplotlib. The C++ side writes
// the series as JSON (report.hpp, compare.hpp) and runs /usr/bin/python3 on the script; a missing
// interpreter or matplotlib is reported as a message, never a crash.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace taiga::eval {

/// Where scripts/plot_eval.py is: $TAIGA_PLOT_SCRIPT when set, else <exe>/../share/taiga/ (an
/// installed tool), else the source tree this library was built from. Empty when none exists.
std::optional<std::filesystem::path> findPlotScript();

struct PlotOutcome {
  bool ok = false;
  std::vector<std::filesystem::path> files;  ///< the PNGs written, as the script reports them
  std::string message;                       ///< what went wrong, for the user, when !ok
};

/// Writes `data_json` to out_dir/<data_name> and runs the plotting script on it, writing the PNGs
/// into out_dir (created if needed).
PlotOutcome makePlots(const std::string& data_json, const std::filesystem::path& out_dir,
                      const std::string& data_name);

}  // namespace taiga::eval
