// `cohort devices`: every device a tracer can take, with its kind and PCI bus id, so that users pick
// `opencl:N` knowingly (CUDA and OpenCL number the same GPUs independently; PoCL's CPU is an OpenCL
// device too), and the tracers `all` takes.
#include <cstdio>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>

#include "cohort/tracers/device_listing.h"
#include "cohort/tracers/tracer_registry.h"
#include "commands.h"

namespace cohort::app {

namespace {

int run_devices(bool json) {
  const std::vector<tracers::TracerDevice> devices = tracers::list_tracer_devices();
  // Which other tracers drive the same GPU, for each listed device.
  std::map<std::string, std::vector<std::string>> same;
  for (const tracers::SharedGpu& s : tracers::tracers_sharing_a_gpu(devices)) {
    same[s.first].push_back(s.second);
    same[s.second].push_back(s.first);
  }
  std::string all;
  try {
    for (const tracers::TracerSpec& spec : tracers::parse_tracer_list("all")) all += (all.empty() ? "" : ",") + spec.text;
  } catch (const std::exception& e) {
    all = std::string("(none: ") + e.what() + ")";
  }
  if (json) {
    nlohmann::json out = nlohmann::json::array();
    for (const tracers::TracerDevice& d : devices)
      out.push_back({{"tracer", d.tracer},
                     {"name", d.name},
                     {"kind", tracers::device_kind_name(d.kind)},
                     {"pci_bus_id", d.pci.text()},
                     {"same_gpu_as", same[d.tracer]}});
    std::cout << nlohmann::json{{"devices", out}, {"all", all}}.dump(1) << "\n";
    return kExitOk;
  }
  std::printf("%-10s %-5s %-13s %s\n", "tracer", "kind", "PCI bus id", "device");
  for (const tracers::TracerDevice& d : devices) {
    std::string also;
    for (const std::string& other : same[d.tracer]) also += (also.empty() ? "  (the same GPU as " : ", ") + other;
    if (!also.empty()) also += ")";
    const std::string pci = d.pci.known ? d.pci.text() : "-";
    std::printf("%-10s %-5s %-13s %s%s\n", d.tracer.c_str(), tracers::device_kind_name(d.kind), pci.c_str(),
                d.name.c_str(), also.c_str());
  }
  std::printf("all        %s\n", all.c_str());
  return kExitOk;
}

}  // namespace

void add_devices_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("devices", "List the devices the tracers can take (embree, cuda:N, opencl:N) with "
                                            "their kind (CPU/GPU) and PCI bus id, which of them are one GPU, and what "
                                            "--tracers all takes");
  auto json = std::make_shared<bool>(false);
  cmd->add_flag("--json", *json, "print the list as JSON (tracer, name, kind, pci_bus_id, same_gpu_as; and all)");
  cmd->callback([json, &exit_code] { exit_code = run_devices(*json); });
}

}  // namespace cohort::app
