#include "cohort/tracers/mpi_link.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

#include <mpi.h>
#include <spdlog/spdlog.h>

#include "cohort/tracers/mpi_link_emulation.h"
#include "cohort/tracers/mpi_wire.h"

namespace cohort::tracers {

namespace {
constexpr int kTag = wire::kControlTag;  // every control message; the header says what it is

int finalize_timeout_seconds() {
  const char* text = std::getenv("COHORT_MPI_FINALIZE_TIMEOUT_S");
  const int seconds = text && *text ? std::atoi(text) : 10;
  return seconds > 0 ? seconds : 10;
}

std::atomic<bool> want_thread_multiple{false};

std::string mpi_error_text(int code) {
  char text[MPI_MAX_ERROR_STRING] = {};
  int length = 0;
  MPI_Error_string(code, text, &length);
  return std::string(text, size_t(std::max(length, 0)));
}
}  // namespace

struct MpiSession::Impl {
  MPI_Comm comm = MPI_COMM_NULL;
  bool we_initialized = false;
  // Peers that joined the running session (rank 0), or rank 0 seen from a node that joined (peer 0): each is
  // rank 0 of its intercommunicator. Every other peer is a rank of `comm`.
  std::map<int, MPI_Comm> intercomms;
  int next_joined_peer = kFirstJoinedPeer;
  struct Endpoint {
    MPI_Comm comm;
    int rank;
  };
  Endpoint endpoint(int peer) const {
    auto found = intercomms.find(peer);
    if (found != intercomms.end()) return {found->second, 0};
    return {comm, peer};
  }
  struct Outgoing {
    int destination;
    std::vector<uint8_t> bytes;  // empty for a send in place
    MPI_Request request;
    const void* group = nullptr;  // a send in place: the buffer it lies in (MpiSession::flush_group)
    // Under an emulated link, a send waits here until `release` (its arrival) before MPI gets it.
    bool held = false;
    MpiClock::time_point release{};
    int tag = 0;
    const void* data = nullptr;
    int size = 0;
  };
  std::list<Outgoing> sends;
  std::optional<LinkSchedule> link;  // COHORT_MPI_LINK
  std::thread link_pump;             // hands held sends to MPI when they are due
  std::atomic<bool> link_pump_stop{false};

  bool isend(Outgoing& out) {
    out.held = false;
    // MPI-3 takes a const buffer; the cast is for MPI-2 headers that still declare void*.
    const Endpoint to = endpoint(out.destination);
    return MPI_Isend(const_cast<void*>(out.data), out.size, MPI_BYTE, to.rank, out.tag, to.comm, &out.request) ==
           MPI_SUCCESS;
  }
  // Queues a send: to MPI now, or held until the emulated link would deliver it. False if MPI refused it.
  bool start(Outgoing& out) {
    if (link) {
      out.release = link->arrival(out.destination, size_t(out.size), MpiClock::now());
      if (out.release > MpiClock::now()) {
        out.held = true;
        return true;
      }
    }
    return isend(out);
  }
  // Hands the held sends that are due to MPI, in order per destination.
  void release_due(MpiClock::time_point now) {
    std::vector<int> waiting;  // destinations whose first held send is not due: later ones wait behind it
    for (Outgoing& out : sends) {
      if (!out.held) continue;
      if (std::find(waiting.begin(), waiting.end(), out.destination) != waiting.end()) continue;
      if (out.release <= now) isend(out);
      else waiting.push_back(out.destination);
    }
  }
  // Whether a send has completed (a held one has not started).
  bool completed(Outgoing& out) {
    if (out.held) return false;
    int done = 0;
    MPI_Test(&out.request, &done, MPI_STATUS_IGNORE);
    return done != 0;
  }
  struct Incoming {
    std::vector<uint8_t> bytes;
    MPI_Request request;
  };
  std::map<int, Incoming> receives;  // per source: a matched control message still arriving
  struct Piece {
    MPI_Request request = MPI_REQUEST_NULL;
    std::vector<uint8_t> dropped;  // scratch for a piece nobody placed
  };
  std::map<int, std::list<Piece>> pieces;  // per source: pieces matched, still arriving

  // Completes what has arrived of `source`'s pieces; true when none is left.
  bool test_pieces(int source) {
    auto found = pieces.find(source);
    if (found == pieces.end()) return true;
    for (auto it = found->second.begin(); it != found->second.end();) {
      int done = 0;
      MPI_Test(&it->request, &done, MPI_STATUS_IGNORE);
      it = done ? found->second.erase(it) : std::next(it);
    }
    return found->second.empty();
  }
  void test_sends() {
    if (link) release_due(MpiClock::now());
    for (auto it = sends.begin(); it != sends.end();) it = completed(*it) ? sends.erase(it) : std::next(it);
  }
  std::vector<uint8_t> farewell;
  std::set<int> released;            // peers that left: no farewell for them
  std::vector<MPI_Comm> abandoned;   // intercommunicators of peers that were abandoned
  std::vector<std::function<void()>> before_finalize;
};

MpiSession& MpiSession::get() {
  static MpiSession session;
  return session;
}

void MpiSession::require_thread_multiple() { want_thread_multiple.store(true); }

int MpiSession::join_peer(int socket) {
  {
    std::lock_guard lock(mutex_);
    if (finalized_) return -1;
    if (!thread_multiple_)
      throw std::runtime_error("taking joining nodes needs MPI_THREAD_MULTIPLE (MpiSession::require_thread_multiple "
                               "before the session starts)");
  }
  MPI_Comm inter = MPI_COMM_NULL;
  const int code = MPI_Comm_join(socket, &inter);
  std::lock_guard lock(mutex_);
  if (code != MPI_SUCCESS) {
    spdlog::warn("rank 0: MPI_Comm_join with a joining node failed: {}", mpi_error_text(code));
    return -1;
  }
  if (finalized_) return -1;
  MPI_Comm_set_errhandler(inter, MPI_ERRORS_RETURN);
  const int peer = impl_->next_joined_peer++;
  impl_->intercomms[peer] = inter;
  return peer;
}

void MpiSession::join(int socket, int slot) {
  MPI_Comm inter = MPI_COMM_NULL;
  if (const int code = MPI_Comm_join(socket, &inter); code != MPI_SUCCESS)
    throw std::runtime_error("MPI_Comm_join with rank 0 failed: " + mpi_error_text(code));
  std::lock_guard lock(mutex_);
  MPI_Comm_set_errhandler(inter, MPI_ERRORS_RETURN);
  impl_->intercomms[0] = inter;
  joined_ = true;
  rank_ = slot;
}

void MpiSession::abandon(int peer) {
  std::lock_guard lock(mutex_);
  if (finalized_) return;
  auto release = [](MPI_Request& request) {
    if (request != MPI_REQUEST_NULL) MPI_Request_free(&request);
  };
  for (auto it = impl_->sends.begin(); it != impl_->sends.end();) {
    if (it->destination != peer) {
      ++it;
      continue;
    }
    if (!it->held) release(it->request);
    it = impl_->sends.erase(it);
  }
  if (auto r = impl_->receives.find(peer); r != impl_->receives.end()) {
    release(r->second.request);
    impl_->receives.erase(r);
  }
  if (auto p = impl_->pieces.find(peer); p != impl_->pieces.end()) {
    for (auto& piece : p->second) release(piece.request);
    impl_->pieces.erase(p);
  }
  // The intercommunicator is kept, not freed: a lost peer may have left messages in it (MPICH aborts on
  // freeing such a communicator), and nothing is sent on it again.
  if (auto found = impl_->intercomms.find(peer); found != impl_->intercomms.end()) {
    impl_->abandoned.push_back(found->second);
    impl_->intercomms.erase(found);
  }
  released_locked(peer);
}

MpiSession::MpiSession() : impl_(new Impl) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) {
    int provided = 0;
    const int wanted = want_thread_multiple.load() ? MPI_THREAD_MULTIPLE : MPI_THREAD_SERIALIZED;
    if (MPI_Init_thread(nullptr, nullptr, wanted, &provided) != MPI_SUCCESS)
      throw std::runtime_error("MPI_Init_thread failed");
    impl_->we_initialized = true;
    if (provided < MPI_THREAD_SERIALIZED)
      throw std::runtime_error("this MPI library offers no MPI_THREAD_SERIALIZED; remote tracers need it");
  }
  int provided = 0;
  MPI_Query_thread(&provided);
  thread_multiple_ = provided >= MPI_THREAD_MULTIPLE;
  if (want_thread_multiple.load() && !thread_multiple_)
    throw std::runtime_error("this MPI library offers no MPI_THREAD_MULTIPLE, which taking joining nodes needs (they "
                             "join on a thread of their own); start the nodes under rank 0's mpirun instead");
  // Errors come back as codes on the world and self communicators too (a library may report a lost rank
  // or a failed join on them): a lost node fails its tracer, not the process.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_set_errhandler(MPI_COMM_SELF, MPI_ERRORS_RETURN);
  // A communicator of our own, so that Cohort's messages never meet another library's.
  MPI_Comm_dup(MPI_COMM_WORLD, &impl_->comm);
  // Failures come back as error codes (a lost peer fails that peer's tracer, not the process), where
  // the library and launcher let the job outlive a rank at all.
  MPI_Comm_set_errhandler(impl_->comm, MPI_ERRORS_RETURN);
  MPI_Comm_rank(impl_->comm, &rank_);
  MPI_Comm_size(impl_->comm, &size_);
  if (std::optional<LinkSpec> link = link_spec_from_environment()) {
    impl_->link.emplace(*link);
    const LinkSpec& spec = impl_->link->spec();
    spdlog::info("rank {}: this rank's sends go through an emulated link of {:.3g} Gbit/s and {:.3g} ms one way "
                 "(COHORT_MPI_LINK={})", rank_, spec.bytes_per_second * 8e-9, spec.latency_seconds * 1e3, spec.text);
    // A held send is due at its arrival time, whether or not the rank is calling into the session then.
    impl_->link_pump = std::thread([this] {
      while (!impl_->link_pump_stop.load()) {
        {
          std::lock_guard lock(mutex_);
          if (finalized_) return;
          impl_->release_due(MpiClock::now());
        }
        std::this_thread::sleep_for(std::chrono::microseconds(50));
      }
    });
  }
}

MpiSession::~MpiSession() {
  finalize();
  delete impl_;
}

void MpiSession::before_finalize(std::function<void()> work) {
  std::lock_guard lock(mutex_);
  impl_->before_finalize.push_back(std::move(work));
}

void MpiSession::finalize() {
  std::vector<std::function<void()>> first;
  {
    std::lock_guard lock(mutex_);
    first.swap(impl_->before_finalize);
  }
  for (auto& work : first) work();
  impl_->link_pump_stop.store(true);
  if (impl_->link_pump.joinable()) impl_->link_pump.join();
  std::lock_guard lock(mutex_);
  if (finalized_) return;
  finalized_ = true;
  // Sends an emulated link still holds leave now.
  for (Impl::Outgoing& out : impl_->sends)
    if (out.held) impl_->isend(out);
  if (rank_ == 0 && !joined_ && !impl_->farewell.empty()) {
    std::vector<int> peers;
    for (int r = 1; r < size_; ++r) peers.push_back(r);
    for (const auto& [peer, inter] : impl_->intercomms) peers.push_back(peer);
    for (int peer : peers) {
      if (impl_->released.count(peer)) continue;
      impl_->sends.push_back({peer, impl_->farewell, MPI_REQUEST_NULL});
      Impl::Outgoing& out = impl_->sends.back();
      const Impl::Endpoint to = impl_->endpoint(peer);
      MPI_Isend(out.bytes.data(), int(out.bytes.size()), MPI_BYTE, to.rank, kTag, to.comm, &out.request);
    }
  }
  // Sends still queued get a second; then they are freed (the library completes or drops them).
  const auto deadline = MpiClock::now() + std::chrono::seconds(1);
  while (!impl_->sends.empty() && MpiClock::now() < deadline) {
    for (auto it = impl_->sends.begin(); it != impl_->sends.end();)
      it = impl_->completed(*it) ? impl_->sends.erase(it) : std::next(it);
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  // (A request from a rank that was lost may already be null.)
  auto release = [](MPI_Request& request) {
    if (request != MPI_REQUEST_NULL) MPI_Request_free(&request);
  };
  for (auto& s : impl_->sends) release(s.request);
  impl_->sends.clear();
  for (auto& [source, r] : impl_->receives) release(r.request);
  impl_->receives.clear();
  for (auto& [source, list] : impl_->pieces)
    for (auto& piece : list) release(piece.request);
  impl_->pieces.clear();
  // Messages that came and that nobody received (a node's hello to a rank 0 that never named it): MPICH
  // refuses to free a communicator that holds any (it aborts the process), so they are received and dropped.
  auto drain = [](MPI_Comm comm) {
    for (;;) {
      int found = 0;
      MPI_Message message;
      MPI_Status status;
      if (MPI_Improbe(MPI_ANY_SOURCE, MPI_ANY_TAG, comm, &found, &message, &status) != MPI_SUCCESS || !found) break;
      int count = 0;
      MPI_Get_count(&status, MPI_BYTE, &count);
      std::vector<uint8_t> dropped(size_t(std::max(count, 1)));
      MPI_Mrecv(dropped.data(), count, MPI_BYTE, &message, MPI_STATUS_IGNORE);
    }
  };
  drain(impl_->comm);
  MPI_Comm_free(&impl_->comm);
  int mpi_finalized = 0;
  MPI_Finalized(&mpi_finalized);
  if (!impl_->we_initialized || mpi_finalized) return;
  // MPI_Finalize synchronizes with every rank, and with every process still connected by a join, so
  // a rank that was lost (killed, under a launcher that let the job go on) can keep it from returning, as
  // can the disconnect of a node that joined. Everything is written by now: past the deadline the process
  // leaves without them rather than hang.
  auto done = std::make_shared<std::atomic<bool>>(false);
  const int seconds = finalize_timeout_seconds();
  std::thread([done, seconds] {
    const auto deadline = MpiClock::now() + std::chrono::seconds(seconds);
    while (!done->load() && MpiClock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (done->load()) return;
    std::fprintf(stderr, "cohort: MPI_Finalize did not return within %d s (a rank was lost?); leaving without it\n",
                 seconds);
    std::fflush(nullptr);
    std::_Exit(0);
  }).detach();
  // Both ends of a joined node's intercommunicator disconnect (collective over it): rank 0 once it has
  // said shutdown to the node, the node once it has heard it; then neither waits for the other to finalize.
  for (auto& [peer, inter] : impl_->intercomms) {
    drain(inter);
    MPI_Comm_disconnect(&inter);
  }
  impl_->intercomms.clear();
  MPI_Finalize();
  done->store(true);
}

void MpiSession::send(int destination, std::vector<uint8_t> bytes) {
  if (bytes.size() > size_t(std::numeric_limits<int>::max()))
    throw std::runtime_error("MPI message of " + std::to_string(bytes.size()) + " bytes is over the 2 GiB a send takes");
  std::lock_guard lock(mutex_);
  if (finalized_) throw std::runtime_error("MPI send after the session was finalized");
  impl_->sends.push_back({destination, std::move(bytes), MPI_REQUEST_NULL});
  Impl::Outgoing& out = impl_->sends.back();
  out.tag = kTag, out.data = out.bytes.data(), out.size = int(out.bytes.size());
  if (!impl_->start(out)) {
    impl_->sends.pop_back();
    throw std::runtime_error("MPI_Isend to rank " + std::to_string(destination) + " failed");
  }
}

void MpiSession::send_in_place(int destination, int tag, const void* data, size_t size, const void* group) {
  if (size > size_t(std::numeric_limits<int>::max()))
    throw std::runtime_error("MPI message of " + std::to_string(size) + " bytes is over the 2 GiB a send takes");
  std::lock_guard lock(mutex_);
  if (finalized_) throw std::runtime_error("MPI send after the session was finalized");
  impl_->sends.push_back({destination, {}, MPI_REQUEST_NULL, group});
  Impl::Outgoing& out = impl_->sends.back();
  out.tag = tag, out.data = data, out.size = int(size);
  if (!impl_->start(out)) {
    impl_->sends.pop_back();
    throw std::runtime_error("MPI_Isend to rank " + std::to_string(destination) + " failed");
  }
}

void MpiSession::set_farewell(std::vector<uint8_t> bytes) {
  std::lock_guard lock(mutex_);
  impl_->farewell = std::move(bytes);
}

void MpiSession::released(int peer) {
  std::lock_guard lock(mutex_);
  released_locked(peer);
}

void MpiSession::released_locked(int peer) { impl_->released.insert(peer); }

size_t MpiSession::progress_sends() {
  std::lock_guard lock(mutex_);
  if (finalized_) return 0;
  impl_->test_sends();
  return impl_->sends.size();
}

bool MpiSession::flush_sends(int destination, MpiClock::time_point deadline) {
  for (;;) {
    bool pending = false;
    {
      std::lock_guard lock(mutex_);
      if (finalized_) return impl_->sends.empty();
      if (impl_->link) impl_->release_due(MpiClock::now());
      for (auto it = impl_->sends.begin(); it != impl_->sends.end();) {
        const bool done = impl_->completed(*it);
        if (!done && (destination < 0 || it->destination == destination)) pending = true;
        it = done ? impl_->sends.erase(it) : std::next(it);
      }
    }
    if (!pending) return true;
    if (MpiClock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
}

bool MpiSession::flush_group(const void* group, MpiClock::time_point deadline) {
  for (;;) {
    bool pending = false;
    {
      std::lock_guard lock(mutex_);
      if (finalized_) return true;
      if (impl_->link) impl_->release_due(MpiClock::now());
      for (auto it = impl_->sends.begin(); it != impl_->sends.end();) {
        const bool done = impl_->completed(*it);
        if (!done && it->group == group) pending = true;
        it = done ? impl_->sends.erase(it) : std::next(it);
      }
    }
    if (!pending) return true;
    if (MpiClock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
}

std::optional<std::vector<uint8_t>> MpiSession::receive(int source, MpiClock::time_point deadline, PieceSink* pieces,
                                                        const std::function<void()>& between_polls) {
  // Polls: yields at first (a band's answer is often close), then sleeps briefly so that a waiting
  // tracer thread does not take a core from the ones rendering. A piece that came starts it over: the
  // band's next piece, or its end, follows.
  for (int polls = 0;; ++polls) {
    {
      std::lock_guard lock(mutex_);
      if (finalized_) throw std::runtime_error("MPI receive after the session was finalized");
      auto pending = impl_->receives.find(source);
      // Match what has come, in order, up to the next control message: pieces go where the sink says.
      while (pending == impl_->receives.end()) {
        int found = 0;
        MPI_Message message;
        MPI_Status status;
        const Impl::Endpoint from = impl_->endpoint(source);
        if (MPI_Improbe(from.rank, pieces ? MPI_ANY_TAG : kTag, from.comm, &found, &message, &status) != MPI_SUCCESS)
          found = 0;  // a lost peer: nothing more comes
        if (!found) break;
        int count = 0;
        MPI_Get_count(&status, MPI_BYTE, &count);
        if (status.MPI_TAG == kTag) {
          Impl::Incoming& in = impl_->receives[source];
          in.bytes.resize(size_t(count));
          MPI_Imrecv(in.bytes.data(), count, MPI_BYTE, &message, &in.request);
          pending = impl_->receives.find(source);
          break;
        }
        polls = 0;
        Impl::Piece& piece = impl_->pieces[source].emplace_back();
        void* into = pieces->place(status.MPI_TAG, size_t(count));
        if (!into) {
          piece.dropped.resize(std::max(count, 1));
          into = piece.dropped.data();
        }
        MPI_Imrecv(into, count, MPI_BYTE, &message, &piece.request);
      }
      const bool pieces_landed = impl_->test_pieces(source);
      if (pending != impl_->receives.end()) {
        int done = 0;
        MPI_Test(&pending->second.request, &done, MPI_STATUS_IGNORE);
        if (done) pending->second.request = MPI_REQUEST_NULL;
        if (pending->second.request == MPI_REQUEST_NULL && pieces_landed) {
          std::vector<uint8_t> bytes = std::move(pending->second.bytes);
          impl_->receives.erase(pending);
          return bytes;
        }
      }
      // Sends progress too while we wait (a library may move data only inside MPI calls).
      impl_->test_sends();
    }
    if (MpiClock::now() >= deadline) return std::nullopt;
    if (between_polls) between_polls();
    if (polls < 200)
      std::this_thread::yield();
    else
      std::this_thread::sleep_for(std::chrono::microseconds(polls < 2000 ? 20 : 200));
  }
}

bool MpiSession::control_waiting(int source) {
  std::lock_guard lock(mutex_);
  if (finalized_) return false;
  if (impl_->receives.count(source)) return true;  // matched, still arriving
  int found = 0;
  const Impl::Endpoint from = impl_->endpoint(source);
  if (MPI_Iprobe(from.rank, kTag, from.comm, &found, MPI_STATUS_IGNORE) != MPI_SUCCESS) return false;
  return found != 0;
}

bool MpiSession::settle_pieces(int source, MpiClock::time_point deadline) {
  for (;;) {
    {
      std::lock_guard lock(mutex_);
      if (finalized_ || impl_->test_pieces(source)) return true;
      impl_->test_sends();
    }
    if (MpiClock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(20));
  }
}

}  // namespace cohort::tracers
