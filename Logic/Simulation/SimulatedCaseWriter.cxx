#include "Simulation/SimulatedCaseWriter.h"

#include <fmt/core.h>

#include <algorithm>
#include <system_error>

#include "Base/JsonDocument.h"
#include "IO/Project/PoseFile.h"
#include "IO/Xray/ImageFileWriter.h"

namespace fct {

namespace {

/// True when `name` is usable as a file name on every platform: letters, digits, '-', '_' and '.', not starting with '.'.
bool isSafeFileStem(const std::string& name) {
  if (name.empty() || name.front() == '.') return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
  });
}

}  // namespace

Status SimulatedCaseWriter::checkViews(const std::vector<ViewSpec>& views) {
  if (views.empty()) return fail("no views to simulate; the view file lists none");
  for (const ViewSpec& view : views) {
    if (!isSafeFileStem(view.name)) {
      return fail(fmt::format("view name '{}' cannot name an image file; use letters, digits, '-', '_' or '.'",
                              view.name));
    }
  }
  return Ok{};
}

Result<SimulatedCase> SimulatedCaseWriter::write(const std::vector<ViewSpec>& views, const std::vector<FloatImage>& images,
                                                 const std::vector<SimulatedExtraImage>& extraImages,
                                                 const Eigen::Isometry3d& T_world_from_ct,
                                                 const nlohmann::ordered_json& parameters,
                                                 const std::filesystem::path& outDir) {
  if (Status checked = checkViews(views); !checked) return fail(checked.error());
  if (images.size() != views.size()) {
    return fail(fmt::format("{} images for {} views; need one image per view", images.size(), views.size()));
  }
  if (outDir.empty()) return fail("output folder is empty");
  std::error_code ec;
  std::filesystem::create_directories(outDir, ec);
  if (ec) return fail(fmt::format("cannot create output folder '{}': {}", outDir.string(), ec.message()));
  const std::filesystem::path dir = std::filesystem::absolute(outDir, ec);
  if (ec) return fail(fmt::format("cannot resolve output folder '{}': {}", outDir.string(), ec.message()));

  SimulatedCase result;
  result.views = views;
  for (std::size_t n = 0; n < views.size(); ++n) {
    result.views[n].imagePath = dir / (views[n].name + ".png");
    result.views[n].frame = 0;
    result.views[n].dewarpPath.clear();  // the simulated images are not from the input views' intensifier
    if (Status written = ImageFileWriter::writePng16(images[n], result.views[n].imagePath, 0.0f, 65535.0f); !written) {
      return fail(written.error());
    }
  }
  for (const SimulatedExtraImage& extra : extraImages) {
    const std::filesystem::path path = dir / extra.fileName;
    if (Status written = path.extension() == ".png" ? ImageFileWriter::writePng16(extra.image, path, 0.0f, 65535.0f)
                                                    : ImageFileWriter::writeNrrd2d(extra.image, path, extra.pixelSpacing_mm);
        !written) {
      return fail(written.error());
    }
  }
  result.viewFile = dir / "views.json";
  result.poseFile = dir / "truth_pose.json";
  result.parameterFile = dir / "simulation.json";
  if (Status written = ViewFile::write(result.views, result.viewFile); !written) return fail(written.error());
  if (Status written = PoseFile::write(T_world_from_ct, result.poseFile); !written) return fail(written.error());

  nlohmann::ordered_json document;
  document["views"] = "views.json";
  document["pose"] = "truth_pose.json";
  document["T_world_from_ct"] = JsonDocument::array(T_world_from_ct.matrix());
  for (const auto& [key, value] : parameters.items()) document[key] = value;
  if (Status written = JsonDocument::write(document, result.parameterFile); !written) return fail(written.error());
  return result;
}

}  // namespace fct
