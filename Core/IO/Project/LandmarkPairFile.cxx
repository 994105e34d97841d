#include "IO/Project/LandmarkPairFile.h"

#include <fmt/core.h>

#include <string>
#include <utility>

#include "Base/JsonDocument.h"
#include "Base/JsonReader.h"
#include "Base/NameTable.h"
#include "IO/Project/LandmarkFile.h"

namespace fct {

namespace {

namespace fs = std::filesystem;

constexpr NameTable<LandmarkPoseMethod, 2> kMethods{
    {{"reprojection", LandmarkPoseMethod::Reprojection}, {"triangulation", LandmarkPoseMethod::Triangulation}}};

}  // namespace

std::string_view LandmarkPairFile::methodName(LandmarkPoseMethod method) { return nameOf(method, kMethods); }

Result<LandmarkPairSet> LandmarkPairFile::read(const fs::path& path) {
  auto document = JsonDocument::parse(path);
  if (!document) return fail(document.error());
  JsonReader reader(document.value(), path.string());
  const fs::path folder = path.parent_path();
  LandmarkPairSet set;
  set.ctFile = (folder / reader.string("ct")).lexically_normal();
  set.imageFile = (folder / reader.string("image")).lexically_normal();
  if (reader.ok() && reader.has("method")) {
    set.method = readNamed(reader, "method", kMethods, "'reprojection' or 'triangulation'").value_or(set.method);
  }
  if (!reader.ok()) return fail(reader.error());
  std::vector<std::string> warnings = reader.unknownKeys({"ct", "image", "method"});

  auto ct = LandmarkFile::readCt(set.ctFile);
  if (!ct) return fail(ct.error());
  auto image = LandmarkFile::readImage(set.imageFile);
  if (!image) return fail(image.error());
  warnings.insert(warnings.end(), ct.warnings().begin(), ct.warnings().end());
  warnings.insert(warnings.end(), image.warnings().begin(), image.warnings().end());
  set.landmarks = Landmarks{std::move(ct).value(), std::move(image).value()};
  Result<LandmarkPairSet> result(std::move(set));
  for (std::string& warning : warnings) result.addWarning(std::move(warning));
  return result;
}

Status LandmarkPairFile::write(const LandmarkPairSet& set, const fs::path& path) {
  if (set.ctFile.empty() || set.imageFile.empty()) {
    return fail(fmt::format("cannot write '{}': the CT and the X-ray landmark files need a name", path.string()));
  }
  const fs::path folder = path.parent_path();
  if (Status written = LandmarkFile::writeCt(set.landmarks.ct, folder / set.ctFile); !written) return written;
  if (Status written = LandmarkFile::writeImage(set.landmarks.imageByView, folder / set.imageFile); !written) {
    return written;
  }
  const nlohmann::ordered_json document{{"ct", set.ctFile.generic_string()},
                                        {"image", set.imageFile.generic_string()},
                                        {"method", std::string(methodName(set.method))}};
  return JsonDocument::write(document, path);
}

}  // namespace fct
