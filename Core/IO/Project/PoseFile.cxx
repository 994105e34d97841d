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
  const std::optional<Eigen::Isometry3d> T_world_from_ct = readKey(reader, "T_world_from_ct");
  if (!T_world_from_ct) return fail(reader.error());
  Result<Eigen::Isometry3d> pose(*T_world_from_ct);
  for (std::string& warning : reader.unknownKeys({"T_world_from_ct"})) pose.addWarning(std::move(warning));
  return pose;
}

std::optional<Eigen::Isometry3d> PoseFile::readKey(JsonReader& reader, std::string_view key) {
  const Eigen::Matrix4d matrix = reader.matrix(key, 4, 4);
  if (!reader.ok()) return std::nullopt;
  auto pose = RigidPose::validated(matrix, std::string(key).c_str());
  if (!pose) {
    reader.reject(pose.error());
    return std::nullopt;
  }
  return pose.value();
}

Status PoseFile::write(const Eigen::Isometry3d& T_world_from_ct, const std::filesystem::path& path) {
  const Eigen::Matrix4d& M = T_world_from_ct.matrix();
  if (auto valid = RigidPose::validated(M, "T_world_from_ct"); !valid) {
    return fail(fmt::format("cannot write '{}': {}", path.string(), valid.error()));
  }
  return JsonDocument::write(nlohmann::ordered_json{{"T_world_from_ct", JsonDocument::array(M)}}, path);
}

}  // namespace fct
