// `--node-port` and `--node-wait`, the options of the commands that may be rank 0 of a session nodes join
// (docs/cluster.md, "Joining a running session"): `cohort render` and `cohort play`.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace cohort::app {

struct NodePortArgs {
  std::string port_file;  // empty: no port
  double first_wait_s = 0.0;
};

inline void add_node_port_options(CLI::App* cmd, NodePortArgs& a) {
  cmd->add_option("--node-port", a.port_file,
                  "open a port for nodes (a TCP socket whose host and port this file names; the connection is handed to "
                  "MPI_Comm_join): `cohort node MAP --join FILE --as N` started on its own (its own mpiexec, any host) "
                  "serves mpi:N, and a slot whose node died is served by the next that joins it (docs/cluster.md)");
  cmd->add_option("--node-wait", a.first_wait_s,
                  "with --node-port: how long the remote tracers wait for their nodes to join before the first frame "
                  "(seconds; later joins are taken any time)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
}

}  // namespace cohort::app
