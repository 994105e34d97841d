#include "IO/Volume/NrrdFormat.h"

#include <fmt/core.h>

#include <bit>
#include <map>
#include <optional>
#include <sstream>

#include "IO/Volume/TextHeader.h"
#include "IO/Volume/VoxelCodec.h"

namespace fct {
namespace {

std::optional<ScalarType> scalarType(const std::string& type) {
  static const std::map<std::string, ScalarType> kTypes = {
      {"uchar", ScalarType::UInt8},          {"unsigned char", ScalarType::UInt8},
      {"uint8", ScalarType::UInt8},          {"uint8_t", ScalarType::UInt8},
      {"signed char", ScalarType::Int8},     {"int8", ScalarType::Int8},
      {"int8_t", ScalarType::Int8},          {"short", ScalarType::Int16},
      {"short int", ScalarType::Int16},      {"signed short", ScalarType::Int16},
      {"signed short int", ScalarType::Int16}, {"int16", ScalarType::Int16},
      {"int16_t", ScalarType::Int16},        {"ushort", ScalarType::UInt16},
      {"unsigned short", ScalarType::UInt16}, {"unsigned short int", ScalarType::UInt16},
      {"uint16", ScalarType::UInt16},        {"uint16_t", ScalarType::UInt16},
      {"int", ScalarType::Int32},            {"signed int", ScalarType::Int32},
      {"int32", ScalarType::Int32},          {"int32_t", ScalarType::Int32},
      {"uint", ScalarType::UInt32},          {"unsigned int", ScalarType::UInt32},
      {"uint32", ScalarType::UInt32},        {"uint32_t", ScalarType::UInt32},
      {"float", ScalarType::Float32},        {"double", ScalarType::Float64}};
  const auto it = kTypes.find(type);
  return it == kTypes.end() ? std::nullopt : std::optional<ScalarType>(it->second);
}

/// Matrix taking positions in the file's space to LPS, or nothing for an unsupported space.
std::optional<Eigen::Matrix3d> toLps(const std::string& space) {
  if (space == "left-posterior-superior" || space == "lps") return Eigen::Matrix3d::Identity();
  if (space == "right-anterior-superior" || space == "ras") return Eigen::Vector3d(-1, -1, 1).asDiagonal().toDenseMatrix();
  if (space == "left-anterior-superior" || space == "las") return Eigen::Vector3d(1, -1, 1).asDiagonal().toDenseMatrix();
  return std::nullopt;
}

}  // namespace

Result<Volume> NrrdFormat::read(const std::filesystem::path& path) {
  const std::string source = fmt::format("NRRD file '{}'", path.string());
  auto content = VoxelCodec::readFile(path);
  if (!content.ok()) return fail(content.error());
  const std::string& text = content.value();
  if (text.rfind("NRRD000", 0) != 0) return fail(fmt::format("{} does not start with the NRRD magic 'NRRD000'", source));

  // Fields up to the first empty line (or the end, for a detached header).
  std::map<std::string, std::string> fields;
  std::size_t pos = text.find('\n');
  std::size_t dataStart = text.size();
  bool headerEnded = false;
  while (pos != std::string::npos && pos < text.size()) {
    const std::size_t lineStart = pos + 1;
    std::size_t lineEnd = text.find('\n', lineStart);
    if (lineEnd == std::string::npos) lineEnd = text.size();
    std::string line = text.substr(lineStart, lineEnd - lineStart);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = lineEnd;
    if (line.empty()) {
      dataStart = std::min(lineEnd + 1, text.size());
      headerEnded = true;
      break;
    }
    if (line[0] == '#') continue;
    const std::size_t colon = line.find(": ");
    if (colon == std::string::npos) continue;  // key:=value pairs and other extensions carry no geometry
    fields[TextHeader::lower(TextHeader::trim(line.substr(0, colon)))] = TextHeader::trim(line.substr(colon + 2));
  }
  const auto field = [&](const std::string& key) -> std::optional<std::string> {
    const auto it = fields.find(key);
    return it == fields.end() ? std::nullopt : std::optional<std::string>(it->second);
  };

  const auto dimension = field("dimension");
  if (!dimension || TextHeader::trim(*dimension) != "3") {
    return fail(fmt::format("{} has dimension {}; only 3D scalar volumes are supported", source,
                            dimension ? *dimension : "(missing)"));
  }
  const auto typeText = field("type");
  const auto type = typeText ? scalarType(TextHeader::lower(*typeText)) : std::nullopt;
  if (!type) {
    return fail(fmt::format("{} has voxel type '{}', which is not supported (use an 8-, 16- or 32-bit integer, float "
                            "or double)", source, typeText ? *typeText : "(missing)"));
  }
  const auto sizesText = field("sizes");
  if (!sizesText) return fail(fmt::format("{} lacks the 'sizes' field", source));
  auto sizes = TextHeader::sizes(*sizesText, "sizes");
  if (!sizes.ok()) return fail(fmt::format("{}: {}", source, sizes.error()));
  const Eigen::Vector3i dims(sizes.value()[0], sizes.value()[1], sizes.value()[2]);
  auto count = VoxelCodec::voxelCount(dims, source);
  if (!count.ok()) return fail(count.error());

  // Geometry in the file's space, then to LPS.
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Matrix3d lpsFromSpace = Eigen::Matrix3d::Identity();
  std::string spaceName = "no space: identity axes";
  const auto space = field("space");
  const auto directions = field("space directions");
  if (space) {
    const auto conversion = toLps(TextHeader::lower(*space));
    if (!conversion) {
      return fail(fmt::format("{} uses space '{}'; only RAS, LAS and LPS patient spaces are supported", source, *space));
    }
    lpsFromSpace = *conversion;
    spaceName = *space;
    if (!directions) return fail(fmt::format("{} has a space but no 'space directions'", source));
    auto numbers = TextHeader::numbers(*directions, 9, "space directions");
    if (!numbers.ok()) return fail(fmt::format("{}: {}", source, numbers.error()));
    axes = Eigen::Map<const Eigen::Matrix3d>(numbers.value().data());  // each vector is one column
    if (const auto originText = field("space origin")) {
      auto o = TextHeader::numbers(*originText, 3, "space origin");
      if (!o.ok()) return fail(fmt::format("{}: {}", source, o.error()));
      origin = Eigen::Map<const Eigen::Vector3d>(o.value().data());
    }
  } else if (directions) {
    return fail(fmt::format("{} has 'space directions' but no 'space' naming its frame; add 'space: RAS' or "
                            "'space: LPS' to the header", source));
  } else if (const auto spacings = field("spacings")) {
    auto s = TextHeader::numbers(*spacings, 3, "spacings");
    if (!s.ok()) return fail(fmt::format("{}: {}", source, s.error()));
    axes = Eigen::Map<const Eigen::Vector3d>(s.value().data()).asDiagonal();
  }

  // Voxel bytes: attached after the blank line, or in a detached data file.
  std::string detached;
  std::string_view payload;
  const auto dataFile = field("data file") ? field("data file") : field("datafile");
  if (dataFile) {
    if (dataFile->find(' ') != std::string::npos || TextHeader::lower(*dataFile) == "list") {
      return fail(fmt::format("{} splits its data over several files ('{}'); only one data file is supported", source,
                              *dataFile));
    }
    const std::filesystem::path dataPath = path.parent_path() / *dataFile;
    auto data = VoxelCodec::readFile(dataPath);  // gunzips a gzip-encoded data file transparently
    if (!data.ok()) return fail(fmt::format("{}: its data file: {}", source, data.error()));
    detached = std::move(data.value());
    payload = detached;
  } else {
    if (!headerEnded) return fail(fmt::format("{} is truncated: the header has no end (blank line) and no data", source));
    payload = std::string_view(text).substr(dataStart);
  }
  if (const auto lineSkip = field("line skip")) {
    auto n = TextHeader::numbers(*lineSkip, 1, "line skip");
    if (!n.ok()) return fail(fmt::format("{}: {}", source, n.error()));
    for (int i = 0; i < static_cast<int>(n.value()[0]); ++i) {
      const std::size_t nl = payload.find('\n');
      if (nl == std::string_view::npos) return fail(fmt::format("{}: 'line skip' runs past the data", source));
      payload.remove_prefix(nl + 1);
    }
  }
  const std::string encoding = TextHeader::lower(field("encoding").value_or("raw"));
  const std::size_t dataBytes = count.value() * VoxelCodec::bytesPerScalar(*type);
  std::string inflated;
  if (encoding == "gzip" || encoding == "gz") {
    if (!dataFile) {  // readFile only gunzips whole files; an attached gzip payload is inflated here
      auto bytes = VoxelCodec::inflate(payload, dataBytes);
      if (!bytes.ok()) return fail(fmt::format("{}: {}", source, bytes.error()));
      inflated = std::move(bytes.value());
      payload = inflated;
    }
  } else if (encoding != "raw") {
    return fail(fmt::format("{} uses encoding '{}'; only raw and gzip are supported", source, encoding));
  }
  if (const auto byteSkip = field("byte skip")) {
    auto n = TextHeader::numbers(*byteSkip, 1, "byte skip");
    if (!n.ok()) return fail(fmt::format("{}: {}", source, n.error()));
    const long long skip = static_cast<long long>(n.value()[0]);
    if (skip == -1) {
      if (payload.size() >= dataBytes) payload.remove_prefix(payload.size() - dataBytes);
    } else if (skip >= 0 && static_cast<std::size_t>(skip) <= payload.size()) {
      payload.remove_prefix(static_cast<std::size_t>(skip));
    } else {
      return fail(fmt::format("{}: 'byte skip' {} is invalid for {} bytes of data", source, skip, payload.size()));
    }
  }
  if (payload.size() < dataBytes) {
    return fail(fmt::format("{} is truncated: {}x{}x{} {} voxels need {} bytes but only {} are present", source,
                            dims.x(), dims.y(), dims.z(), VoxelCodec::name(*type), dataBytes, payload.size()));
  }
  const bool bigEndian = TextHeader::lower(field("endian").value_or(
                             std::endian::native == std::endian::big ? "big" : "little")) == "big";
  auto volume = VoxelCodec::assemble(dims, lpsFromSpace * axes, lpsFromSpace * origin,
                                     VoxelCodec::toFloat(payload, count.value(), *type, bigEndian), source);
  if (!volume.ok()) return volume;
  volume.value().description = fmt::format("{} ({}, {}, {} encoding)", path.filename().string(),
                                           VoxelCodec::name(*type), spaceName, encoding);
  return volume;
}

std::string NrrdFormat::header(const Volume& volume) {
  const Eigen::Matrix3d axes = volume.direction_lps() * volume.spacing_mm().asDiagonal();
  const Eigen::Vector3d& o = volume.origin_lps_mm();
  std::string text = "NRRD0004\n# written by FluoroCT\ntype: float\ndimension: 3\nspace: left-posterior-superior\n";
  text += fmt::format("sizes: {} {} {}\n", volume.dims().x(), volume.dims().y(), volume.dims().z());
  text += "space directions:";
  for (int c = 0; c < 3; ++c) text += fmt::format(" ({},{},{})", axes(0, c), axes(1, c), axes(2, c));
  text += "\nkinds: domain domain domain\n";
  text += fmt::format("endian: {}\n", std::endian::native == std::endian::big ? "big" : "little");
  text += "encoding: raw\n";
  text += fmt::format("space origin: ({},{},{})\n\n", o.x(), o.y(), o.z());
  return text;
}

}  // namespace fct
