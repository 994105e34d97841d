#include "SequenceCaseWriter.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <system_error>

#include "Base/JsonDocument.h"
#include "IO/Project/PoseFile.h"
#include "IO/Xray/ImageFileWriter.h"
#include "Image/BoneSurface.h"

namespace fct::cli {

Result<SequenceCase> SequenceCaseWriter::write(const Volume& ct, const std::vector<ViewSpec>& views,
                                               const Eigen::Isometry3d& T_world_from_ct, const BoneMotion& motion,
                                               const FluoroscopyOptions& options, bool toolsFixed,
                                               const std::filesystem::path& folder) {
  auto bone = BoneSurface::extract(ct);
  if (!bone) return fail("the sequence moves the bone about its centre, but " + bone.error());
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) return fail(fmt::format("cannot create the output folder '{}': {}", folder.string(), ec.message()));
  const std::vector<Eigen::Isometry3d> poses = motion.poses(T_world_from_ct, bone.value().centroid_ct_mm());
  std::vector<Camera> cameras;
  std::vector<ViewSpec> specs = views;
  for (ViewSpec& spec : specs) {
    cameras.push_back(spec.camera);
    spec.sequence = ViewSequence{};
    spec.frame = 0;
  }
  const Status rendered = FluoroscopySimulator::renderSequence(
      ct, cameras, poses, options, options.seed, toolsFixed, [&](int frame, std::vector<FloatImage> images) -> Status {
        for (std::size_t v = 0; v < images.size(); ++v) {
          const std::filesystem::path path = folder / fmt::format("{}_{:03}.tif", specs[v].name, frame);
          if (Status written = ImageFileWriter::writeTiff(images[v], path); !written) return written;
          specs[v].sequence->files.push_back(path);
        }
        fmt::print("frame {:3}/{}: wrote {} views\n", frame, poses.size() - 1, images.size());
        return Ok{};
      });
  if (!rendered) return fail(rendered.error());
  for (ViewSpec& spec : specs) spec.imagePath = spec.sequence->files.front();

  SequenceCase written;
  written.frames = static_cast<int>(poses.size());
  written.viewFile = folder / "views.json";
  written.truthFile = folder / "truth_track.json";
  if (Status status = ViewFile::write(specs, written.viewFile); !status) return fail(status.error());
  if (Status status = PoseFile::write(poses.front(), folder / "truth_pose.json"); !status) return fail(status.error());
  nlohmann::ordered_json frames = nlohmann::ordered_json::array();
  for (std::size_t k = 0; k < poses.size(); ++k) {
    frames.push_back({{"index", k}, {"T_world_from_ct", JsonDocument::array(poses[k].matrix())}});
  }
  const nlohmann::ordered_json truth{{"frames", std::move(frames)},
                                     {"rotation_centre_ct_mm", JsonDocument::array(bone.value().centroid_ct_mm())},
                                     {"max_translation_mm", motion.options().maxTranslation_mm},
                                     {"max_rotation_deg", motion.options().maxRotation_deg},
                                     {"jerk_frame", motion.options().jerkFrame},
                                     {"motion_seed", motion.options().seed}};
  if (Status status = JsonDocument::write(truth, written.truthFile); !status) return fail(status.error());
  return written;
}

}  // namespace fct::cli
