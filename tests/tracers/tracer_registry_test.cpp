// Tracer lists: Embree leaves cores to the host when it renders beside CUDA tracers, and keeps them all
// otherwise.
#include <gtest/gtest.h>

#include <thread>

#include "cohort/tracers/tracer_registry.h"

using namespace cohort::tracers;

TEST(TracerRegistry, EmbreeLeavesAQuarterOfTheThreadsBesideGpus) {
  EXPECT_EQ(embree_threads_beside_gpus(32), 24);
  EXPECT_EQ(embree_threads_beside_gpus(16), 12);
  EXPECT_EQ(embree_threads_beside_gpus(4), 2);
  EXPECT_EQ(embree_threads_beside_gpus(2), 1) << "always one thread at least";
  EXPECT_EQ(embree_threads_beside_gpus(0), 1);
}

TEST(TracerRegistry, OnlyAListWithCudaLimitsEmbree) {
  const std::vector<TracerSpec> alone = parse_tracer_list("embree");
  ASSERT_EQ(alone.size(), 1u);
  EXPECT_EQ(alone[0].threads, 0) << "alone, Embree takes every thread";
  const std::vector<TracerSpec> opencl = parse_tracer_list("embree,opencl:0");
  EXPECT_EQ(opencl[0].threads, 0) << "an OpenCL device may be the CPU itself";
  const std::vector<TracerSpec> mixed = parse_tracer_list("cuda:0,embree");
  ASSERT_EQ(mixed.size(), 2u);
  EXPECT_EQ(mixed[1].kind, "embree");
  EXPECT_EQ(mixed[1].threads, embree_threads_beside_gpus(std::thread::hardware_concurrency()));
  EXPECT_EQ(mixed[0].threads, 0);
}

TEST(TracerRegistry, AutoAuxRaysTakesFirstHitsWhereCudaRendersWithoutOpenClOrNodes) {
  EXPECT_EQ(auto_aux_rays(parse_tracer_list("cuda:0")), "first-hit");
  EXPECT_EQ(auto_aux_rays(parse_tracer_list("cuda:0,cuda:1,embree")), "first-hit");
  EXPECT_EQ(auto_aux_rays(parse_tracer_list("embree")), "centre") << "Embree's centre packets cost about as much";
  EXPECT_EQ(auto_aux_rays(parse_tracer_list("cuda:0,opencl:2")), "centre") << "OpenCL reads first hits after its band";
  EXPECT_EQ(auto_aux_rays(parse_tracer_list("embree,cuda:0,mpi:1")), "centre") << "a node's tracers are unknown here";
}
