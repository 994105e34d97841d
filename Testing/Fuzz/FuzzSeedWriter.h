#pragma once
// FuzzSeedWriter: the seed inputs that the project's own writers make (a small CT in every volume format, DICOM CT and
// X-ray files made with DCMTK, images, view, pose, landmark, preset, transform, Transgraph cache and dewarp files),
// one folder per fuzz target.
// scripts/fuzz.sh adds the seeds made from ../shared/data and by the fluoroct CLI.

#include <filesystem>

#include "Base/Result.h"

namespace fct::fuzz {

/// Writes the seeds of loaderTargets() into root/<target>/ (folders created). Fails naming the file not written.
Status writeLoaderSeeds(const std::filesystem::path& root);

}  // namespace fct::fuzz
