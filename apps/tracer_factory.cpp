#include "tracer_factory.h"

#include <stdexcept>

#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_tracer.h"
#endif
#ifdef COHORT_HAVE_OPENCL
#include "cohort/tracers/opencl_tracer.h"
#endif

namespace cohort::app {

std::vector<TracerSpec> parse_tracer_list(const std::string& list) {
  std::vector<TracerSpec> specs;
  size_t start = 0;
  while (start <= list.size()) {
    size_t comma = list.find(',', start);
    std::string item = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    start = comma == std::string::npos ? list.size() + 1 : comma + 1;
    if (item.empty()) continue;
    TracerSpec spec;
    spec.text = item;
    size_t colon = item.find(':');
    spec.kind = item.substr(0, colon);
    if (colon != std::string::npos) {
      std::string index = item.substr(colon + 1);
      if (index.empty() || index.find_first_not_of("0123456789") != std::string::npos)
        throw std::invalid_argument("tracer '" + item + "': the device after ':' must be a number");
      spec.device = std::stoi(index);
    }
    if (spec.kind != "embree" && spec.kind != "opencl" && spec.kind != "cuda")
      throw std::invalid_argument("unknown tracer '" + item + "' (known: embree, opencl[:N], cuda[:N])");
    if (spec.kind == "embree" && colon != std::string::npos)
      throw std::invalid_argument("tracer '" + item + "': the Embree tracer takes no device index");
    specs.push_back(spec);
  }
  if (specs.empty()) throw std::invalid_argument("no tracers named in '" + list + "'");
  return specs;
}

std::unique_ptr<core::Tracer> make_tracer(const TracerSpec& spec) {
#ifdef COHORT_HAVE_EMBREE
  if (spec.kind == "embree") return std::make_unique<tracers::EmbreeTracer>();
#endif
#ifdef COHORT_HAVE_OPENCL
  if (spec.kind == "opencl") {
    tracers::OpenCLTracer::Options options;
    options.device = spec.device;
    return std::make_unique<tracers::OpenCLTracer>(options);
  }
#endif
  throw std::runtime_error("tracer '" + spec.text + "' is not built into this binary");
}

std::vector<std::unique_ptr<core::Tracer>> make_tracers(const std::string& list) {
  std::vector<std::unique_ptr<core::Tracer>> out;
  for (const TracerSpec& spec : parse_tracer_list(list)) out.push_back(make_tracer(spec));
  return out;
}

std::vector<std::string> built_tracer_kinds() {
  std::vector<std::string> kinds;
#ifdef COHORT_HAVE_EMBREE
  kinds.push_back("embree");
#endif
#ifdef COHORT_HAVE_OPENCL
  kinds.push_back("opencl");
#endif
#ifdef COHORT_HAVE_CUDA
  kinds.push_back("cuda");
#endif
  return kinds;
}

}  // namespace cohort::app
