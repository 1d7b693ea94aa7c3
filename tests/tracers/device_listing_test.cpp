// Which requested tracers share a GPU and which GPUs "all" takes, from device listings written out as the
// drivers report them (the nvidia-h100-x2 machine: PoCL first, then NVIDIA's OpenCL numbering the same two
// GPUs as CUDA), and the listing of this machine's own devices.
#include <gtest/gtest.h>

#include <algorithm>

#include "cohort/tracers/device_listing.h"
#include "cohort/tracers/tracer_registry.h"

using namespace cohort::tracers;

namespace {

const PciBusId kFirstGpu = PciBusId::of(0, 0x19, 0);
const PciBusId kSecondGpu = PciBusId::of(0, 0x3b, 0);

TracerDevice device(const std::string& tracer, DeviceKind kind, PciBusId pci = {}) { return {tracer, tracer, kind, pci}; }

// Two H100s: cuda:0/1, PoCL as opencl:0, NVIDIA's OpenCL as opencl:1 (the first GPU) and opencl:2.
std::vector<TracerDevice> two_gpu_machine() {
  return {device("embree", DeviceKind::cpu),          device("cuda:0", DeviceKind::gpu, kFirstGpu),
          device("cuda:1", DeviceKind::gpu, kSecondGpu), device("opencl:0", DeviceKind::cpu),
          device("opencl:1", DeviceKind::gpu, kFirstGpu), device("opencl:2", DeviceKind::gpu, kSecondGpu)};
}

std::vector<TracerDevice> pick(const std::vector<TracerDevice>& all, const std::vector<std::string>& names) {
  std::vector<TracerDevice> out;
  for (const std::string& n : names)
    out.push_back(*std::find_if(all.begin(), all.end(), [&](const TracerDevice& d) { return d.tracer == n; }));
  return out;
}

}  // namespace

TEST(PciBusId, FormatsAndMatchesLikeLspci) {
  EXPECT_EQ(PciBusId::of(0, 0x19, 0).text(), "0000:19:00.0");
  EXPECT_EQ(PciBusId::of(1, 0xab, 0x1f, 3).text(), "0001:ab:1f.3");
  EXPECT_EQ(PciBusId::without_domain(0x3b, 2).text(), "????:3b:02.0");
  EXPECT_EQ(PciBusId{}.text(), "");
  EXPECT_TRUE(same_pci_device(PciBusId::of(0, 0x19, 0), PciBusId::of(0, 0x19, 0, 1))) << "the function is ignored";
  EXPECT_FALSE(same_pci_device(PciBusId::of(0, 0x19, 0), PciBusId::of(1, 0x19, 0))) << "another domain";
  EXPECT_FALSE(same_pci_device(PciBusId::of(0, 0x19, 0), PciBusId::of(0, 0x19, 1))) << "another device";
  EXPECT_TRUE(same_pci_device(PciBusId::without_domain(0x19, 0), PciBusId::of(2, 0x19, 0)))
      << "an unknown domain (older NVIDIA OpenCL) matches on bus and device";
  EXPECT_FALSE(same_pci_device(PciBusId{}, PciBusId{})) << "unknown (PoCL) never equals, even itself";
  EXPECT_FALSE(same_pci_device(PciBusId{}, kFirstGpu));
}

TEST(SharedGpus, CudaAndTheOpenCLDeviceOfTheSameGpuAreNamed) {
  const std::vector<TracerDevice> all = two_gpu_machine();
  const std::vector<SharedGpu> shared = tracers_sharing_a_gpu(pick(all, {"embree", "cuda:0", "opencl:1"}));
  ASSERT_EQ(shared.size(), 1u);
  EXPECT_EQ(shared[0].first, "cuda:0");
  EXPECT_EQ(shared[0].second, "opencl:1");
  EXPECT_EQ(shared[0].pci, "0000:19:00.0");
  const std::string warning = shared_gpu_warning(shared[0]);
  for (const char* word : {"cuda:0", "opencl:1", "0000:19:00.0"}) EXPECT_NE(warning.find(word), std::string::npos) << warning;
}

TEST(SharedGpus, TwoGpusPoclAndUnknownIdsAreNotShared) {
  const std::vector<TracerDevice> all = two_gpu_machine();
  EXPECT_TRUE(tracers_sharing_a_gpu(pick(all, {"cuda:0", "opencl:2"})).empty());
  EXPECT_TRUE(tracers_sharing_a_gpu(pick(all, {"embree", "cuda:0", "cuda:1", "opencl:0"})).empty())
      << "PoCL's CPU device has no bus id: unknown, never the same as a GPU";
  EXPECT_TRUE(tracers_sharing_a_gpu({device("opencl:0", DeviceKind::gpu), device("opencl:1", DeviceKind::gpu)}).empty())
      << "two devices without ids may be two GPUs";
}

TEST(SharedGpus, TheSameTracerNamedTwiceIsShared) {
  const std::vector<SharedGpu> shared = tracers_sharing_a_gpu({device("opencl:0", DeviceKind::cpu), device("opencl:0", DeviceKind::cpu)});
  ASSERT_EQ(shared.size(), 1u);
  EXPECT_NE(shared_gpu_warning(shared[0]).find("opencl:0"), std::string::npos);
}

TEST(AllTracers, TakeEachGpuOnceAndNeverTheCpuThroughOpenCL) {
  EXPECT_EQ(gpu_tracers_for_all(two_gpu_machine()), (std::vector<std::string>{"cuda:0", "cuda:1"}))
      << "NVIDIA's OpenCL devices are CUDA's GPUs again; PoCL is the CPU Embree has";
  // One NVIDIA GPU under CUDA and another vendor's GPU only OpenCL drives: both.
  std::vector<TracerDevice> mixed = {device("cuda:0", DeviceKind::gpu, kFirstGpu), device("opencl:0", DeviceKind::gpu, kFirstGpu),
                                     device("opencl:1", DeviceKind::gpu, kSecondGpu), device("opencl:2", DeviceKind::cpu)};
  EXPECT_EQ(gpu_tracers_for_all(mixed), (std::vector<std::string>{"cuda:0", "opencl:1"}));
  // Beside CUDA, an OpenCL GPU that does not say where it is may be one of CUDA's: left out.
  mixed.push_back(device("opencl:3", DeviceKind::gpu));
  EXPECT_EQ(gpu_tracers_for_all(mixed), (std::vector<std::string>{"cuda:0", "opencl:1"}));
}

TEST(AllTracers, WithoutCudaEachOpenCLGpuOnce) {
  // Two platforms showing one GPU (known id), and a GPU that gives no id.
  const std::vector<TracerDevice> devices = {device("opencl:0", DeviceKind::cpu), device("opencl:1", DeviceKind::gpu, kFirstGpu),
                                             device("opencl:2", DeviceKind::gpu, kFirstGpu), device("opencl:3", DeviceKind::gpu),
                                             device("opencl:4", DeviceKind::other, kSecondGpu)};
  EXPECT_EQ(gpu_tracers_for_all(devices), (std::vector<std::string>{"opencl:1", "opencl:3", "opencl:4"}));
  EXPECT_TRUE(gpu_tracers_for_all({device("embree", DeviceKind::cpu), device("opencl:0", DeviceKind::cpu)}).empty());
}

// This machine's own devices: every tracer kind the build has is listed, the CPU ones without a bus id,
// and "all" never names two tracers on one GPU.
TEST(AllTracers, ThisMachinesListingAndAllAgree) {
  const std::vector<TracerDevice> devices = list_tracer_devices();
  for (const TracerDevice& d : devices) {
    EXPECT_FALSE(d.name.empty()) << d.tracer;
    if (d.kind == DeviceKind::cpu) {
      EXPECT_FALSE(d.pci.known) << d.tracer << " is a CPU device with a PCI bus id";
    }
  }
  for (const std::string& kind : built_tracer_kinds()) {
    const int listed = int(std::count_if(devices.begin(), devices.end(), [&](const TracerDevice& d) {
      return d.tracer == kind || d.tracer.rfind(kind + ":", 0) == 0;
    }));
    EXPECT_EQ(listed, device_count(kind)) << kind;
  }
  std::vector<TracerDevice> chosen;
  for (const TracerSpec& spec : parse_tracer_list("all")) {
    const std::string name = spec.kind == "embree" ? "embree" : spec.kind + ":" + std::to_string(spec.device);
    auto found = std::find_if(devices.begin(), devices.end(), [&](const TracerDevice& d) { return d.tracer == name; });
    ASSERT_NE(found, devices.end()) << name << " is not listed";
    chosen.push_back(*found);
  }
  EXPECT_TRUE(tracers_sharing_a_gpu(chosen).empty());
}
