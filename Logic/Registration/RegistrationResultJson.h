#pragma once
// RegistrationResultJson: a RegistrationResult as JSON, the one reader and writer of the result object shared by the
// CLI's RESULT.json and the Studio's session file (docs/file-formats.md "RESULT.json"). Each writer adds its own keys
// around it (the CLI: how the initial pose was found, the Transgraph tables, the run's options; the Studio: the
// user's verdict); the reader ignores keys it does not know.
//
// The object, version 2:
//   {format: "fluoroct-registration-result", version: 2, T_world_from_ct, cancelled,
//    initial_pose: {T_world_from_ct}, rotation_centre_ct_mm, view_names, stages: [...], total_seconds, total_drrs,
//    view_renderer_setup_seconds, options: {method, schedule}}
// An object without `format` is version 1, in either of its two spellings: the CLI's (initial_pose.T_world_from_ct,
// options.method, options.schedule, no view_names) or the session's (T_initial, drr_method, schedule, view_names).

#include <nlohmann/json.hpp>

#include <string>

#include "Base/Result.h"
#include "Registration/Registration.h"

namespace fct {

/// Reads and writes the JSON object of a registration result.
class RegistrationResultJson {
 public:
  /// Value of the object's `format` key.
  static constexpr const char* kFormat = "fluoroct-registration-result";
  /// The version written; versions 1 to kVersion are read.
  static constexpr int kVersion = 2;

  /// The result as a version-2 object. Stage i's kept fractions are keyed by view_names (fractions without a view
  /// name are left out); metrics and searches by their schedule names ("vlnc", "genetic"); poses are 4x4 row-major,
  /// LPS mm.
  static nlohmann::ordered_json write(const RegistrationResult& result);

  /// Reads a result object of version 1 or 2; `where` names it in messages ("RESULT.json", "x.json: result").
  /// Fails naming the key on a missing key, a wrong type, NaN, a pose that is not rigid, an unknown stage metric or
  /// search, an invalid schedule, or a format or version this program does not read. A version-1 object without
  /// view_names takes them from the first stage's kept_fraction keys (in alphabetical order).
  static Result<RegistrationResult> read(const nlohmann::json& object, const std::string& where);
};

}  // namespace fct
