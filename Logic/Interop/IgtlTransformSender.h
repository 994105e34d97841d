#pragma once
// IgtlTransformSender: sends the bone pose as an OpenIGTLink TRANSFORM message to a server such as 3D Slicer's
// OpenIGTLinkIF connector (default port 18944), over one TCP connection kept open between sends.
// Slicer works in RAS, FluoroCT in LPS: the matrix sent is T_ras = D · T_world_from_ct · D with D = diag(−1, −1, 1, 1),
// which Slicer stores as the transform node's "to parent" matrix (apply it to the CT volume to place the CT in the
// C-arm world). Connecting and sending each give up after a timeout (kDefaultTimeout_ms); a refused connection, an
// unknown host, a timeout and a server that closed the connection each fail with a message naming the server.

#include <Eigen/Geometry>

#include <chrono>
#include <string>

#include "Base/Result.h"

namespace fct {

/// Where an OpenIGTLink server listens.
struct IgtlEndpoint {
  std::string host;
  int port = 18944;

  /// "host:port", as messages name the server.
  std::string text() const;
};

/// Sends TRANSFORM messages to one OpenIGTLink server.
class IgtlTransformSender {
 public:
  /// How long connecting and sending one message may take before they fail.
  static constexpr std::chrono::milliseconds kDefaultTimeout_ms{3000};
  /// The longest device name an OpenIGTLink header holds, bytes.
  static constexpr std::size_t kMaxDeviceNameBytes = 20;

  /// Parses "HOST:PORT" (port 1..65535; a bracketed IPv6 host "[::1]:18944"); fails naming the text otherwise.
  static Result<IgtlEndpoint> parseEndpoint(const std::string& text);
  /// Checks a device name: 1..20 printable ASCII characters; fails saying what is wrong otherwise.
  static Status checkDeviceName(const std::string& deviceName);
  /// The pose in Slicer's RAS frame: D · T_world_from_ct · D, D = diag(−1, −1, 1, 1) (mm).
  static Eigen::Matrix4d rasFromLps(const Eigen::Isometry3d& T_world_from_ct);

  /// A sender to `endpoint` whose messages carry `deviceName` (checked on send); nothing is connected yet.
  IgtlTransformSender(IgtlEndpoint endpoint, std::string deviceName,
                      std::chrono::milliseconds timeout = kDefaultTimeout_ms);
  /// Closes the connection.
  ~IgtlTransformSender();
  IgtlTransformSender(const IgtlTransformSender&) = delete;
  IgtlTransformSender& operator=(const IgtlTransformSender&) = delete;

  /// Connects unless connected. Fails on an unknown host, a refused connection or no answer within the timeout.
  Status connect();
  /// Sends T_world_from_ct (LPS mm) as a TRANSFORM in RAS (rasFromLps), connecting first if needed. Fails on a bad
  /// device name or pose, a connection failure, a server that closed the connection, or a send that did not finish
  /// within the timeout; the connection is then closed and the next send connects again.
  Status send(const Eigen::Isometry3d& T_world_from_ct);
  /// True while a connection is open (it may have been closed by the server since the last send).
  bool connected() const { return m_socket >= 0; }
  /// Closes the connection, if any.
  void close();

  const IgtlEndpoint& endpoint() const { return m_endpoint; }

 private:
  /// Fails when the server closed the connection (or reset it); discards anything the server sent meanwhile.
  Status checkOpen();
  /// Writes all `size` bytes within the timeout.
  Status writeAll(const void* data, std::size_t size);

  IgtlEndpoint m_endpoint;
  std::string m_deviceName;
  std::chrono::milliseconds m_timeout;
  int m_socket = -1;
};

}  // namespace fct
