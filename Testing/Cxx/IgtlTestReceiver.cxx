#include "IgtlTestReceiver.h"

#include <igtlMessageHeader.h>
#include <igtlServerSocket.h>
#include <igtlTransformMessage.h>

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <iostream>

namespace fct::test {

namespace {

/// Reads TRANSFORM messages from `client` until `messages` arrived, the client closed or a wait timed out; other
/// message types are skipped.
std::vector<ReceivedTransform> readTransforms(igtl::ClientSocket* client, int messages) {
  std::vector<ReceivedTransform> received;
  client->SetReceiveTimeout(IgtlTestReceiver::kWait_ms);
  while (static_cast<int>(received.size()) < messages) {
    const igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
    header->InitPack();
    if (client->Receive(header->GetPackPointer(), header->GetPackSize()) != header->GetPackSize()) break;
    header->Unpack();
    if (std::strcmp(header->GetDeviceType(), "TRANSFORM") != 0) {
      client->Skip(header->GetBodySizeToRead(), 0);
      continue;
    }
    const igtl::TransformMessage::Pointer transform = igtl::TransformMessage::New();
    transform->SetMessageHeader(header);
    transform->AllocatePack();
    if (client->Receive(transform->GetPackBodyPointer(), transform->GetPackBodySize()) != transform->GetPackBodySize()) {
      break;
    }
    if (!(transform->Unpack(1) & igtl::MessageHeader::UNPACK_BODY)) break;  // CRC mismatch
    igtl::Matrix4x4 matrix;
    transform->GetMatrix(matrix);
    ReceivedTransform r;
    r.deviceName = transform->GetDeviceName();
    for (int row = 0; row < 4; ++row) {
      for (int col = 0; col < 4; ++col) r.matrix(row, col) = matrix[row][col];
    }
    received.push_back(std::move(r));
  }
  return received;
}

}  // namespace

IgtlTestReceiver::IgtlTestReceiver(Behaviour behaviour, int messages) {
  igtl::ServerSocket::Pointer server = igtl::ServerSocket::New();
  if (server->CreateServer(0) != 0) return;
  m_port = server->GetServerPort();
  m_done = std::async(std::launch::async, [server, behaviour, messages]() -> std::vector<ReceivedTransform> {
    const igtl::ClientSocket::Pointer client = server->WaitForConnection(kWait_ms);
    if (!client) return {};
    std::vector<ReceivedTransform> received;
    if (behaviour == Behaviour::Record) received = readTransforms(client, messages);
    client->CloseSocket();
    server->CloseSocket();
    return received;
  });
}

IgtlTestReceiver::~IgtlTestReceiver() {
  if (m_done.valid()) m_done.wait();
}

std::string IgtlTestReceiver::endpoint() const { return "127.0.0.1:" + std::to_string(m_port); }

std::vector<ReceivedTransform> IgtlTestReceiver::received() {
  return m_done.valid() ? m_done.get() : std::vector<ReceivedTransform>{};
}

int IgtlTestReceiver::unusedPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  const bool bound = ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0 &&
                     ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0;
  ::close(fd);
  return bound ? ntohs(address.sin_port) : 0;
}

void IgtlTestReceiver::print(const std::vector<ReceivedTransform>& transforms) {
  const Eigen::IOFormat format(6, 0, " ", "\n", "    [", "]");
  for (const ReceivedTransform& t : transforms) {
    std::cout << "received TRANSFORM, device '" << t.deviceName << "':\n" << t.matrix.format(format) << "\n";
  }
}

}  // namespace fct::test
