#include "cohort/tracers/device_identity.h"

#include <cstdio>

namespace cohort::tracers {

const char* device_kind_name(DeviceKind kind) {
  switch (kind) {
    case DeviceKind::cpu: return "CPU";
    case DeviceKind::gpu: return "GPU";
    case DeviceKind::other: break;
  }
  return "other";
}

PciBusId PciBusId::of(unsigned domain, unsigned bus, unsigned device, unsigned function) {
  PciBusId id = without_domain(bus, device, function);
  id.domain_known = true;
  id.domain = domain;
  return id;
}

PciBusId PciBusId::without_domain(unsigned bus, unsigned device, unsigned function) {
  PciBusId id;
  id.known = true;
  id.bus = bus;
  id.device = device;
  id.function = function;
  return id;
}

std::string PciBusId::text() const {
  if (!known) return "";
  char out[32];
  if (domain_known)
    std::snprintf(out, sizeof out, "%04x:%02x:%02x.%x", domain, bus, device, function);
  else
    std::snprintf(out, sizeof out, "????:%02x:%02x.%x", bus, device, function);
  return out;
}

bool same_pci_device(const PciBusId& a, const PciBusId& b) {
  if (!a.known || !b.known) return false;
  if (a.domain_known && b.domain_known && a.domain != b.domain) return false;
  return a.bus == b.bus && a.device == b.device;
}

}  // namespace cohort::tracers
