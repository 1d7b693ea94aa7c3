// An emulated network link under a rank's sends (COHORT_MPI_LINK, docs/cluster.md "Emulated links"). The
// kernels of the machines Cohort is measured on have no netem, so a link's bandwidth and latency are
// modelled where the messages leave: a message to a destination leaves once the link to it has carried
// the messages queued before it (their bytes at the link's rate), and is handed to MPI when it would
// arrive, the one-way latency later; on one host the library then delivers it at once. One full-duplex
// link per (sending rank, destination): a star of switched links, each rank on a port of its own.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>

#include "cohort/tracers/mpi_link.h"

namespace cohort::tracers {

struct LinkSpec {
  double bytes_per_second = 0.0;
  double latency_seconds = 0.0;
  std::string text;  // as given, for logs
};

// "10gbit,0.5ms": a rate in bit/s with a k, m or g prefix (100mbit, 1gbit, 2.5gbit) and a one-way latency
// in ms or us (0.5ms, 200us, 0ms). Throws std::invalid_argument naming the text and what is wrong.
LinkSpec parse_link_spec(const std::string& text);

// The link COHORT_MPI_LINK asks for, or none when it is unset or empty (errors as parse_link_spec's, naming
// the variable).
std::optional<LinkSpec> link_spec_from_environment();

class LinkSchedule {
 public:
  explicit LinkSchedule(LinkSpec spec) : spec_(std::move(spec)) {}
  // When a message of `bytes` handed over at `now` for `destination` arrives there (and so when it is
  // handed to MPI). Messages to one destination arrive in the order they were handed over.
  MpiClock::time_point arrival(int destination, size_t bytes, MpiClock::time_point now);
  const LinkSpec& spec() const { return spec_; }

 private:
  LinkSpec spec_;
  std::map<int, MpiClock::time_point> free_at_;  // per destination: when the link has sent what it holds
};

}  // namespace cohort::tracers
