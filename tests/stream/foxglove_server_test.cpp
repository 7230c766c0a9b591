// The Foxglove WebSocket server (stream/foxglove_server.hpp) with Foxglove's own protocol client
// (tools/foxglove-check): a client that connects late gets what was kept for it first, a history
// in order or the latest state, and nothing that was not kept; the history is bounded.
#include "taiga/stream/foxglove_server.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <future>
#include <nlohmann/json.hpp>

#include "../support/run_taiga.hpp"

namespace taiga::stream {
namespace {

std::vector<FoxgloveChannel> channels() {
  return {{"/history", "test.Kept", "{}"}, {"/state", "test.Kept", "{}"}};
}

/// What foxglove-check receives in `seconds` from the server on `port` (it then times out).
nlohmann::json receive(std::uint16_t port, int seconds) {
  const test::TaigaResult r = test::runCommand(fmt::format(
      "node tools/foxglove-check/foxglove-check.mjs ws://127.0.0.1:{} {} 2>&1", port, seconds));
  EXPECT_EQ(r.exit_code, 0) << r.output << " (run scripts/setup.sh)";
  return nlohmann::json::parse(r.output)["topics"];
}

std::string message(int n) { return nlohmann::json{{"n", n}}.dump(); }

TEST(FoxgloveServer, ALateClientGetsTheHistoryInOrderAndTheLatestStateFirst) {
  FoxgloveServer server("127.0.0.1", 0, channels());
  for (int n = 0; n < 5; ++n) {
    const FoxgloveServer::Kept kept{message(n)};
    server.publish(0, n, message(n), &kept);
  }
  server.publish(0, 5, message(5));  // not kept: a late client never sees it
  for (int n = 0; n < 3; ++n) {
    const FoxgloveServer::Kept latest{message(10 + n), /*replace=*/true};
    server.publish(1, n, "", &latest);  // nobody subscribed: only kept
  }
  auto client = std::async(std::launch::async, [&] { return receive(server.port(), 3); });
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // connected and subscribed
  const FoxgloveServer::Kept kept{message(6)};
  server.publish(0, 6, message(6), &kept);  // sent now, once
  const nlohmann::json topics = client.get();

  std::vector<int> history, state;
  for (const nlohmann::json& m : topics["/history"]["messages"]) history.push_back(m["n"]);
  for (const nlohmann::json& m : topics["/state"]["messages"]) state.push_back(m["n"]);
  EXPECT_EQ(history, (std::vector<int>{0, 1, 2, 3, 4, 6}));
  EXPECT_EQ(state, std::vector<int>{12});
  EXPECT_EQ(server.stats().connections, 1u);
}

TEST(FoxgloveServer, TheHistoryKeepsTheNewestWithinItsBound) {
  // Each message is 8 bytes ({"n":12}); 20 bytes hold the newest two.
  FoxgloveServer server("127.0.0.1", 0, channels(), "taiga", 64u << 20, {}, 20);
  for (int n = 10; n < 15; ++n) {
    const FoxgloveServer::Kept kept{message(n)};
    server.publish(0, n, "", &kept);
  }
  EXPECT_EQ(server.stats().history_dropped, 3u);
  const nlohmann::json topics = receive(server.port(), 3);
  std::vector<int> history;
  for (const nlohmann::json& m : topics["/history"]["messages"]) history.push_back(m["n"]);
  EXPECT_EQ(history, (std::vector<int>{13, 14}));
}

}  // namespace
}  // namespace taiga::stream
