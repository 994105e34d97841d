// fluoroct_fuzz_seeds DIR: writes the seed inputs that the project's own writers make into DIR/<target>/ (for
// scripts/fuzz.sh, which adds the seeds made from the shared data and by the fluoroct CLI).

#include <cstdio>

#include "FuzzSeedWriter.h"
#include "FuzzStudioTargets.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fluoroct_fuzz_seeds DIR\n");
    return 2;
  }
  for (fct::Status (*write)(const std::filesystem::path&) : {fct::fuzz::writeLoaderSeeds, fct::fuzz::writeStudioSeeds}) {
    if (const fct::Status written = write(argv[1]); !written) {
      std::fprintf(stderr, "error: %s\n", written.error().c_str());
      return 1;
    }
  }
  return 0;
}
