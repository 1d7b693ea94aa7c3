// Rank 0's port for nodes that join a running session (docs/cluster.md, "Joining a running session"):
// nodes started on their own (their own mpiexec, any host) join it and serve a remote tracer's slot,
// mpi:N. A slot whose node died, left or never came is served by the next node that joins it; until then
// its rows go to the other tracers.
//
// The port is a TCP socket: a node connects, says the join's magic words, and both hand the connection
// to MPI_Comm_join (MPI-2), which makes it an intercommunicator. Not MPI_Open_port and MPI_Comm_accept:
// an accept blocks until a node comes, and MPICH 5.0 holds its global lock all the while, so every other
// MPI call of rank 0 (its tracers' bands) would wait for the next node; nor can an accept be cancelled at
// exit. Here rank 0 calls into MPI only for a node that is joining right then. That and each newcomer's
// greeting (join, hello: bounded waits) run on a thread of their own (MPI_THREAD_MULTIPLE), outside the
// session's lock, so frames do not wait for a node that joins. A node that asks for a busy slot, runs
// another version, or says nothing in time is refused with the reason, logged on both sides; the remote
// tracer of its slot then picks up the one that was welcomed.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cohort/tracers/mpi_link.h"
#include "cohort/tracers/mpi_wire.h"

namespace cohort::tracers {

// A node that joined and was welcomed, waiting for its slot's remote tracer to take it.
struct JoiningNode {
  int peer = -1;
  wire::Hello hello;
  MpiClock::time_point connected{};  // when its connection was accepted
};

class NodePort {
 public:
  // Opens the port for the remote tracers' `slots` (mpi:N) and writes where it is to `path` ("HOST PORT":
  // this host's name, or COHORT_NODE_PORT_HOST; the TCP port COHORT_NODE_PORT_TCP, or any free one),
  // whole, by a rename, so that a node never reads half of it. Remote tracers made within `first_wait` of now wait
  // that long for their node (a run that starts with nodes still joining). Call before the first MPI use
  // of the process (it asks for MPI_THREAD_MULTIPLE); throws where the library lacks it or the port
  // cannot be opened or written.
  static NodePort& open(const std::string& path, std::chrono::milliseconds first_wait, const std::vector<int>& slots);
  // The port, when open.
  static NodePort* get();

  // A remote tracer serves `slot`: nodes may join it.
  void serve_slot(int slot);
  // Whether the slot's node answers (a joining node is refused then); a node that timed out or left frees it.
  void set_busy(int slot, bool busy);
  // The node that joined `slot` and waits for its tracer, if any (taken: the slot is busy from then on).
  std::optional<JoiningNode> take(int slot);
  // Whether a node that joined `slot` waits for its tracer to take it.
  bool waiting(int slot);
  // Waits until a node joins `slot`, at most until the deadline.
  std::optional<JoiningNode> wait_for(int slot, MpiClock::time_point deadline);
  MpiClock::time_point first_deadline() const { return first_deadline_; }
  const std::string& path() const { return path_; }

  // Stops taking nodes and removes the port's file (the session's finalize calls it first).
  void close();

 private:
  NodePort(std::string path, std::chrono::milliseconds first_wait, const std::vector<int>& slots);
  void accept_loop();
  void greet(int peer);
  // Refuses the newcomer on `peer` with `why` (logged here; the node logs it too) and forgets it.
  void refuse(int peer, const std::string& why);

  std::string path_;
  MpiClock::time_point first_deadline_;
  std::mutex mutex_;
  std::condition_variable changed_;
  struct Slot {
    bool busy = false;
    std::optional<JoiningNode> waiting;
  };
  std::map<int, Slot> slots_;
  bool accept_ended_ = false;
  std::atomic<bool> closed_{false};
  int listening_ = -1;
  std::thread accepting_;
};

}  // namespace cohort::tracers
