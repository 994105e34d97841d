// The libFuzzer program of the fuzz entry points: FCT_FUZZ_TARGET names the one to fuzz (scripts/fuzz.sh sets it).
// fluoroct_fuzz has the loaders' targets, fluoroct_fuzz_studio (FCT_FUZZ_STUDIO) the Studio's session target too.

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "FuzzTargets.h"
#ifdef FCT_FUZZ_STUDIO
#include "FuzzStudioTargets.h"
#endif

namespace {

int (*g_run)(const std::uint8_t*, std::size_t) = nullptr;

std::vector<fct::fuzz::FuzzTarget> programTargets() {
  std::vector<fct::fuzz::FuzzTarget> targets = fct::fuzz::loaderTargets();
#ifdef FCT_FUZZ_STUDIO
  const auto& studio = fct::fuzz::studioTargets();
  targets.insert(targets.end(), studio.begin(), studio.end());
#endif
  return targets;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* wanted = std::getenv("FCT_FUZZ_TARGET");
  std::string names;
  for (const fct::fuzz::FuzzTarget& target : programTargets()) {
    if (wanted && target.name == std::string(wanted)) g_run = target.run;
    names += std::string(" ") + target.name;
  }
  if (!g_run) {
    std::fprintf(stderr, "fuzz: set FCT_FUZZ_TARGET to one of:%s\n", names.c_str());
    std::exit(2);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { return g_run(data, size); }
