#include "Interop/IgtlTransformSender.h"

#include <fmt/core.h>
#include <igtlTransformMessage.h>

#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

// The transport is POSIX sockets rather than igtl::ClientSocket: its ConnectToServer blocks for the operating
// system's connect timeout (minutes for an unreachable host) and its Send can raise SIGPIPE on a closed connection.
// libOpenIGTLink builds the message (header, body, CRC).

namespace fct {

namespace {

std::string errnoText(int error) { return std::strerror(error); }

/// Milliseconds as poll() takes them.
int pollTimeout(std::chrono::milliseconds timeout) { return static_cast<int>(timeout.count()); }

/// Waits until `fd` is writable or the timeout passes; returns poll()'s revents (0 on timeout), or -1 with errno.
int waitWritable(int fd, std::chrono::milliseconds timeout) {
  pollfd p{fd, POLLOUT, 0};
  int ready = 0;
  do {
    ready = ::poll(&p, 1, pollTimeout(timeout));
  } while (ready < 0 && errno == EINTR);
  return ready <= 0 ? ready : p.revents;
}

/// The pending error of a socket (SO_ERROR), 0 if none.
int socketError(int fd) {
  int error = 0;
  socklen_t length = sizeof error;
  if (::getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &length) != 0) return errno;
  return error;
}

/// Opens a non-blocking socket to `address` within the timeout; the socket, or -1 with `error` set (ETIMEDOUT on
/// timeout).
int connectWithin(const addrinfo& address, std::chrono::milliseconds timeout, int& error) {
  const int fd = ::socket(address.ai_family, address.ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, address.ai_protocol);
  if (fd < 0) {
    error = errno;
    return -1;
  }
  if (::connect(fd, address.ai_addr, address.ai_addrlen) == 0) return fd;
  if (errno != EINPROGRESS) {
    error = errno;
    ::close(fd);
    return -1;
  }
  const int ready = waitWritable(fd, timeout);
  error = ready == 0 ? ETIMEDOUT : ready < 0 ? errno : socketError(fd);
  if (error == 0) return fd;
  ::close(fd);
  return -1;
}

/// What a failed connect means for the user.
std::string connectFailure(const IgtlEndpoint& endpoint, int error, std::chrono::milliseconds timeout) {
  if (error == ECONNREFUSED) {
    return fmt::format("cannot connect to the OpenIGTLink server at {}: connection refused (nothing listens there; "
                       "in 3D Slicer add a server connector on port {} in the OpenIGTLinkIF module and tick Active)",
                       endpoint.text(), endpoint.port);
  }
  if (error == ETIMEDOUT) {
    return fmt::format("cannot connect to the OpenIGTLink server at {}: no answer within {:.1f} s (check the host "
                       "name, the network and the firewall)",
                       endpoint.text(), timeout.count() / 1000.0);
  }
  return fmt::format("cannot connect to the OpenIGTLink server at {}: {}", endpoint.text(), errnoText(error));
}

}  // namespace

std::string IgtlEndpoint::text() const {
  return host.find(':') != std::string::npos ? fmt::format("[{}]:{}", host, port) : fmt::format("{}:{}", host, port);
}

Result<IgtlEndpoint> IgtlTransformSender::parseEndpoint(const std::string& text) {
  const auto bad = [&text](const std::string& why) {
    return fail(fmt::format("'{}' is not HOST:PORT ({}); e.g. localhost:18944, 3D Slicer's OpenIGTLinkIF port", text,
                            why));
  };
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos) return bad("no ':PORT'");
  std::string host = text.substr(0, colon);
  const std::string portText = text.substr(colon + 1);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  if (host.empty()) return bad("no host");
  if (host.find(':') != std::string::npos && text.front() != '[') return bad("write an IPv6 host in brackets");
  if (portText.empty() || portText.size() > 5 || portText.find_first_not_of("0123456789") != std::string::npos) {
    return bad("the port must be a number");
  }
  const int port = std::stoi(portText);
  if (port < 1 || port > 65535) return bad("the port must be 1..65535");
  return IgtlEndpoint{host, port};
}

Status IgtlTransformSender::checkDeviceName(const std::string& deviceName) {
  if (deviceName.empty()) return fail("the OpenIGTLink device name is empty");
  if (deviceName.size() > kMaxDeviceNameBytes) {
    return fail(fmt::format("the OpenIGTLink device name '{}' has {} characters; the protocol holds at most {}",
                            deviceName, deviceName.size(), kMaxDeviceNameBytes));
  }
  for (const char c : deviceName) {
    if (c < 0x20 || c > 0x7e) {
      return fail(fmt::format("the OpenIGTLink device name '{}' has a character other than printable ASCII",
                              deviceName));
    }
  }
  return Ok{};
}

Eigen::Matrix4d IgtlTransformSender::rasFromLps(const Eigen::Isometry3d& T_world_from_ct) {
  const Eigen::Matrix4d D = Eigen::Vector4d(-1.0, -1.0, 1.0, 1.0).asDiagonal();
  return D * T_world_from_ct.matrix() * D;
}

IgtlTransformSender::IgtlTransformSender(IgtlEndpoint endpoint, std::string deviceName,
                                         std::chrono::milliseconds timeout)
    : m_endpoint(std::move(endpoint)), m_deviceName(std::move(deviceName)), m_timeout(timeout) {}

IgtlTransformSender::~IgtlTransformSender() { close(); }

void IgtlTransformSender::close() {
  if (m_socket >= 0) ::close(m_socket);
  m_socket = -1;
}

Status IgtlTransformSender::connect() {
  if (connected()) return Ok{};
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* addresses = nullptr;
  const std::string port = std::to_string(m_endpoint.port);
  if (const int status = ::getaddrinfo(m_endpoint.host.c_str(), port.c_str(), &hints, &addresses); status != 0) {
    return fail(fmt::format("cannot find the OpenIGTLink server host '{}': {}", m_endpoint.host,
                            ::gai_strerror(status)));
  }
  int error = ECONNREFUSED;
  for (const addrinfo* a = addresses; a && m_socket < 0; a = a->ai_next) m_socket = connectWithin(*a, m_timeout, error);
  ::freeaddrinfo(addresses);
  if (m_socket < 0) return fail(connectFailure(m_endpoint, error, m_timeout));
  return Ok{};
}

Status IgtlTransformSender::checkOpen() {
  char discarded[4096];
  for (;;) {
    const ssize_t n = ::recv(m_socket, discarded, sizeof discarded, MSG_DONTWAIT);
    if (n > 0) continue;  // the server may send its own messages; this sender reads none of them
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return Ok{};
    if (n < 0 && errno == EINTR) continue;
    const std::string why = n == 0 ? "closed the connection" : "reset the connection (" + errnoText(errno) + ")";
    return fail(fmt::format("the OpenIGTLink server at {} {}", m_endpoint.text(), why));
  }
}

Status IgtlTransformSender::writeAll(const void* data, std::size_t size) {
  const auto* bytes = static_cast<const char*>(data);
  const auto deadline = std::chrono::steady_clock::now() + m_timeout;
  while (size > 0) {
    const ssize_t n = ::send(m_socket, bytes, size, MSG_NOSIGNAL);
    if (n > 0) {
      bytes += n;
      size -= static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() > 0 && waitWritable(m_socket, left) > 0) continue;
      return fail(fmt::format("the OpenIGTLink server at {} took no data for {:.1f} s (is it stalled?)",
                              m_endpoint.text(), m_timeout.count() / 1000.0));
    }
    const int error = errno;
    if (error == EPIPE || error == ECONNRESET) {
      return fail(fmt::format("the OpenIGTLink server at {} closed the connection", m_endpoint.text()));
    }
    return fail(fmt::format("cannot send to the OpenIGTLink server at {}: {}", m_endpoint.text(), errnoText(error)));
  }
  return Ok{};
}

Status IgtlTransformSender::send(const Eigen::Isometry3d& T_world_from_ct) {
  if (Status name = checkDeviceName(m_deviceName); !name) return name;
  if (!T_world_from_ct.matrix().allFinite()) return fail("the pose to send has a non-finite entry");
  if (Status connection = connect(); !connection) return connection;
  if (Status open = checkOpen(); !open) {
    close();
    return open;
  }
  const Eigen::Matrix4d T_ras = rasFromLps(T_world_from_ct);
  igtl::Matrix4x4 matrix;
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) matrix[row][col] = static_cast<float>(T_ras(row, col));
  }
  const igtl::TransformMessage::Pointer message = igtl::TransformMessage::New();
  message->SetDeviceName(m_deviceName.c_str());
  message->SetMatrix(matrix);
  message->Pack();
  if (Status written = writeAll(message->GetPackPointer(), static_cast<std::size_t>(message->GetPackSize())); !written) {
    close();
    return written;
  }
  return Ok{};
}

}  // namespace fct
