#include "IO/Project/ItkTransformFile.h"

#include <fmt/core.h>

#include <charconv>
#include <sstream>
#include <string>
#include <vector>

#include "Base/TextFile.h"
#include "Geometry/RigidPose.h"

namespace fct {

namespace {

constexpr const char* kHeader = "#Insight Transform File V1.0";

/// The linear ITK transform classes this reader understands (all y = A (x - c) + t + c).
bool isLinearType(const std::string& type) {
  return type == "AffineTransform_double_3_3" || type == "AffineTransform_float_3_3" ||
         type == "MatrixOffsetTransformBase_double_3_3" || type == "MatrixOffsetTransformBase_float_3_3";
}

/// Whitespace-separated numbers; fails naming the first token that is not a number.
Result<std::vector<double>> parseNumbers(const std::string& text) {
  std::istringstream tokens(text);
  std::vector<double> numbers;
  std::string token;
  while (tokens >> token) {
    double value = 0.0;
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (error != std::errc() || end != token.data() + token.size()) {
      return fail(fmt::format("'{}' is not a number", token));
    }
    numbers.push_back(value);
  }
  return numbers;
}

std::string trimmed(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return {};
  return text.substr(begin, text.find_last_not_of(" \t\r") - begin + 1);
}

}  // namespace

Status ItkTransformFile::write(const Eigen::Isometry3d& T_world_from_ct, const std::filesystem::path& path) {
  if (auto valid = RigidPose::validated(T_world_from_ct.matrix(), "T_world_from_ct"); !valid) {
    return fail(fmt::format("cannot write '{}': {}", path.string(), valid.error()));
  }
  const Eigen::Isometry3d T_ct_from_world = T_world_from_ct.inverse();
  const Eigen::Matrix3d& R = T_ct_from_world.linear();
  const Eigen::Vector3d& t = T_ct_from_world.translation();
  const std::string text = fmt::format(
      "{}\n#Transform 0\nTransform: AffineTransform_double_3_3\n"
      "Parameters: {} {} {} {} {} {} {} {} {} {} {} {}\nFixedParameters: 0 0 0\n",
      kHeader, R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2), t.x(), t.y(), t.z());
  return TextFile::writeAtomically(path, text);
}

Result<Eigen::Isometry3d> ItkTransformFile::read(const std::filesystem::path& path) {
  auto text = TextFile::read(path);
  if (!text) return fail(text.error());
  const std::string file = path.string();
  std::istringstream lines(text.value());
  std::string line;
  std::getline(lines, line);
  if (trimmed(line).rfind("#Insight Transform File", 0) != 0) {
    return fail(fmt::format("{}: not an ITK transform file (the first line must be \"{}\")", file, kHeader));
  }
  std::vector<std::string> types;
  std::string parameters, fixedParameters;
  bool hasParameters = false, hasFixedParameters = false;
  while (std::getline(lines, line)) {
    line = trimmed(line);
    if (line.empty() || line.front() == '#') continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) return fail(fmt::format("{}: unexpected line \"{}\"", file, line));
    const std::string key = line.substr(0, colon);
    const std::string value = trimmed(line.substr(colon + 1));
    if (key == "Transform") {
      types.push_back(value);
    } else if (key == "Parameters") {
      parameters = value;
      hasParameters = true;
    } else if (key == "FixedParameters") {
      fixedParameters = value;
      hasFixedParameters = true;
    }
  }
  if (types.size() != 1) {
    return fail(fmt::format("{}: holds {} transforms; FluoroCT reads a file with exactly one linear transform", file,
                            types.size()));
  }
  if (!isLinearType(types[0])) {
    return fail(fmt::format("{}: transform type '{}' is not supported; save a linear (rigid) transform, "
                            "e.g. AffineTransform_double_3_3",
                            file, types[0]));
  }
  if (!hasParameters || !hasFixedParameters) {
    return fail(fmt::format("{}: the '{}' line is missing", file, hasParameters ? "FixedParameters" : "Parameters"));
  }
  auto p = parseNumbers(parameters);
  if (!p) return fail(fmt::format("{}: Parameters: {}", file, p.error()));
  auto c = parseNumbers(fixedParameters);
  if (!c) return fail(fmt::format("{}: FixedParameters: {}", file, c.error()));
  if (p.value().size() != 12 || c.value().size() != 3) {
    return fail(fmt::format("{}: expected 12 Parameters and 3 FixedParameters, got {} and {}", file, p.value().size(),
                            c.value().size()));
  }
  const auto& v = p.value();
  Eigen::Matrix3d A;
  A << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
  const Eigen::Vector3d translation(v[9], v[10], v[11]);
  const Eigen::Vector3d centre(c.value()[0], c.value()[1], c.value()[2]);
  Eigen::Matrix4d T_ct_from_world = Eigen::Matrix4d::Identity();
  T_ct_from_world.topLeftCorner<3, 3>() = A;
  T_ct_from_world.topRightCorner<3, 1>() = translation + centre - A * centre;
  auto valid = RigidPose::validated(T_ct_from_world, "the stored transform");
  if (!valid) return fail(fmt::format("{}: {}; FluoroCT poses are rigid", file, valid.error()));
  return valid.value().inverse();
}

}  // namespace fct
