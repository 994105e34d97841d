#include "IO/Volume/MetaImageFormat.h"

#include <fmt/core.h>

#include <bit>
#include <cctype>
#include <cmath>
#include <map>
#include <optional>

#include "IO/Volume/TextHeader.h"
#include "IO/Volume/VoxelCodec.h"

namespace fct {
namespace {

std::optional<ScalarType> scalarType(const std::string& type) {
  static const std::map<std::string, ScalarType> kTypes = {
      {"MET_UCHAR", ScalarType::UInt8},   {"MET_CHAR", ScalarType::Int8},   {"MET_USHORT", ScalarType::UInt16},
      {"MET_SHORT", ScalarType::Int16},   {"MET_UINT", ScalarType::UInt32}, {"MET_INT", ScalarType::Int32},
      {"MET_FLOAT", ScalarType::Float32}, {"MET_DOUBLE", ScalarType::Float64}};
  const auto it = kTypes.find(type);
  return it == kTypes.end() ? std::nullopt : std::optional<ScalarType>(it->second);
}

/// LPS direction of an axis that runs away from the anatomical side `letter` (ITK: "RAI" is the identity).
std::optional<Eigen::Vector3d> axisFromLetter(char letter) {
  switch (letter) {
    case 'R': return Eigen::Vector3d(1, 0, 0);
    case 'L': return Eigen::Vector3d(-1, 0, 0);
    case 'A': return Eigen::Vector3d(0, 1, 0);
    case 'P': return Eigen::Vector3d(0, -1, 0);
    case 'I': return Eigen::Vector3d(0, 0, 1);
    case 'S': return Eigen::Vector3d(0, 0, -1);
    default: return std::nullopt;
  }
}

/// AnatomicalOrientation letters of the closest axis-aligned orientation (each column to a distinct LPS axis).
std::string orientationLetters(const Eigen::Matrix3d& direction) {
  static const char kFrom[3][2] = {{'R', 'L'}, {'A', 'P'}, {'I', 'S'}};  // [lps axis][negative?]
  std::string letters = "???";
  bool used[3] = {false, false, false};
  for (int pick = 0; pick < 3; ++pick) {  // greedily assign the strongest remaining (column, lps axis) pair
    int bestCol = -1, bestRow = -1;
    double best = -1.0;
    for (int c = 0; c < 3; ++c) {
      if (letters[c] != '?') continue;
      for (int r = 0; r < 3; ++r) {
        if (!used[r] && std::abs(direction(r, c)) > best) {
          best = std::abs(direction(r, c));
          bestCol = c;
          bestRow = r;
        }
      }
    }
    used[bestRow] = true;
    letters[bestCol] = kFrom[bestRow][direction(bestRow, bestCol) < 0 ? 1 : 0];
  }
  return letters;
}

}  // namespace

Result<Volume> MetaImageFormat::read(const std::filesystem::path& path) {
  const std::string source = fmt::format("MetaImage file '{}'", path.string());
  auto content = VoxelCodec::readFile(path);
  if (!content.ok()) return fail(content.error());
  const std::string& text = content.value();

  // "Key = Value" lines up to and including ElementDataFile, after which local data starts.
  std::map<std::string, std::string> fields;
  std::size_t pos = 0;
  std::size_t dataStart = std::string::npos;
  while (pos < text.size()) {
    std::size_t lineEnd = text.find('\n', pos);
    if (lineEnd == std::string::npos) lineEnd = text.size();
    const std::string line = text.substr(pos, lineEnd - pos);
    pos = lineEnd + 1;
    const std::size_t eq = line.find('=');
    if (eq == std::string::npos) {
      if (!TextHeader::trim(line).empty()) return fail(fmt::format("{}: header line '{}' is not 'Key = Value'", source, TextHeader::trim(line)));
      continue;
    }
    const std::string key = TextHeader::trim(line.substr(0, eq));
    fields[key] = TextHeader::trim(line.substr(eq + 1));
    if (key == "ElementDataFile") {
      dataStart = std::min(pos, text.size());
      break;
    }
  }
  if (fields.find("ObjectType") == fields.end() && fields.find("NDims") == fields.end()) {
    return fail(fmt::format("{} is not a MetaImage (no ObjectType or NDims field)", source));
  }
  const auto field = [&](std::initializer_list<const char*> keys) -> std::optional<std::string> {
    for (const char* key : keys) {
      if (const auto it = fields.find(key); it != fields.end()) return it->second;
    }
    return std::nullopt;
  };
  const auto isTrue = [&](const char* key) { return TextHeader::lower(field({key}).value_or("false")) == "true"; };

  if (field({"NDims"}).value_or("") != "3") {
    return fail(fmt::format("{} has NDims {}; only 3D scalar volumes are supported", source,
                            field({"NDims"}).value_or("(missing)")));
  }
  if (const auto channels = field({"ElementNumberOfChannels"}); channels && *channels != "1") {
    return fail(fmt::format("{} has {} channels per voxel; only scalar volumes are supported", source, *channels));
  }
  const auto typeText = field({"ElementType"});
  const auto type = typeText ? scalarType(*typeText) : std::nullopt;
  if (!type) {
    return fail(fmt::format("{} has ElementType '{}', which is not supported (use MET_UCHAR, MET_CHAR, MET_SHORT, "
                            "MET_USHORT, MET_INT, MET_UINT, MET_FLOAT or MET_DOUBLE)", source,
                            typeText.value_or("(missing)")));
  }
  const auto dimText = field({"DimSize"});
  if (!dimText) return fail(fmt::format("{} lacks the DimSize field", source));
  auto dimValues = TextHeader::sizes(*dimText, "DimSize");
  if (!dimValues.ok()) return fail(fmt::format("{}: {}", source, dimValues.error()));
  const Eigen::Vector3i dims(dimValues.value()[0], dimValues.value()[1], dimValues.value()[2]);
  auto count = VoxelCodec::voxelCount(dims, source);
  if (!count.ok()) return fail(count.error());

  Eigen::Vector3d spacing_mm = Eigen::Vector3d::Ones();
  if (const auto spacingText = field({"ElementSpacing", "ElementSize"})) {
    auto s = TextHeader::numbers(*spacingText, 3, "ElementSpacing");
    if (!s.ok()) return fail(fmt::format("{}: {}", source, s.error()));
    spacing_mm = Eigen::Map<const Eigen::Vector3d>(s.value().data());
  }
  Eigen::Vector3d origin_lps_mm = Eigen::Vector3d::Zero();
  if (const auto originText = field({"Offset", "Position", "Origin"})) {
    auto o = TextHeader::numbers(*originText, 3, "Offset");
    if (!o.ok()) return fail(fmt::format("{}: {}", source, o.error()));
    origin_lps_mm = Eigen::Map<const Eigen::Vector3d>(o.value().data());
  }
  Eigen::Matrix3d direction = Eigen::Matrix3d::Identity();
  if (const auto matrixText = field({"TransformMatrix", "Rotation", "Orientation"})) {
    auto m = TextHeader::numbers(*matrixText, 9, "TransformMatrix");
    if (!m.ok()) return fail(fmt::format("{}: {}", source, m.error()));
    direction = Eigen::Map<const Eigen::Matrix3d>(m.value().data());  // row n of the text = column n here
  } else if (const auto letters = field({"AnatomicalOrientation"}); letters && letters->size() == 3) {
    for (int c = 0; c < 3; ++c) {
      const auto axis = axisFromLetter(static_cast<char>(std::toupper(static_cast<unsigned char>((*letters)[c]))));
      if (!axis) return fail(fmt::format("{}: AnatomicalOrientation '{}' is not made of R/L/A/P/I/S", source, *letters));
      direction.col(c) = *axis;
    }
  }

  // Voxel bytes: local (after the header) or a data file beside the header.
  const std::string dataFile = field({"ElementDataFile"}).value_or("");
  std::string detached;
  std::string_view payload;
  if (dataFile.empty()) return fail(fmt::format("{} lacks the ElementDataFile field (it is truncated?)", source));
  if (dataFile == "LOCAL") {
    payload = std::string_view(text).substr(dataStart);
  } else if (dataFile.find(' ') != std::string::npos || dataFile.find('%') != std::string::npos || dataFile == "LIST") {
    return fail(fmt::format("{} splits its data over several files ('{}'); only one data file is supported", source,
                            dataFile));
  } else {
    auto data = VoxelCodec::readFile(path.parent_path() / dataFile);
    if (!data.ok()) return fail(fmt::format("{}: its data file: {}", source, data.error()));
    detached = std::move(data.value());
    payload = detached;
  }
  const std::size_t dataBytes = count.value() * VoxelCodec::bytesPerScalar(*type);
  std::string inflated;
  if (isTrue("CompressedData")) {
    auto bytes = VoxelCodec::inflate(payload, dataBytes);
    if (!bytes.ok()) return fail(fmt::format("{}: {}", source, bytes.error()));
    inflated = std::move(bytes.value());
    payload = inflated;
  } else if (const auto headerSize = field({"HeaderSize"})) {
    auto n = TextHeader::numbers(*headerSize, 1, "HeaderSize");
    if (!n.ok()) return fail(fmt::format("{}: {}", source, n.error()));
    const long long skip = static_cast<long long>(n.value()[0]);
    if (skip == -1 && payload.size() >= dataBytes) {
      payload.remove_prefix(payload.size() - dataBytes);
    } else if (skip >= 0 && static_cast<std::size_t>(skip) <= payload.size()) {
      payload.remove_prefix(static_cast<std::size_t>(skip));
    }
  }
  if (payload.size() < dataBytes) {
    return fail(fmt::format("{} is truncated: {}x{}x{} {} voxels need {} bytes but only {} are present", source,
                            dims.x(), dims.y(), dims.z(), VoxelCodec::name(*type), dataBytes, payload.size()));
  }
  const bool bigEndian = isTrue("BinaryDataByteOrderMSB") || isTrue("ElementByteOrderMSB");
  auto volume = VoxelCodec::assemble(dims, direction * spacing_mm.asDiagonal(), origin_lps_mm,
                                     VoxelCodec::toFloat(payload, count.value(), *type, bigEndian), source);
  if (!volume.ok()) return volume;
  volume.value().description = fmt::format("{} ({}, LPS{})", path.filename().string(), VoxelCodec::name(*type),
                                           isTrue("CompressedData") ? ", compressed" : "");
  return volume;
}

std::string MetaImageFormat::header(const Volume& volume, const std::string& data_file) {
  const Eigen::Matrix3d& d = volume.direction_lps();
  const Eigen::Vector3d& s = volume.spacing_mm();
  const Eigen::Vector3d& o = volume.origin_lps_mm();
  std::string text = "ObjectType = Image\nNDims = 3\nBinaryData = True\n";
  text += fmt::format("BinaryDataByteOrderMSB = {}\n", std::endian::native == std::endian::big ? "True" : "False");
  text += "CompressedData = False\nTransformMatrix =";
  for (int c = 0; c < 3; ++c) text += fmt::format(" {} {} {}", d(0, c), d(1, c), d(2, c));
  text += fmt::format("\nOffset = {} {} {}\nCenterOfRotation = 0 0 0\n", o.x(), o.y(), o.z());
  text += fmt::format("AnatomicalOrientation = {}\n", orientationLetters(d));
  text += fmt::format("ElementSpacing = {} {} {}\n", s.x(), s.y(), s.z());
  text += fmt::format("DimSize = {} {} {}\n", volume.dims().x(), volume.dims().y(), volume.dims().z());
  text += fmt::format("ElementType = MET_FLOAT\nElementDataFile = {}\n", data_file);
  return text;
}

}  // namespace fct
