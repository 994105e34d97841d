#include "Simulation/Physics/HuMaterialModel.h"

#include <fmt/core.h>

#include <cmath>

namespace fct {

Status HuMaterialModel::validate() const {
  const bool finite = std::isfinite(airBelow_hu) && std::isfinite(boneFrom_hu) && std::isfinite(corticalBone_hu) &&
                      std::isfinite(metalFrom_hu);
  if (!finite || !(airBelow_hu < boneFrom_hu && boneFrom_hu < corticalBone_hu && corticalBone_hu < metalFrom_hu) ||
      boneFrom_hu <= -1000.0) {
    return fail(fmt::format("HU material thresholds must increase: air < {} < bone from {} < cortical {} < metal {} "
                            "(and bone above -1000 HU)",
                            airBelow_hu, boneFrom_hu, corticalBone_hu, metalFrom_hu));
  }
  return Ok{};
}

}  // namespace fct
