#pragma once
// The initial pose of the commands that register (register, track): from --init (a pose file or ITK transform) or
// estimated from --landmarks (a landmark pair file) with the views' cameras.

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "Base/Result.h"
#include "Registration/RegistrationView.h"

namespace fct::cli {

/// The initial pose and, for the result files, where it came from.
struct InitialPose {
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();
  nlohmann::ordered_json source;  ///< {"source": "pose file" | "landmarks", "path", and a landmark fit's residuals}
};

/// Fails naming the flags unless exactly one of `init` and `landmarks` is given.
Status checkInitialPoseFlags(const std::string& init, const std::string& landmarks);

/// The initial pose from the --init file `init`, or else estimated from the --landmarks file `landmarks` with the
/// views' cameras (warnings go to stderr). Fails naming the flag.
Result<InitialPose> readInitialPose(const std::string& init, const std::string& landmarks,
                                    const std::vector<RegistrationView>& views);

}  // namespace fct::cli
