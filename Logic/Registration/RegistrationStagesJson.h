#pragma once
// RegistrationStagesJson: the per-stage report of a registration as JSON, one writer shared by the CLI's RESULT.json
// and the studio's session file (README "Registration": the `stages` keys).

#include <nlohmann/json.hpp>

#include "Registration/Registration.h"

namespace fct {

/// JSON of a registration's stage reports.
class RegistrationStagesJson {
 public:
  /// Every stage of `result`, in order: {name, metric, level, search, seconds, drrs, fallback_rays, evaluations,
  /// start_similarity, similarity, kept_fraction: {<view name>: fraction}, cancelled}. Kept fractions without a
  /// view name (more fractions than names) are left out.
  static nlohmann::ordered_json write(const RegistrationResult& result);
};

}  // namespace fct
