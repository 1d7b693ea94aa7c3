#include "cohort/tracers/mpi_node_port.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <stdexcept>

#include <unistd.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "cohort/tracers/mpi_join_socket.h"

namespace cohort::tracers {

namespace {
// A newcomer connects once it has loaded its scene and opened its tracers, so its join and hello follow
// at once: this bounds a node that connects and then says nothing.
constexpr std::chrono::seconds kGreetingTimeout{10};

// A connection that does not say the magic words by then is dropped.
constexpr std::chrono::seconds kMagicTimeout{5};

// Never destroyed: the session's finalize closes it (static destruction order would not promise that).
NodePort*& the_port() {
  static NodePort* port = nullptr;
  return port;
}

std::optional<wire::Message> receive_message(MpiSession& mpi, int peer, MpiClock::time_point deadline,
                                             std::string& problem) {
  std::optional<std::vector<uint8_t>> bytes = mpi.receive(peer, deadline);
  if (!bytes) {
    problem = fmt::format("it said nothing within {} s", kGreetingTimeout.count());
    return std::nullopt;
  }
  try {
    return wire::parse_message(bytes->data(), bytes->size());
  } catch (const wire::WireError& e) {
    problem = std::string("malformed message: ") + e.what();
    return std::nullopt;
  }
}
}  // namespace

NodePort& NodePort::open(const std::string& path, std::chrono::milliseconds first_wait, const std::vector<int>& slots) {
  MpiSession::require_thread_multiple();
  MpiSession& mpi = MpiSession::get();
  if (the_port()) throw std::runtime_error("a node port is already open (" + the_port()->path() + ")");
  the_port() = new NodePort(path, first_wait, slots);
  // The port's thread must stop calling MPI before MPI ends, whoever finalizes first.
  mpi.before_finalize([] {
    if (NodePort* port = NodePort::get()) port->close();
  });
  return *the_port();
}

NodePort* NodePort::get() { return the_port(); }

NodePort::NodePort(std::string path, std::chrono::milliseconds first_wait, const std::vector<int>& slots)
    : path_(std::move(path)), first_deadline_(MpiClock::now() + first_wait) {
  MpiSession& mpi = MpiSession::get();
  if (mpi.rank() != 0) throw std::runtime_error("only rank 0 opens a port for nodes (--node-port)");
  // Every slot is known before the first node may come (the tracers are made one after another); one
  // that a world rank serves (mpirun -np N) is busy until that node fails.
  for (int slot : slots) slots_[slot].busy = slot < mpi.size();
  const char* fixed = std::getenv("COHORT_NODE_PORT_TCP");
  listening_ = join_socket::listen_on(fixed && *fixed ? std::atoi(fixed) : 0);
  std::string host;
  if (const char* named = std::getenv("COHORT_NODE_PORT_HOST"); named && *named) {
    host = named;
  } else {
    char name[256] = {};
    host = gethostname(name, sizeof name - 1) == 0 ? name : "localhost";
  }
  const std::string partial = path_ + ".partial";
  {
    std::ofstream out(partial);
    out << host << " " << join_socket::port_of(listening_) << "\n";
    if (!out) throw std::runtime_error("cannot write the port to " + partial);
  }
  if (std::rename(partial.c_str(), path_.c_str()) != 0)
    throw std::runtime_error("cannot rename " + partial + " to " + path_);
  spdlog::info("rank 0: nodes join through {}:{} (named in {}: cohort node MAP --join {} --as N)", host,
               join_socket::port_of(listening_), path_, path_);
  accepting_ = std::thread([this] { accept_loop(); });
}

void NodePort::close() {
  if (closed_.exchange(true)) return;
  // The thread sees it within its next poll (at most a greeting in progress, bounded, later).
  accepting_.join();
  join_socket::close_socket(listening_);
  std::remove(path_.c_str());
}

void NodePort::accept_loop() {
  MpiSession& mpi = MpiSession::get();
  while (!closed_.load()) {
    const int connection = join_socket::accept_within(listening_, std::chrono::milliseconds(100));
    if (connection < 0) continue;
    // Only a node that is joining right now goes to MPI_Comm_join, which waits for its other end.
    if (!join_socket::receive_exactly(connection, join_socket::kMagic, kMagicTimeout)) {
      spdlog::warn("rank 0: dropped a connection to the node port that did not say it joins within {} s",
                   kMagicTimeout.count());
      join_socket::close_socket(connection);
      continue;
    }
    const int peer = mpi.join_peer(connection);
    join_socket::close_socket(connection);
    if (peer >= 0) greet(peer);
  }
  std::lock_guard lock(mutex_);
  accept_ended_ = true;
  changed_.notify_all();
}

void NodePort::refuse(int peer, const std::string& why) {
  MpiSession& mpi = MpiSession::get();
  spdlog::warn("rank 0: refused a node that joined: {}", why);
  try {
    mpi.send(peer, wire::frame_message(wire::Kind::refuse, 0, wire::encode_text(why)));
    mpi.flush_sends(peer, MpiClock::now() + std::chrono::seconds(1));
  } catch (const std::exception& e) {
    spdlog::warn("rank 0: could not tell the refused node why: {}", e.what());
  }
  mpi.abandon(peer);
}

void NodePort::greet(int peer) {
  MpiSession& mpi = MpiSession::get();
  const auto connected = MpiClock::now();
  const auto deadline = connected + kGreetingTimeout;
  std::string problem;
  std::optional<wire::Message> join = receive_message(mpi, peer, deadline, problem);
  if (!join || join->kind != wire::Kind::join) {
    refuse(peer, join ? fmt::format("its first message was {}, not join", wire::to_string(join->kind)) : problem);
    return;
  }
  uint32_t asked = 0;
  try {
    asked = wire::decode_join(join->payload);
  } catch (const wire::WireError& e) {
    refuse(peer, std::string("malformed join: ") + e.what());
    return;
  }
  std::optional<wire::Message> said = receive_message(mpi, peer, deadline, problem);
  if (said && said->kind == wire::Kind::load_failed) {
    std::string reason;
    try {
      reason = wire::decode_text(said->payload);
    } catch (const wire::WireError& e) {
      reason = std::string("(unreadable reason: ") + e.what() + ")";
    }
    spdlog::warn("rank 0: a node joining mpi:{} could not start (its scene or its tracers) and leaves: {}", asked, reason);
    mpi.abandon(peer);
    return;
  }
  if (!said || said->kind != wire::Kind::hello) {
    refuse(peer, said ? fmt::format("it sent {} where its hello was due", wire::to_string(said->kind)) : problem);
    return;
  }
  wire::Hello hello;
  try {
    hello = wire::decode_hello(said->payload);
  } catch (const wire::WireError& e) {
    refuse(peer, std::string("malformed hello: ") + e.what());
    return;
  }
  int slot = int(asked);
  {
    std::unique_lock lock(mutex_);
    if (asked == 0) {
      slot = -1;
      for (const auto& [n, s] : slots_)
        if (!s.busy && !s.waiting) {
          slot = n;
          break;
        }
    }
    auto found = slots_.find(slot);
    // The versions first: with another build nothing else matters.
    std::string why = wire::version_mismatch(hello, std::max(slot, 0));
    if (why.empty() && slot < 0) why = "every slot (mpi:N) of rank 0 has a node";
    if (why.empty() && found == slots_.end())
      why = fmt::format("rank 0 has no remote tracer mpi:{} (its --tracers name the slots)", slot);
    if (why.empty() && found->second.busy) why = fmt::format("mpi:{} is busy: its node answers", slot);
    if (why.empty() && found->second.waiting) why = fmt::format("mpi:{} is busy: another node joined it first", slot);
    if (!why.empty()) {
      lock.unlock();
      refuse(peer, why);
      return;
    }
    found->second.waiting = JoiningNode{peer, hello, connected};
  }
  mpi.send(peer, wire::frame_message(wire::Kind::welcome, 0, wire::encode_text(fmt::format("mpi:{}", slot))));
  spdlog::info("rank 0: a node on {} ({}) joined mpi:{}, greeted {:.1f} ms after its MPI_Comm_join", hello.host,
               hello.tracers, slot, std::chrono::duration<double, std::milli>(MpiClock::now() - connected).count());
  changed_.notify_all();
}

void NodePort::serve_slot(int slot) {
  std::lock_guard lock(mutex_);
  slots_[slot];
}

void NodePort::set_busy(int slot, bool busy) {
  std::lock_guard lock(mutex_);
  slots_[slot].busy = busy;
}

std::optional<JoiningNode> NodePort::take(int slot) {
  std::lock_guard lock(mutex_);
  auto found = slots_.find(slot);
  if (found == slots_.end() || !found->second.waiting) return std::nullopt;
  std::optional<JoiningNode> node = std::move(found->second.waiting);
  found->second.waiting.reset();
  found->second.busy = true;
  return node;
}

bool NodePort::waiting(int slot) {
  std::lock_guard lock(mutex_);
  auto found = slots_.find(slot);
  return found != slots_.end() && found->second.waiting.has_value();
}

std::optional<JoiningNode> NodePort::wait_for(int slot, MpiClock::time_point deadline) {
  {
    std::unique_lock lock(mutex_);
    changed_.wait_until(lock, deadline, [&] {
      auto found = slots_.find(slot);
      return accept_ended_ || (found != slots_.end() && found->second.waiting);
    });
  }
  return take(slot);
}

}  // namespace cohort::tracers
