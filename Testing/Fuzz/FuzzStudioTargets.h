#pragma once
// The fuzz entry point of the Studio's session file (Widgets layer, so in a library of its own) and its seeds.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "Base/Result.h"
#include "FuzzTargets.h"

namespace fct::fuzz {

/// A session file (StudioSession::open into a fresh StudioDocument) beside the fixture CT, views and landmarks.
int fuzzSessionFile(const std::uint8_t* data, std::size_t size);
/// The Studio's targets ("session").
const std::vector<FuzzTarget>& studioTargets();
/// Writes a session of the fixture case (CT, views, landmarks, initial pose) into root/session/. Fails naming why.
Status writeStudioSeeds(const std::filesystem::path& root);

}  // namespace fct::fuzz
