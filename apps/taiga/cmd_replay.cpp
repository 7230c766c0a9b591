// taiga replay: a capture's UDP packets sent again at their recorded pace (io/replay.hpp).
#include <fmt/format.h>

#include <memory>

#include "command.hpp"
#include "taiga/io/replay.hpp"

namespace taiga::app {
namespace {

struct ReplayCommandOptions {
  std::string capture;
  io::ReplayOptions replay;
};

int runReplay(const ReplayCommandOptions& options) {
  const io::ReplayReport r = io::replayCapture(options.capture, options.replay);
  fmt::print(
      "sent {} datagrams ({:.1f} MB) to {}: {:.1f} s of capture in {:.1f} s; at most {:.1f} ms "
      "late{}\n",
      r.datagrams, static_cast<double>(r.bytes) / 1e6, options.replay.host, r.capture_s, r.wall_s,
      r.max_late_ms,
      r.refused > 0 ? fmt::format("; {} refused (nobody listening?)", r.refused) : "");
  fmt::print("first datagram sent at Unix time {:.6f} s, its capture time {:.6f} s\n",
             r.start_unix_s, r.first_capture_s);
  return r.datagrams > 0 ? kExitOk : kExitBadInput;
}

}  // namespace

Command addReplayCommand(CLI::App& tool) {
  auto options = std::make_shared<ReplayCommandOptions>();
  CLI::App* parser = tool.add_subcommand(
      "replay", "Send a capture's UDP packets to a host at their recorded pace, as the sensor did");
  parser->add_option("CAPTURE", options->capture, "pcap or pcapng capture")
      ->required()
      ->check(CLI::ExistingFile);
  parser->add_option("--to", options->replay.host, "Host to send to")->capture_default_str();
  parser
      ->add_option("--rate", options->replay.rate,
                   "Pace: x the recorded one (2: twice as fast); 0: as fast as possible")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  parser
      ->add_option("--port-offset", options->replay.port_offset,
                   "Added to every destination port (e.g. 10000: 7502 -> 17502)")
      ->capture_default_str();
  parser->add_option("--skip", options->replay.skip_s, "Start this far into the capture, s")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  return {parser, [options] { return runReplay(*options); }, options};
}

}  // namespace taiga::app
