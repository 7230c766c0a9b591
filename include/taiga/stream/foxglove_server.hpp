#pragma once
// A WebSocket server speaking the Foxglove WebSocket protocol v1 (subprotocol
// foxglove.websocket.v1; github.com/foxglove/ws-protocol, docs/spec.md), so that Foxglove and any
// client of the protocol can watch a run: channels of JSON messages, advertised when a client
// connects, sent to the clients that subscribed. Built on websocketpp and standalone asio
// (Debian packages), on a thread of its own; publish() may be called from any thread.
//
// Only what a data source needs is implemented: serverInfo, advertise, subscribe, unsubscribe
// and Message Data (binary opcode 1: u32 subscription id, u64 timestamp ns, payload). A client
// that falls behind by more than max_buffered_bytes gets nothing new until it catches up (the
// messages in between are dropped for it, and counted).
//
// The same port can answer plain HTTP GET requests (the viewer's page and data, view/): a request
// that is not a WebSocket upgrade goes to the HttpHandler given, if any (404 otherwise).
//
// This header is C++17 (its implementation must be compiled as C++17 for websocketpp 0.8).

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace taiga::stream {

struct FoxgloveChannel {
  std::string topic;        ///< e.g. "/taiga/pose"
  std::string schema_name;  ///< e.g. "foxglove.PoseInFrame"
  std::string schema;       ///< its JSON Schema, as text
};

struct HttpResponse {
  int status = 200;
  std::string content_type = "text/plain";
  std::string body;
};
/// Answers a GET for `resource` (path and query, e.g. "/api/node/3"). Called on the server's
/// thread; may throw, which answers 500.
using HttpHandler = std::function<HttpResponse(const std::string& resource)>;

struct FoxgloveServerStats {
  std::uint64_t connections = 0;       ///< clients that connected over the server's life
  std::uint64_t messages_sent = 0;     ///< Message Data frames sent
  std::uint64_t messages_dropped = 0;  ///< not sent to a client that was too far behind
  std::uint64_t history_dropped = 0;   ///< kept messages dropped for max_history_bytes
};

class FoxgloveServer {
 public:
  /// Listens on `address`:`port` (port 0: any free one, see port()). InputError naming the
  /// address when it cannot.
  FoxgloveServer(const std::string& address, std::uint16_t port,
                 std::vector<FoxgloveChannel> channels, std::string name = "taiga",
                 std::size_t max_buffered_bytes = 64u << 20, HttpHandler http = {},
                 std::size_t max_history_bytes = 256u << 20);
  ~FoxgloveServer();
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  std::uint16_t port() const;
  /// What a client that subscribes later gets of a message, before anything new: `json` (e.g. a
  /// thinner copy), added to the channel's kept messages (a history, such as the map's
  /// keyframes; the oldest dropped beyond max_history_bytes per channel, counted) or, with
  /// `replace`, in their place (a state, such as the latest keyframe poses).
  struct Kept {
    std::string json;
    bool replace = false;
  };
  /// Sends `json` on channel `channel` (index into the channels given) to its subscribers, and
  /// keeps `keep` for later ones, atomically: no subscriber misses the message or gets it twice.
  /// An empty `json` (nobody was subscribed when it would have been built) sends `keep->json`.
  void publish(std::size_t channel, std::uint64_t t_ns, const std::string& json,
               const Kept* keep = nullptr);
  /// Whether any client subscribed to `channel` (to skip building messages nobody wants).
  bool subscribed(std::size_t channel) const;
  FoxgloveServerStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace taiga::stream
