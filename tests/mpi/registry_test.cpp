// Remote tracers by name: `mpi:RANK` in a --tracers list, and the refusals of names that cannot be one.
#include <gtest/gtest.h>

#include <algorithm>

#include "cohort/tracers/tracer_registry.h"

using namespace cohort;

TEST(MpiRegistry, RemoteTracersAreNamedByRank) {
  const auto specs = tracers::parse_tracer_list("embree,mpi:1,mpi:12");
  ASSERT_EQ(specs.size(), 3u);
  EXPECT_EQ(specs[1].kind, "mpi");
  EXPECT_EQ(specs[1].device, 1);
  EXPECT_EQ(specs[2].device, 12);
  EXPECT_EQ(specs[2].text, "mpi:12");
  EXPECT_TRUE(tracers::remote_tracers_built());
  // The in-process kinds, which the tracer tests iterate, leave it out: it needs a node to render.
  const auto kinds = tracers::built_tracer_kinds();
  EXPECT_EQ(std::find(kinds.begin(), kinds.end(), "mpi"), kinds.end());
}

TEST(MpiRegistry, ANodeServesOneRemoteTracer) {
  try {
    tracers::parse_tracer_list("mpi:1,embree,mpi:1");
    ADD_FAILURE() << "mpi:1 twice was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("named twice"), std::string::npos) << e.what();
  }
}

TEST(MpiRegistry, ARemoteTracerNeedsARankAboveZero) {
  for (const char* bad : {"mpi", "mpi:0", "mpi:x", "mpi:"}) {
    try {
      tracers::parse_tracer_list(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}
