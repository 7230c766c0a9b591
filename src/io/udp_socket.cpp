#include "taiga/io/udp_socket.hpp"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

constexpr std::size_t kMaxDatagramBytes = 65535;

sockaddr_in resolve(const std::string& host, std::uint16_t port) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  const int error = getaddrinfo(host.c_str(), nullptr, &hints, &found);
  if (error != 0 || found == nullptr)
    throw InputError(
        fmt::format("{}:{}: cannot resolve the address: {}", host, port, gai_strerror(error)));
  sockaddr_in address{};
  std::memcpy(&address, found->ai_addr, sizeof(address));
  freeaddrinfo(found);
  address.sin_port = htons(port);
  return address;
}

int openSocket(const std::string& label) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0)
    throw InputError(fmt::format("{}: cannot open a UDP socket: {}", label, std::strerror(errno)));
  return fd;
}

}  // namespace

UdpSocket::UdpSocket(int fd, std::string label) : fd_(fd), label_(std::move(label)) {}

UdpSocket UdpSocket::bound(const std::string& address, std::uint16_t port,
                           int receive_buffer_bytes) {
  const std::string label = fmt::format("{}:{}", address, port);
  UdpSocket s(openSocket(label), label);
  const int one = 1;
  setsockopt(s.fd_, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof(one));
  if (receive_buffer_bytes > 0) {
    // SO_RCVBUFFORCE passes net.core.rmem_max for root; otherwise the system caps the request.
    if (setsockopt(s.fd_, SOL_SOCKET, SO_RCVBUFFORCE, &receive_buffer_bytes, sizeof(int)) != 0)
      setsockopt(s.fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer_bytes, sizeof(int));
  }
  const sockaddr_in at = resolve(address, port);
  if (::bind(s.fd_, reinterpret_cast<const sockaddr*>(&at), sizeof(at)) != 0)
    throw InputError(fmt::format("{}: cannot receive UDP there: {}{}", label, std::strerror(errno),
                                 errno == EADDRINUSE ? " (another program, or another taiga run, "
                                                       "listens on that port)"
                                                     : ""));
  sockaddr_in actual{};
  socklen_t length = sizeof(actual);
  getsockname(s.fd_, reinterpret_cast<sockaddr*>(&actual), &length);
  s.port_ = ntohs(actual.sin_port);
  return s;
}

UdpSocket UdpSocket::connected(const std::string& host, std::uint16_t port) {
  const std::string label = fmt::format("{}:{}", host, port);
  UdpSocket s(openSocket(label), label);
  const int buffer = 8 << 20;
  setsockopt(s.fd_, SOL_SOCKET, SO_SNDBUF, &buffer, sizeof(buffer));
  const sockaddr_in to = resolve(host, port);
  if (::connect(s.fd_, reinterpret_cast<const sockaddr*>(&to), sizeof(to)) != 0)
    throw InputError(fmt::format("{}: cannot send UDP there: {}", label, std::strerror(errno)));
  s.port_ = port;
  return s;
}

UdpSocket::UdpSocket(UdpSocket&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      port_(other.port_),
      label_(std::move(other.label_)),
      kernel_drops_(other.kernel_drops_) {}

UdpSocket& UdpSocket::operator=(UdpSocket&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    port_ = other.port_;
    label_ = std::move(other.label_);
    kernel_drops_ = other.kernel_drops_;
  }
  return *this;
}

UdpSocket::~UdpSocket() {
  if (fd_ >= 0) ::close(fd_);
}

int UdpSocket::receiveBufferBytes() const {
  int bytes = 0;
  socklen_t length = sizeof(bytes);
  getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &bytes, &length);
  return bytes;
}

bool UdpSocket::send(std::span<const std::uint8_t> payload) {
  return ::send(fd_, payload.data(), payload.size(), 0) == static_cast<ssize_t>(payload.size());
}

bool UdpSocket::receive(std::vector<std::uint8_t>& buffer) {
  buffer.resize(kMaxDatagramBytes);
  iovec io{buffer.data(), buffer.size()};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(std::uint32_t))];
  msghdr message{};
  message.msg_iov = &io;
  message.msg_iovlen = 1;
  message.msg_control = control;
  message.msg_controllen = sizeof(control);
  const ssize_t n = ::recvmsg(fd_, &message, MSG_DONTWAIT);
  if (n < 0) {
    buffer.clear();
    return false;
  }
  buffer.resize(static_cast<std::size_t>(n));
  for (cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c))
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL)
      std::memcpy(&kernel_drops_, CMSG_DATA(c), sizeof(kernel_drops_));
  return true;
}

std::vector<std::size_t> waitReadable(std::span<const UdpSocket* const> sockets,
                                      std::chrono::milliseconds timeout) {
  std::vector<pollfd> fds;
  for (const UdpSocket* s : sockets) fds.push_back({s->fd(), POLLIN, 0});
  std::vector<std::size_t> ready;
  if (::poll(fds.data(), fds.size(), static_cast<int>(timeout.count())) <= 0) return ready;
  for (std::size_t i = 0; i < fds.size(); ++i)
    if (fds[i].revents & POLLIN) ready.push_back(i);
  return ready;
}

}  // namespace taiga::io
