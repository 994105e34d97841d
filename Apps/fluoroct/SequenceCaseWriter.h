#pragma once
// SequenceCaseWriter: `fluoroct simulate --frames N`: a simulated fluoroscopy sequence of the bone moving
// (BoneMotion about the bone centre, from the true pose) rendered by the physical simulator and written as a case
// `fluoroct track` reads: DIR/<view>_<frame>.tif (32-bit float frames), DIR/views.json (each view's "sequence"),
// DIR/truth_pose.json (frame 0's pose) and DIR/truth_track.json (every frame's true pose, as track.json lists them).

#include <Eigen/Geometry>

#include <filesystem>
#include <vector>

#include "Base/Result.h"
#include "IO/Project/ViewFile.h"
#include "Image/Volume.h"
#include "Simulation/BoneMotion.h"
#include "Simulation/FluoroscopySimulator.h"

namespace fct::cli {

/// What was written.
struct SequenceCase {
  std::filesystem::path viewFile;   ///< DIR/views.json
  std::filesystem::path truthFile;  ///< DIR/truth_track.json
  int frames = 0;
};

/// Writes simulated sequences.
class SequenceCaseWriter {
 public:
  /// Renders `motion`'s frames of `ct` in every view from T_world_from_ct (frame 0 is the pose moved by the motion's
  /// frame-0 parameters) with the physical `options` (view n of frame k: noise seed options.seed + k * views + n) and
  /// writes the case into `folder`. Tools (K-wires, screws, plate) stay fixed in the world when `toolsFixed`, else
  /// move with the bone. Fails on no bone in the CT, a simulation error, or an unwritable folder.
  static Result<SequenceCase> write(const Volume& ct, const std::vector<ViewSpec>& views,
                                    const Eigen::Isometry3d& T_world_from_ct, const BoneMotion& motion,
                                    const FluoroscopyOptions& options, bool toolsFixed,
                                    const std::filesystem::path& folder);
};

}  // namespace fct::cli
