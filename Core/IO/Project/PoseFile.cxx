#include "IO/Project/PoseFile.h"

#include <fmt/core.h>

#include "Base/JsonDocument.h"
#include "Base/JsonReader.h"
#include "Geometry/RigidPose.h"

namespace fct {

Result<Eigen::Isometry3d> PoseFile::read(const std::filesystem::path& path) {
  auto document = JsonDocument::parse(path);
  if (!document) return fail(document.error());
  JsonReader reader(document.value(), path.string());
  const Eigen::Matrix4d matrix = reader.matrix("T_world_from_ct", 4, 4);
  if (!reader.ok()) return fail(reader.error());
  auto pose = RigidPose::validated(matrix, "T_world_from_ct");
  if (!pose) return fail(fmt::format("{}: {}", path.string(), pose.error()));
  for (std::string& warning : reader.unknownKeys({"T_world_from_ct"})) pose.addWarning(std::move(warning));
  return pose;
}

Status PoseFile::write(const Eigen::Isometry3d& T_world_from_ct, const std::filesystem::path& path) {
  const Eigen::Matrix4d& M = T_world_from_ct.matrix();
  if (auto valid = RigidPose::validated(M, "T_world_from_ct"); !valid) {
    return fail(fmt::format("cannot write '{}': {}", path.string(), valid.error()));
  }
  return JsonDocument::write(nlohmann::ordered_json{{"T_world_from_ct", JsonDocument::array(M)}}, path);
}

}  // namespace fct
