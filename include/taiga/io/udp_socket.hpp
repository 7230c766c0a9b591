#pragma once
// A UDP socket (IPv4) for sensor traffic: bound to receive a sensor's packets, or unbound to send
// them (taiga replay) or to publish poses. Errors throw InputError naming the address and port.

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace taiga::io {

class UdpSocket {
 public:
  /// A socket bound to `address`:`port` (port 0: any free port, see port()) with a receive
  /// buffer of at least `receive_buffer_bytes` where the system allows it.
  static UdpSocket bound(const std::string& address, std::uint16_t port,
                         int receive_buffer_bytes = 0);
  /// A socket for sending to `host`:`port` (a name or a dotted address).
  static UdpSocket connected(const std::string& host, std::uint16_t port);

  UdpSocket(UdpSocket&& other) noexcept;
  UdpSocket& operator=(UdpSocket&& other) noexcept;
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  ~UdpSocket();

  int fd() const { return fd_; }
  std::uint16_t port() const { return port_; }
  /// The receive buffer the system granted, bytes.
  int receiveBufferBytes() const;

  /// Sends one datagram; false when the system refused it (e.g. nobody listens on loopback).
  bool send(std::span<const std::uint8_t> payload);
  /// Receives one datagram into `buffer` (resized to it) without waiting; false when none waits.
  bool receive(std::vector<std::uint8_t>& buffer);
  /// Datagrams the kernel dropped because the receive buffer was full (SO_RXQ_OVFL), as of the
  /// last receive().
  std::uint32_t kernelDrops() const { return kernel_drops_; }

 private:
  explicit UdpSocket(int fd, std::string label);
  int fd_ = -1;
  std::uint16_t port_ = 0;
  std::string label_;
  std::uint32_t kernel_drops_ = 0;
};

/// Waits until one of `sockets` has a datagram or `timeout` passes; returns the ready ones'
/// indices (empty on timeout or on a signal).
std::vector<std::size_t> waitReadable(std::span<const UdpSocket* const> sockets,
                                      std::chrono::milliseconds timeout);

}  // namespace taiga::io
