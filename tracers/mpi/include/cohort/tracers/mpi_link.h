// The process's MPI session and its one way to move bytes: non-blocking sends and matched-probe
// receives (MPI_Improbe + MPI_Imrecv), polled with MPI_Test against a deadline, so no call waits
// forever. Every MPI call goes through one mutex: rank 0 talks to its nodes from several tracer
// threads, and a library that offers less than MPI_THREAD_MULTIPLE is then still used correctly.
// Standard MPI-3 only (Open MPI and MPICH alike).
#pragma once

#include <chrono>
#include <cstdint>
#include <list>
#include <mutex>
#include <optional>
#include <vector>

namespace cohort::tracers {

using MpiClock = std::chrono::steady_clock;

class MpiSession {
 public:
  // Initializes MPI on first use (MPI_Init_thread) unless the program already did; finalizes at exit.
  static MpiSession& get();
  int rank() const { return rank_; }
  int size() const { return size_; }
  // Finalize now (sends still pending are given up to a second). Later MPI use throws.
  void finalize();
  bool finalized() const { return finalized_; }

  // Queues `bytes` for `destination`; the session keeps them until the send has completed.
  void send(int destination, std::vector<uint8_t> bytes);
  // Progresses the queued sends; returns how many are still in flight.
  size_t progress_sends();
  // Waits until every queued send to `destination` (or all, with -1) has completed, at most until the
  // deadline; false if some had not.
  bool flush_sends(int destination, MpiClock::time_point deadline);
  // The next message from `source`, or nothing when none has fully arrived by the deadline. A message
  // whose receipt began and did not finish is picked up by the next call for that source.
  std::optional<std::vector<uint8_t>> receive(int source, MpiClock::time_point deadline);

  // Rank 0: the message finalize() sends to every rank above 0 that was not released, so that nodes
  // no tracer talked to (or whose tracer failed to start) leave too.
  void set_farewell(std::vector<uint8_t> bytes);
  void released(int rank);

  ~MpiSession();

 private:
  MpiSession();
  struct Impl;
  Impl* impl_ = nullptr;
  int rank_ = 0, size_ = 1;
  bool finalized_ = false;
  std::mutex mutex_;
};

}  // namespace cohort::tracers
