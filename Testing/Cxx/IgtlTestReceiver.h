#pragma once
// IgtlTestReceiver: a loopback OpenIGTLink server for the tests (an igtl::ServerSocket on an ephemeral port, served by
// a thread), standing in for 3D Slicer's OpenIGTLinkIF. It accepts one client and either records the TRANSFORM
// messages it receives or closes the connection at once. Every wait is bounded (kWait_ms), so a test that sends
// nothing ends instead of hanging.

#include <Eigen/Core>

#include <future>
#include <string>
#include <vector>

namespace fct::test {

/// One TRANSFORM message as received.
struct ReceivedTransform {
  std::string deviceName;
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();  ///< as sent (Slicer's RAS frame for FluoroCT's sender)
};

/// A loopback OpenIGTLink server serving one client in a thread.
class IgtlTestReceiver {
 public:
  /// What the server does with its client.
  enum class Behaviour {
    Record,        ///< reads messages until `messages` TRANSFORMs arrived or the client closed
    CloseOnAccept  ///< closes the connection as soon as the client connected
  };
  /// The longest the server waits for a client or a message, ms.
  static constexpr int kWait_ms = 60000;

  /// Listens on an ephemeral port and starts serving; port() is 0 if the server could not be created.
  explicit IgtlTestReceiver(Behaviour behaviour, int messages = 1);
  /// Waits for the serving thread.
  ~IgtlTestReceiver();

  /// The port the server listens on (on every interface; clients use 127.0.0.1).
  int port() const { return m_port; }
  /// "127.0.0.1:<port>".
  std::string endpoint() const;
  /// Waits until the server is done (its client closed, the messages arrived, or it closed the connection) and
  /// returns the TRANSFORMs received; may be called once.
  std::vector<ReceivedTransform> received();
  /// A loopback port nothing listens on (bound, then closed again), for the refused-connection tests.
  static int unusedPort();
  /// Prints each received transform (device name and matrix) on stdout, as the report of a loopback run.
  static void print(const std::vector<ReceivedTransform>& transforms);

 private:
  int m_port = 0;
  std::future<std::vector<ReceivedTransform>> m_done;
};

}  // namespace fct::test
