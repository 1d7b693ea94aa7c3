// Which physical device a tracer renders on, as the drivers report it: its kind (CPU or GPU) and, for a
// PCI device, its bus id. CUDA and OpenCL number their devices independently (opencl:1 may be the GPU
// that is cuda:0), so the registry compares bus ids to tell two tracers on one GPU apart from two GPUs.
#pragma once

#include <string>

namespace cohort::tracers {

enum class DeviceKind { cpu, gpu, other };

// "CPU", "GPU" or "other" (an OpenCL accelerator or custom device).
const char* device_kind_name(DeviceKind kind);

// A PCI address, domain:bus:device.function. Drivers that do not say (PoCL, the CPU) leave it unknown;
// NVIDIA's older OpenCL drivers give bus and device but not the domain.
struct PciBusId {
  bool known = false;
  bool domain_known = false;
  unsigned domain = 0, bus = 0, device = 0, function = 0;

  static PciBusId of(unsigned domain, unsigned bus, unsigned device, unsigned function = 0);
  static PciBusId without_domain(unsigned bus, unsigned device, unsigned function = 0);
  // "0000:65:00.0" (as lspci -D writes it; "????:65:00.0" when the domain is unknown), "" when unknown.
  std::string text() const;
};

// Whether both ids are known and name one device: bus and device equal, and the domain too where both
// know it (the function is ignored: a GPU's other functions are its audio or USB parts). Unknown never
// equals anything, itself included.
bool same_pci_device(const PciBusId& a, const PciBusId& b);

}  // namespace cohort::tracers
