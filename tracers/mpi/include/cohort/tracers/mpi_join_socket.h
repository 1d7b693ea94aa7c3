// The TCP connection a node joins rank 0's running session over (docs/cluster.md, "Joining a running
// session"): rank 0 listens, a node connects and says the join's magic words, and then both hand the
// socket to MPI_Comm_join (MPI-2), which makes an intercommunicator of it. Only the handshake travels on
// it; every message after goes through MPI. Every wait here has a deadline.
#pragma once

#include <chrono>
#include <string>

namespace cohort::tracers::join_socket {

// What a node sends first, so that rank 0 hands MPI only a connection from a node that is about to join
// (never a stray one, which would leave MPI_Comm_join waiting).
constexpr char kMagic[] = "CHMP join\n";
constexpr size_t kMagicBytes = sizeof kMagic - 1;

// A socket listening on every interface, on `port` (0: any free one); throws with the reason.
int listen_on(int port);
// The port a listening socket took.
int port_of(int socket);
// The next connection, or -1 when none came within `wait`.
int accept_within(int listening, std::chrono::milliseconds wait);
// Connects to host:port within `wait`; throws with the reason.
int connect_within(const std::string& host, int port, std::chrono::milliseconds wait);
// Sends all of `bytes`; false on failure.
bool send_all(int socket, const std::string& bytes);
// Whether exactly `expected` arrives within `wait`.
bool receive_exactly(int socket, const std::string& expected, std::chrono::milliseconds wait);
void close_socket(int socket);

}  // namespace cohort::tracers::join_socket
