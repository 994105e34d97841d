#include "FuzzStudioTargets.h"

#include <Eigen/Geometry>

#include "FuzzScratch.h"
#include "IO/Project/LandmarkFile.h"
#include "Widgets/StudioDocument.h"
#include "Widgets/StudioSession.h"

namespace fct::fuzz {
namespace fs = std::filesystem;

int fuzzSessionFile(const std::uint8_t* data, std::size_t size) {
  StudioDocument document;
  const Status opened = StudioSession::open(document, FuzzScratch::write("fuzz.fctsession.json", data, size));
  FuzzScratch::require(opened.ok() || !opened.error().empty(), "StudioSession::open failed without a message");
  return 0;
}

const std::vector<FuzzTarget>& studioTargets() {
  static const std::vector<FuzzTarget> targets{{"session", fuzzSessionFile}};
  return targets;
}

Status writeStudioSeeds(const fs::path& root) {
  const fs::path scratch = FuzzScratch::folder();
  StudioDocument document;
  if (Status loaded = document.loadCt(scratch / FuzzScratch::kCtFile); !loaded) return loaded;
  if (Status loaded = document.loadViews(scratch / FuzzScratch::kViewFile); !loaded) return loaded;
  auto ct = LandmarkFile::readCt(scratch / FuzzScratch::kCtLandmarkFile);
  auto image = LandmarkFile::readImage(scratch / FuzzScratch::kImageLandmarkFile);
  if (!ct) return fail(ct.error());
  if (!image) return fail(image.error());
  document.setLandmarks(Landmarks{ct.value(), image.value()});
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();
  T_world_from_ct.translation() = Eigen::Vector3d(1.0, -2.0, 0.5);
  document.setInitialPose(T_world_from_ct, "fuzz seed");
  const fs::path session = scratch / "seed.fctsession.json";  // beside the fixtures, so its paths are relative
  if (Status saved = StudioSession::save(document, session); !saved) return saved;
  std::error_code ec;
  fs::create_directories(root / "session", ec);
  fs::copy_file(session, root / "session" / "fixture.fctsession.json", fs::copy_options::overwrite_existing, ec);
  if (ec) return fail("cannot copy the session seed into " + (root / "session").string() + ": " + ec.message());
  return Ok{};
}

}  // namespace fct::fuzz
