// The devices the tracers can take, as the registry lists them (`cohort devices`), and the decisions it
// makes from them, over plain data: which requested tracers would share one GPU (CUDA and OpenCL number
// their devices independently, so `cuda:0` and `opencl:1` may be one H100), and which GPUs "all" takes.
#pragma once

#include <string>
#include <vector>

#include "cohort/tracers/device_identity.h"

namespace cohort::tracers {

struct TracerDevice {
  std::string tracer;  // as --tracers names it: "embree", "cuda:0", "opencl:2"
  std::string name;    // what the driver calls it
  DeviceKind kind = DeviceKind::other;
  PciBusId pci;        // unknown for the CPU and where the driver does not say (PoCL)
};

// Every device of every tracer kind this build has, probed: Embree's CPU, each CUDA device, each OpenCL
// device (opencl:N is the N-th OpenCL device of all platforms, whatever it is). Never throws.
std::vector<TracerDevice> list_tracer_devices();

// Two requested tracers that would render on one GPU, slowing each other down.
struct SharedGpu {
  std::string first, second;  // tracer names, in the order requested
  std::string pci;            // the bus id they share ("" when the same tracer is named twice)
};

// Every pair of `requested` on one device: the same tracer named twice, or two whose PCI bus ids are
// known and equal (same_pci_device: an unknown id, PoCL's, never matches). Embree (the CPU) is left out.
std::vector<SharedGpu> tracers_sharing_a_gpu(const std::vector<TracerDevice>& requested);
// The warning for one pair, naming both tracers and the bus id.
std::string shared_gpu_warning(const SharedGpu& shared);

// The GPU tracers "all" takes, each GPU once: every CUDA device, then every OpenCL device that is not a
// CPU (Embree has the CPU) and is not a GPU taken before. Where CUDA devices exist, an OpenCL device whose
// bus id is unknown is left out (it may be one of them); without CUDA it is taken unless its id matches.
std::vector<std::string> gpu_tracers_for_all(const std::vector<TracerDevice>& devices);

}  // namespace cohort::tracers
