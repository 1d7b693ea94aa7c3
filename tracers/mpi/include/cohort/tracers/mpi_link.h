// The process's MPI session and its one way to move bytes: non-blocking sends and matched-probe
// receives (MPI_Improbe + MPI_Imrecv), polled with MPI_Test against a deadline, so no call waits
// forever. Every MPI call goes through one mutex: rank 0 talks to its nodes from several tracer
// threads, and a library that offers less than MPI_THREAD_MULTIPLE is then still used correctly.
// Standard MPI-3 only (Open MPI and MPICH alike).
//
// A peer is named by an int: the world ranks of `mpirun -np N` are themselves (peer 2 is world rank 2);
// a node that joined rank 0's running session (MPI-2's MPI_Comm_join, docs/cluster.md "Joining a running
// session") is a peer id of its own, kFirstJoinedPeer and up, that stands for rank 0 of its
// intercommunicator. On a node that joined, peer 0 is rank 0 across the intercommunicator.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <list>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace cohort::tracers {

using MpiClock = std::chrono::steady_clock;

// Where a band's pieces go as they arrive (rank 0's remote tracer, docs/cluster.md): messages on a tag
// other than the control tag are raw rows that the receiver places itself. Called with the session's
// lock held, so it must not call the session.
class PieceSink {
 public:
  virtual ~PieceSink() = default;
  // A message of `bytes` bytes on `tag` has been matched: the memory to receive it into (all of it), or
  // null to receive it into scratch and drop it.
  virtual void* place(int tag, size_t bytes) = 0;
};

constexpr int kFirstJoinedPeer = 1 << 16;

class MpiSession {
 public:
  // Initializes MPI on first use (MPI_Init_thread) unless the program already did; finalizes at exit.
  static MpiSession& get();
  // Before the first get(): ask for MPI_THREAD_MULTIPLE (joining nodes are taken on a thread of its own,
  // outside the session's lock). get() then throws when the library does not offer it.
  static void require_thread_multiple();
  // This process's rank in Cohort's session: its world rank, or for a node that joined, the slot it serves.
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool thread_multiple() const { return thread_multiple_; }

  // Rank 0: makes the node at the other end of `socket` (a TCP connection rank 0's NodePort accepted) a
  // peer: MPI_Comm_join (MPI-2), which waits until the node joins too; outside the session's lock (needs
  // MPI_THREAD_MULTIPLE). Its peer id, or -1 when the join failed.
  int join_peer(int socket);
  // A node: joins rank 0 over `socket` (MPI_Comm_join); peer 0 then is rank 0 across the
  // intercommunicator, and rank() says `slot`. Throws when the join fails.
  void join(int socket, int slot);
  bool joined() const { return joined_; }
  // Forget a peer that left or was replaced: its messages are dropped, sends to it given up; its
  // intercommunicator is disconnected in the background (bounded) where it said goodbye.
  void abandon(int peer);
  // Finalize now (sends still pending are given up to a second). Later MPI use throws.
  void finalize();
  // Runs `work` at the start of finalize(), before anything else (the node port stops taking nodes there).
  void before_finalize(std::function<void()> work);
  bool finalized() const { return finalized_; }

  // Queues `bytes` for `destination`; the session keeps them until the send has completed.
  void send(int destination, std::vector<uint8_t> bytes);
  // Sends `size` bytes from where they lie on `tag` (a band's piece, straight from the node's band
  // buffer): they must stay valid and unchanged until flush_sends(destination) or, for the sends of
  // one `group` (the buffer they lie in), flush_group(group) returns true.
  void send_in_place(int destination, int tag, const void* data, size_t size, const void* group = nullptr);
  // Waits until every send of `group` has completed, at most until the deadline; false if some had not.
  bool flush_group(const void* group, MpiClock::time_point deadline);
  // Progresses the queued sends; returns how many are still in flight.
  size_t progress_sends();
  // Waits until every queued send to `destination` (or all, with -1) has completed, at most until the
  // deadline; false if some had not.
  bool flush_sends(int destination, MpiClock::time_point deadline);
  // The next control message from `source`, or nothing when none has fully arrived by the deadline. A
  // message whose receipt began and did not finish is picked up by the next call for that source.
  // With `pieces`, messages on piece tags that come first are received where it places them, and a
  // control message is returned only once every piece matched before it has landed (messages from
  // one source are matched in the order they were sent, so a band's pieces are in place when the
  // band_rows that closes it is returned). Without, pieces wait unmatched. `between_polls`, when given,
  // runs between polls without the session's lock (it may send: a remote tracer's commits ahead).
  std::optional<std::vector<uint8_t>> receive(int source, MpiClock::time_point deadline, PieceSink* pieces = nullptr,
                                              const std::function<void()>& between_polls = {});
  // Whether a control message from `source` is waiting to be received (MPI_Iprobe; no wait).
  bool control_waiting(int source);
  // Waits at most until the deadline for the pieces from `source` that are being received into place
  // to land; false when some have not (they still land where they were placed, later).
  bool settle_pieces(int source, MpiClock::time_point deadline);

  // Rank 0: the message finalize() sends to every rank above 0 that was not released, so that nodes
  // no tracer talked to (or whose tracer failed to start) leave too.
  void set_farewell(std::vector<uint8_t> bytes);
  void released(int peer);

  ~MpiSession();

 private:
  MpiSession();
  void released_locked(int peer);
  struct Impl;
  Impl* impl_ = nullptr;
  int rank_ = 0, size_ = 1;
  bool finalized_ = false;
  bool thread_multiple_ = false;
  bool joined_ = false;
  std::mutex mutex_;
};

}  // namespace cohort::tracers
