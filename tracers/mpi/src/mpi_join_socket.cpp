#include "cohort/tracers/mpi_join_socket.h"

#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace cohort::tracers::join_socket {

namespace {
using Clock = std::chrono::steady_clock;

int ms_left(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left > 0 ? int(left) : 0;
}

bool wait_for(int socket, short events, Clock::time_point deadline) {
  for (;;) {
    pollfd p{socket, events, 0};
    const int n = poll(&p, 1, ms_left(deadline));
    if (n > 0) return true;
    if (n == 0 || errno != EINTR) return false;
  }
}
}  // namespace

int listen_on(int port) {
  const int s = socket(AF_INET, SOCK_STREAM, 0);
  if (s < 0) throw std::runtime_error(std::string("socket: ") + std::strerror(errno));
  const int one = 1;
  setsockopt(s, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_ANY);
  address.sin_port = htons(uint16_t(port));
  if (bind(s, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 || listen(s, 8) != 0) {
    const std::string why = std::strerror(errno);
    ::close(s);
    throw std::runtime_error("cannot listen on TCP port " + std::to_string(port) + ": " + why);
  }
  return s;
}

int port_of(int socket) {
  sockaddr_in address{};
  socklen_t size = sizeof address;
  if (getsockname(socket, reinterpret_cast<sockaddr*>(&address), &size) != 0) return -1;
  return ntohs(address.sin_port);
}

int accept_within(int listening, std::chrono::milliseconds wait) {
  if (!wait_for(listening, POLLIN, Clock::now() + wait)) return -1;
  return ::accept(listening, nullptr, nullptr);
}

int connect_within(const std::string& host, int port, std::chrono::milliseconds wait) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int code = getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found); code != 0)
    throw std::runtime_error("cannot resolve " + host + ": " + gai_strerror(code));
  const auto deadline = Clock::now() + wait;
  std::string why = "no address";
  // Rank 0 may be starting still: tried until the deadline.
  while (true) {
    for (addrinfo* a = found; a; a = a->ai_next) {
      const int s = socket(a->ai_family, a->ai_socktype, a->ai_protocol);
      if (s < 0) continue;
      if (::connect(s, a->ai_addr, a->ai_addrlen) == 0) {
        freeaddrinfo(found);
        return s;
      }
      why = std::strerror(errno);
      ::close(s);
    }
    if (Clock::now() >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  freeaddrinfo(found);
  throw std::runtime_error("cannot connect to " + host + ":" + std::to_string(port) + ": " + why);
}

bool send_all(int socket, const std::string& bytes) {
  size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(socket, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    sent += size_t(n);
  }
  return true;
}

bool receive_exactly(int socket, const std::string& expected, std::chrono::milliseconds wait) {
  const auto deadline = Clock::now() + wait;
  std::string got;
  while (got.size() < expected.size()) {
    if (!wait_for(socket, POLLIN, deadline)) return false;
    char buffer[64];
    const ssize_t n = ::recv(socket, buffer, std::min(sizeof buffer, expected.size() - got.size()), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    got.append(buffer, size_t(n));
  }
  return got == expected;
}

void close_socket(int socket) {
  if (socket >= 0) ::close(socket);
}

}  // namespace cohort::tracers::join_socket
