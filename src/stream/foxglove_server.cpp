// Compiled as C++17: websocketpp 0.8's headers do not compile as C++20 (CMakeLists.txt).
#include "taiga/stream/foxglove_server.hpp"

#define ASIO_STANDALONE
#include <fmt/format.h>

#include <atomic>
#include <deque>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"

namespace taiga::stream {
namespace {

using Server = websocketpp::server<websocketpp::config::asio>;
using Handle = websocketpp::connection_hdl;
constexpr const char* kSubprotocol = "foxglove.websocket.v1";
constexpr std::uint8_t kMessageDataOpcode = 1;

void putLe(std::string& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}

}  // namespace

struct FoxgloveServer::Impl {
  std::vector<FoxgloveChannel> channels;
  std::string name;
  std::size_t max_buffered_bytes = 0;
  HttpHandler http;
  Server server;
  std::thread thread;
  mutable std::mutex mutex;
  /// Per client: subscription id by channel index.
  std::map<Handle, std::map<std::size_t, std::uint32_t>, std::owner_less<Handle>> clients;
  std::vector<int> subscribers;  ///< per channel
  struct KeptMessage {
    std::uint64_t t_ns;
    std::string json;
  };
  /// Per channel, what a late subscriber gets first (publish()'s `keep`).
  std::vector<std::deque<KeptMessage>> history;
  std::vector<std::size_t> history_bytes;
  std::size_t max_history_bytes = 0;
  FoxgloveServerStats stats;

  void onOpen(Handle client);
  void onClose(Handle client);
  void onMessage(Handle client, Server::message_ptr message);
  void onHttp(Handle client);
  bool validate(Handle client);
  void sendText(Handle client, const std::string& text);
  /// A Message Data frame to one client, unless it is too far behind (counted) and this is not
  /// the history it subscribed to (`kept`: bounded by max_history_bytes). Under `mutex`.
  void sendMessage(Handle client, std::uint32_t subscription, std::uint64_t t_ns,
                   const std::string& json, bool kept = false);
};

void FoxgloveServer::Impl::sendMessage(Handle client, std::uint32_t subscription,
                                       std::uint64_t t_ns, const std::string& json, bool kept) {
  websocketpp::lib::error_code error;
  Server::connection_ptr connection = server.get_con_from_hdl(client, error);
  if (error) return;
  if (!kept && connection->get_buffered_amount() > max_buffered_bytes) {
    ++stats.messages_dropped;
    return;
  }
  std::string frame;
  frame.reserve(13 + json.size());
  frame.push_back(static_cast<char>(kMessageDataOpcode));
  putLe(frame, subscription, 4);
  putLe(frame, t_ns, 8);
  frame += json;
  connection->send(frame, websocketpp::frame::opcode::binary);
  ++stats.messages_sent;
}

bool FoxgloveServer::Impl::validate(Handle client) {
  Server::connection_ptr connection = server.get_con_from_hdl(client);
  for (const std::string& protocol : connection->get_requested_subprotocols()) {
    if (protocol == kSubprotocol) {
      connection->select_subprotocol(kSubprotocol);
      return true;
    }
  }
  return false;  // not a client of this protocol: the handshake fails
}

void FoxgloveServer::Impl::sendText(Handle client, const std::string& text) {
  websocketpp::lib::error_code error;
  server.send(client, text, websocketpp::frame::opcode::text, error);
}

void FoxgloveServer::Impl::onOpen(Handle client) {
  {
    std::lock_guard lock(mutex);
    clients[client];
    ++stats.connections;
  }
  sendText(client, nlohmann::json{{"op", "serverInfo"},
                                  {"name", name},
                                  {"capabilities", nlohmann::json::array()},
                                  {"supportedEncodings", nlohmann::json::array()}}
                       .dump());
  nlohmann::json advertised = nlohmann::json::array();
  for (std::size_t i = 0; i < channels.size(); ++i)
    advertised.push_back({{"id", i + 1},
                          {"topic", channels[i].topic},
                          {"encoding", "json"},
                          {"schemaName", channels[i].schema_name},
                          {"schema", channels[i].schema},
                          {"schemaEncoding", "jsonschema"}});
  sendText(client, nlohmann::json{{"op", "advertise"}, {"channels", advertised}}.dump());
}

void FoxgloveServer::Impl::onClose(Handle client) {
  std::lock_guard lock(mutex);
  const auto it = clients.find(client);
  if (it == clients.end()) return;
  for (const auto& subscription : it->second) --subscribers[subscription.first];
  clients.erase(it);
}

void FoxgloveServer::Impl::onMessage(Handle client, Server::message_ptr message) {
  if (message->get_opcode() != websocketpp::frame::opcode::text)
    return;  // nothing binary is accepted
  const nlohmann::json request = nlohmann::json::parse(message->get_payload(), nullptr, false);
  if (!request.is_object() || !request.contains("op")) return;
  std::lock_guard lock(mutex);
  auto& subscriptions = clients[client];
  try {
    if (request["op"] == "subscribe") {
      for (const nlohmann::json& s : request.at("subscriptions")) {
        const auto channel = s.at("channelId").get<std::size_t>();
        if (channel == 0 || channel > channels.size()) continue;
        const auto id = s.at("id").get<std::uint32_t>();
        if (!subscriptions.emplace(channel - 1, id).second) continue;
        ++subscribers[channel - 1];
        for (const KeptMessage& kept : history[channel - 1])
          sendMessage(client, id, kept.t_ns, kept.json, true);
      }
    } else if (request["op"] == "unsubscribe") {
      for (const nlohmann::json& id : request.at("subscriptionIds")) {
        for (auto it = subscriptions.begin(); it != subscriptions.end(); ++it) {
          if (it->second != id.get<std::uint32_t>()) continue;
          --subscribers[it->first];
          subscriptions.erase(it);
          break;
        }
      }
    }
  } catch (const nlohmann::json::exception&) {  // a malformed request is ignored
  }
}

void FoxgloveServer::Impl::onHttp(Handle client) {
  Server::connection_ptr connection = server.get_con_from_hdl(client);
  HttpResponse response{404, "text/plain", "not found\n"};
  if (connection->get_request().get_method() != "GET") {
    response = {405, "text/plain", "only GET\n"};
  } else if (http) {
    try {
      response = http(connection->get_resource());
    } catch (const std::exception& e) {
      response = {500, "text/plain", std::string(e.what()) + "\n"};
    }
  }
  connection->set_status(static_cast<websocketpp::http::status_code::value>(response.status));
  connection->replace_header("Content-Type", response.content_type);
  connection->replace_header("Cache-Control", "no-cache");
  connection->set_body(std::move(response.body));
}

FoxgloveServer::FoxgloveServer(const std::string& address, std::uint16_t port,
                               std::vector<FoxgloveChannel> channels, std::string name,
                               std::size_t max_buffered_bytes, HttpHandler http,
                               std::size_t max_history_bytes)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.http = std::move(http);
  s.max_history_bytes = max_history_bytes;
  s.channels = std::move(channels);
  s.name = std::move(name);
  s.max_buffered_bytes = max_buffered_bytes;
  s.subscribers.assign(s.channels.size(), 0);
  s.history.resize(s.channels.size());
  s.history_bytes.assign(s.channels.size(), 0);
  s.server.clear_access_channels(websocketpp::log::alevel::all);
  s.server.clear_error_channels(websocketpp::log::elevel::all);
  s.server.init_asio();
  s.server.set_reuse_addr(true);
  s.server.set_validate_handler([&s](Handle h) { return s.validate(h); });
  s.server.set_open_handler([&s](Handle h) { s.onOpen(h); });
  s.server.set_close_handler([&s](Handle h) { s.onClose(h); });
  s.server.set_fail_handler([&s](Handle h) { s.onClose(h); });
  s.server.set_message_handler([&s](Handle h, Server::message_ptr m) { s.onMessage(h, m); });
  s.server.set_http_handler([&s](Handle h) { s.onHttp(h); });
  websocketpp::lib::error_code error;
  s.server.listen(asio::ip::tcp::endpoint(asio::ip::make_address(address, error), port), error);
  if (!error) s.server.start_accept(error);
  if (error)
    throw InputError(fmt::format("{}:{}: cannot listen there (WebSocket and HTTP): {}", address,
                                 port, error.message()));
  s.thread = std::thread([&s] { s.server.run(); });
  if (!s.channels.empty())
    logger().info("Foxglove WebSocket on ws://{}:{} ({} channels)", address, this->port(),
                  s.channels.size());
}

FoxgloveServer::~FoxgloveServer() {
  Impl& s = *impl_;
  asio::post(s.server.get_io_service(), [&s] {
    websocketpp::lib::error_code error;
    s.server.stop_listening(error);
    std::lock_guard lock(s.mutex);
    for (const auto& client : s.clients)
      s.server.close(client.first, websocketpp::close::status::going_away, "run ended", error);
  });
  // Closing handshakes get a moment; then the loop is stopped whatever the clients do.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  s.server.stop();
  s.thread.join();
}

std::uint16_t FoxgloveServer::port() const {
  websocketpp::lib::asio::error_code error;
  const auto endpoint = impl_->server.get_local_endpoint(error);
  return error ? 0 : endpoint.port();
}

bool FoxgloveServer::subscribed(std::size_t channel) const {
  std::lock_guard lock(impl_->mutex);
  return channel < impl_->subscribers.size() && impl_->subscribers[channel] > 0;
}

void FoxgloveServer::publish(std::size_t channel, std::uint64_t t_ns, const std::string& json,
                             const Kept* keep) {
  Impl& s = *impl_;
  std::lock_guard lock(s.mutex);
  const std::string& sent = json.empty() && keep ? keep->json : json;
  if (!sent.empty()) {
    for (const auto& [client, subscriptions] : s.clients) {
      const auto it = subscriptions.find(channel);
      if (it != subscriptions.end()) s.sendMessage(client, it->second, t_ns, sent);
    }
  }
  if (!keep) return;
  std::deque<Impl::KeptMessage>& kept = s.history.at(channel);
  std::size_t& bytes = s.history_bytes[channel];
  if (keep->replace) {
    kept.clear();
    bytes = 0;
  }
  kept.push_back({t_ns, keep->json});
  bytes += keep->json.size();
  while (bytes > s.max_history_bytes && kept.size() > 1) {
    bytes -= kept.front().json.size();
    kept.pop_front();
    ++s.stats.history_dropped;
  }
}

FoxgloveServerStats FoxgloveServer::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

}  // namespace taiga::stream
