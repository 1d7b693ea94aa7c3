#include "cohort/tracers/device_listing.h"

#include <algorithm>
#include <thread>

#ifdef COHORT_HAVE_OPENCL
#include "cohort/tracers/opencl_tracer.h"
#endif
#ifdef COHORT_HAVE_CUDA
#include "cohort/tracers/cuda_tracer.h"
#endif

namespace cohort::tracers {

namespace {

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

std::vector<TracerDevice> list_tracer_devices() {
  std::vector<TracerDevice> out;
#ifdef COHORT_HAVE_EMBREE
  out.push_back({"embree", std::to_string(std::max(1u, std::thread::hardware_concurrency())) + " hardware threads",
                 DeviceKind::cpu, {}});
#endif
#ifdef COHORT_HAVE_CUDA
  for (int d = 0, n = cuda_device_count(); d < n; ++d)
    out.push_back({"cuda:" + std::to_string(d), cuda_device_name(d), DeviceKind::gpu, cuda_device_pci_bus_id(d)});
#endif
#ifdef COHORT_HAVE_OPENCL
  const std::vector<OpenCLTracer::DeviceDescription> opencl = OpenCLTracer::describe_devices();
  for (size_t d = 0; d < opencl.size(); ++d)
    out.push_back({"opencl:" + std::to_string(d), opencl[d].label, opencl[d].kind, opencl[d].pci});
#endif
  return out;
}

std::vector<SharedGpu> tracers_sharing_a_gpu(const std::vector<TracerDevice>& requested) {
  std::vector<SharedGpu> shared;
  for (size_t i = 0; i < requested.size(); ++i)
    for (size_t j = i + 1; j < requested.size(); ++j) {
      const TracerDevice &a = requested[i], &b = requested[j];
      if (a.tracer == "embree" || b.tracer == "embree") continue;
      if (a.tracer == b.tracer)
        shared.push_back({a.tracer, b.tracer, a.pci.text()});
      else if (same_pci_device(a.pci, b.pci))
        shared.push_back({a.tracer, b.tracer, a.pci.domain_known ? a.pci.text() : b.pci.text()});
    }
  return shared;
}

std::string shared_gpu_warning(const SharedGpu& shared) {
  if (shared.first == shared.second)
    return "tracer " + shared.first + " is named twice: both render on one device and slow each other down";
  return "tracers " + shared.first + " and " + shared.second + " are the same GPU (PCI " + shared.pci +
         "): two tracers on one GPU slow each other down; `cohort devices` lists which OpenCL device is which GPU";
}

std::vector<std::string> gpu_tracers_for_all(const std::vector<TracerDevice>& devices) {
  std::vector<std::string> taken;
  std::vector<PciBusId> taken_pci;
  const bool any_cuda =
      std::any_of(devices.begin(), devices.end(), [](const TracerDevice& d) { return starts_with(d.tracer, "cuda:"); });
  auto already = [&](const PciBusId& pci) {
    return std::any_of(taken_pci.begin(), taken_pci.end(), [&](const PciBusId& t) { return same_pci_device(t, pci); });
  };
  for (const TracerDevice& d : devices)
    if (starts_with(d.tracer, "cuda:") && !already(d.pci)) {
      taken.push_back(d.tracer);
      taken_pci.push_back(d.pci);
    }
  for (const TracerDevice& d : devices) {
    if (!starts_with(d.tracer, "opencl:") || d.kind == DeviceKind::cpu) continue;
    if (already(d.pci) || (any_cuda && !d.pci.known)) continue;
    taken.push_back(d.tracer);
    taken_pci.push_back(d.pci);
  }
  return taken;
}

}  // namespace cohort::tracers
