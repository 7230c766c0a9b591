// taiga view: the web viewer on a finished run or any point cloud (docs/viewer.md), served until
// Ctrl-C or SIGTERM.
#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <thread>

#include "command.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/live_config.hpp"
#include "taiga/view/run_view.hpp"

namespace taiga::app {
namespace {

struct ViewOptions {
  std::string input;
  std::string bind = "127.0.0.1:8080";
};

std::atomic<bool> stop_requested{false};
void stopOnSignal(int /*signal*/) { stop_requested = true; }

int runView(const ViewOptions& options) {
  const auto address = udpAddressPort(options.bind);
  if (!address)
    throw InputError(fmt::format("--bind: expected host:port, found '{}'", options.bind));
  const auto start = std::chrono::steady_clock::now();
  const view::RunView run_view = view::RunView::load(options.input);
  const double load_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stream::FoxgloveServer server(
      address->first, address->second, {}, "taiga view", 64u << 20,
      [&run_view](const std::string& resource) { return run_view.get(resource); });
  fmt::print("view       {} points in {} level-of-detail nodes, read and indexed in {:.1f} s\n",
             run_view.tree().pointCount(), run_view.tree().nodes().size(), load_s);
  fmt::print("serving    http://{}:{}/ (Ctrl-C ends)\n", address->first, server.port());
  std::fflush(stdout);
  std::signal(SIGINT, stopOnSignal);
  std::signal(SIGTERM, stopOnSignal);
  while (!stop_requested) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  return kExitOk;
}

}  // namespace

Command addViewCommand(CLI::App& tool) {
  auto options = std::make_shared<ViewOptions>();
  CLI::App* parser = tool.add_subcommand(
      "view", "Show a run's map, trajectory and health in a web browser (docs/viewer.md)");
  parser
      ->add_option("INPUT", options->input,
                   "A run directory of `taiga run` or a LAS/PLY/PCD point cloud")
      ->required();
  parser->add_option("--bind", options->bind,
                     "HOST:PORT to serve on (default 127.0.0.1:8080; 0.0.0.0 for other machines)");
  return {parser, [options] { return runView(*options); }, options};
}

}  // namespace taiga::app
