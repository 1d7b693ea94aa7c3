// The emulated link's arithmetic (tracers/mpi/include/cohort/tracers/mpi_link_emulation.h): parsing
// COHORT_MPI_LINK's text and when messages arrive. The cluster case `mpi.cluster_link` checks it under mpirun.
#include "cohort/tracers/mpi_link_emulation.h"

#include <chrono>
#include <stdexcept>

#include <gtest/gtest.h>

namespace cohort::tracers {
namespace {

double ms_between(MpiClock::time_point a, MpiClock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

TEST(LinkEmulation, ParsesRatesAndLatencies) {
  const LinkSpec ten = parse_link_spec("10gbit,0.5ms");
  EXPECT_DOUBLE_EQ(ten.bytes_per_second, 1.25e9);
  EXPECT_DOUBLE_EQ(ten.latency_seconds, 0.5e-3);
  const LinkSpec slow = parse_link_spec("100Mbit,200us");
  EXPECT_DOUBLE_EQ(slow.bytes_per_second, 12.5e6);
  EXPECT_DOUBLE_EQ(slow.latency_seconds, 200e-6);
  EXPECT_DOUBLE_EQ(parse_link_spec("2.5gbit,0ms").latency_seconds, 0.0);
}

TEST(LinkEmulation, RefusesMalformedLinksNamingThem) {
  for (const char* bad : {"10gbit", "fast,1ms", "10gbyte,1ms", "10gbit,1hour", "0gbit,1ms", "-1gbit,1ms", "10gbit,-2ms", ""}) {
    try {
      parse_link_spec(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos) << e.what();
    }
  }
}

TEST(LinkEmulation, MessagesQueueBehindEachOtherThenTakeTheLatency) {
  LinkSchedule link(parse_link_spec("1gbit,0.5ms"));  // 125,000 bytes a millisecond
  const MpiClock::time_point t0 = MpiClock::now();
  // Two 1 ms messages handed over together: the second leaves when the first has been sent.
  EXPECT_NEAR(ms_between(t0, link.arrival(1, 125000, t0)), 1.5, 1e-6);
  EXPECT_NEAR(ms_between(t0, link.arrival(1, 125000, t0)), 2.5, 1e-6);
  // Another destination has a link of its own.
  EXPECT_NEAR(ms_between(t0, link.arrival(2, 125000, t0)), 1.5, 1e-6);
  // Once the link is idle again a message leaves at once: latency plus its own bytes.
  const MpiClock::time_point later = t0 + std::chrono::milliseconds(10);
  EXPECT_NEAR(ms_between(later, link.arrival(1, 12500, later)), 0.6, 1e-6);
}

}  // namespace
}  // namespace cohort::tracers
