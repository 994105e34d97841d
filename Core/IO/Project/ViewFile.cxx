#include "IO/Project/ViewFile.h"

#include <fmt/core.h>

#include <set>

#include "Base/JsonDocument.h"
#include "Base/JsonReader.h"

namespace fct {

namespace {

using nlohmann::json;
using nlohmann::ordered_json;

void addWarnings(std::vector<std::string>& warnings, std::vector<std::string> more) {
  warnings.insert(warnings.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
}

/// The image path and frame of a view ("image": "ap.png" or {"path": "ap.dcm", "frame": 0, "mirror_columns": false}),
/// made absolute
/// against `folder`; checks that the file exists.
void readImage(JsonReader& reader, const std::filesystem::path& folder, ViewSpec& view,
               std::vector<std::string>& warnings) {
  const json* image = reader.find("image");
  if (!image) return;
  std::string relative;
  if (image->is_string()) {
    relative = reader.string("image");
  } else if (image->is_object()) {
    relative = reader.string("image.path");
    view.frame = reader.has("image.frame") ? reader.integer("image.frame", 0) : 0;
    view.mirrorColumns = reader.has("image.mirror_columns") && reader.boolean("image.mirror_columns");
    addWarnings(warnings, reader.unknownKeys({"path", "frame", "mirror_columns"}, "image"));
  } else {
    reader.rejectKey("image", fmt::format("must be a file name or {{\"path\": ..., \"frame\": ...}}, got {}",
                                          JsonReader::describe(*image)));
  }
  if (!reader.ok()) return;
  view.imagePath = (folder / std::filesystem::path(relative)).lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(view.imagePath, ec)) {
    reader.rejectKey("image", fmt::format("names '{}', which does not exist; image paths are relative to the view "
                                          "file's folder '{}'",
                                          view.imagePath.string(), folder.string()));
  }
}

/// The dewarp file path of a view ("dewarp": "intensifier.dewarp.json"), made absolute against `folder`; checks that
/// the file exists.
void readDewarp(JsonReader& reader, const std::filesystem::path& folder, ViewSpec& view) {
  if (!reader.has("dewarp")) return;
  const std::string relative = reader.string("dewarp");
  if (!reader.ok()) return;
  view.dewarpPath = (folder / std::filesystem::path(relative)).lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(view.dewarpPath, ec)) {
    reader.rejectKey("dewarp", fmt::format("names '{}', which does not exist; make it with 'fluoroct dewarp-calibrate' "
                                           "(paths are relative to the view file's folder '{}')",
                                           view.dewarpPath.string(), folder.string()));
  }
}

/// The camera from either T_world_from_camera + source_to_detector_mm + principal_point_px, or projection_matrix.
void readCamera(JsonReader& reader, ViewSpec& view) {
  CameraIntrinsics intrinsics;
  intrinsics.cols = reader.integer("detector.cols", 1);
  intrinsics.rows = reader.integer("detector.rows", 1);
  intrinsics.pixelSpacing_mm = reader.vector("detector.pixel_spacing_mm", 2);
  if (reader.ok() && (intrinsics.pixelSpacing_mm.array() <= 0.0).any()) {
    reader.rejectKey("detector.pixel_spacing_mm", fmt::format("must be positive, got [{}, {}] mm",
                                                              intrinsics.pixelSpacing_mm.x(),
                                                              intrinsics.pixelSpacing_mm.y()));
  }
  const bool hasProjection = reader.has("projection_matrix");
  const bool hasPose = reader.has("T_world_from_camera") || reader.has("source_to_detector_mm") ||
                       reader.has("principal_point_px");
  if (hasProjection && hasPose) {
    reader.reject("gives both projection_matrix and T_world_from_camera/source_to_detector_mm/principal_point_px; "
                  "keep only one camera form");
  } else if (!hasProjection && !hasPose) {
    reader.reject("has no camera: give T_world_from_camera with source_to_detector_mm and principal_point_px, "
                  "or a 3x4 projection_matrix");
  }
  if (!reader.ok()) return;
  Result<Camera> camera = Camera();
  if (hasProjection) {
    const Eigen::Matrix<double, 3, 4> P = reader.matrix("projection_matrix", 3, 4);
    if (!reader.ok()) return;
    camera = Camera::fromProjectionMatrix(P, intrinsics.cols, intrinsics.rows, intrinsics.pixelSpacing_mm);
  } else {
    intrinsics.sourceToDetector_mm = reader.positiveNumber("source_to_detector_mm");
    intrinsics.principalPoint_px = reader.vector("principal_point_px", 2);
    Eigen::Isometry3d T_world_from_camera;
    T_world_from_camera.matrix() = reader.matrix("T_world_from_camera", 4, 4);
    if (!reader.ok()) return;
    camera = Camera::create(intrinsics, T_world_from_camera);
  }
  if (!camera) return reader.reject(camera.error());
  view.camera = camera.value();
}

void readSpheres(JsonReader& reader, ViewSpec& view, std::vector<std::string>& warnings) {
  const json* spheres = reader.find("calibration_spheres_px");
  if (!spheres) return;
  if (!spheres->is_array()) {
    return reader.rejectKey("calibration_spheres_px", fmt::format("must be an array of {{\"center\": [u, v], "
                                                                  "\"radius\": r}}, got {}",
                                                                  JsonReader::describe(*spheres)));
  }
  for (std::size_t i = 0; i < spheres->size(); ++i) {
    JsonReader sphere((*spheres)[i], fmt::format("{}: calibration_spheres_px[{}]", reader.where(), i));
    const Eigen::Vector2d center_px = sphere.vector("center", 2);
    const double radius_px = sphere.positiveNumber("radius");
    if (!sphere.ok()) return reader.adoptError(sphere);
    view.calibrationSpheres.push_back({center_px, radius_px});
    addWarnings(warnings, sphere.unknownKeys({"center", "radius"}));
  }
}

/// The image path as written: relative to `folder` if the image lies inside it, else absolute.
std::string pathForFile(const std::filesystem::path& imagePath, const std::filesystem::path& folder) {
  const std::filesystem::path absolute = std::filesystem::absolute(imagePath).lexically_normal();
  const std::filesystem::path relative = absolute.lexically_relative(folder);
  if (!relative.empty() && *relative.begin() != "..") return relative.generic_string();
  return absolute.generic_string();
}

}  // namespace

Result<std::vector<ViewSpec>> ViewFile::read(const std::filesystem::path& path) {
  auto document = JsonDocument::parse(path);
  if (!document) return fail(document.error());
  const json& root = document.value();
  const std::string file = path.string();
  const std::filesystem::path folder = std::filesystem::absolute(path).parent_path().lexically_normal();

  JsonReader top(root, file);
  const json* viewsJson = top.find("views");
  if (top.ok() && (!viewsJson || !viewsJson->is_array() || viewsJson->empty())) {
    top.rejectKey("views", fmt::format("must be a non-empty array of views, got {}",
                                       viewsJson ? JsonReader::describe(*viewsJson) : "nothing"));
  }
  if (!top.ok()) return fail(top.error());
  std::vector<std::string> warnings = top.unknownKeys({"views"});

  std::vector<ViewSpec> views;
  std::set<std::string> names;
  for (std::size_t i = 0; i < viewsJson->size(); ++i) {
    const json& viewJson = (*viewsJson)[i];
    JsonReader unnamed(viewJson, fmt::format("{}: views[{}]", file, i));
    ViewSpec view;
    view.name = unnamed.string("name");
    if (!unnamed.ok()) return fail(unnamed.error());
    if (!names.insert(view.name).second) {
      return fail(fmt::format("{}: views[{}]: view name '{}' is used twice; give each view a unique name", file, i,
                              view.name));
    }
    JsonReader reader(viewJson, fmt::format("{}: view '{}'", file, view.name));
    readImage(reader, folder, view, warnings);
    readDewarp(reader, folder, view);
    readCamera(reader, view);
    readSpheres(reader, view, warnings);
    if (!reader.ok()) return fail(reader.error());
    addWarnings(warnings, reader.unknownKeys({"name", "image", "detector", "source_to_detector_mm",
                                              "principal_point_px", "T_world_from_camera", "projection_matrix",
                                              "calibration_spheres_px", "dewarp"}));
    addWarnings(warnings, reader.unknownKeys({"cols", "rows", "pixel_spacing_mm"}, "detector"));
    views.push_back(std::move(view));
  }
  Result<std::vector<ViewSpec>> result(std::move(views));
  for (std::string& warning : warnings) result.addWarning(std::move(warning));
  return result;
}

Status ViewFile::write(const std::vector<ViewSpec>& views, const std::filesystem::path& path) {
  if (views.empty()) return fail(fmt::format("cannot write '{}': there are no views to write", path.string()));
  const std::filesystem::path folder = std::filesystem::absolute(path).parent_path().lexically_normal();
  std::set<std::string> names;
  ordered_json viewsJson = ordered_json::array();
  for (const ViewSpec& view : views) {
    if (view.name.empty()) return fail(fmt::format("cannot write '{}': a view has no name", path.string()));
    if (!names.insert(view.name).second) {
      return fail(fmt::format("cannot write '{}': view name '{}' is used twice", path.string(), view.name));
    }
    const CameraIntrinsics& in = view.camera.intrinsics();
    if (auto valid = Camera::create(in, view.camera.T_world_from_camera()); !valid) {
      return fail(fmt::format("cannot write '{}': view '{}': {}", path.string(), view.name, valid.error()));
    }
    ordered_json v;
    v["name"] = view.name;
    if (!view.imagePath.empty()) {
      v["image"] = ordered_json{{"path", pathForFile(view.imagePath, folder)}, {"frame", view.frame}};
      if (view.mirrorColumns) v["image"]["mirror_columns"] = true;
    }
    if (!view.dewarpPath.empty()) v["dewarp"] = pathForFile(view.dewarpPath, folder);
    v["detector"] = ordered_json{{"cols", in.cols},
                                 {"rows", in.rows},
                                 {"pixel_spacing_mm", JsonDocument::array(in.pixelSpacing_mm)}};
    v["source_to_detector_mm"] = in.sourceToDetector_mm;
    v["principal_point_px"] = JsonDocument::array(in.principalPoint_px);
    v["T_world_from_camera"] = JsonDocument::array(view.camera.T_world_from_camera().matrix());
    if (!view.calibrationSpheres.empty()) {
      ordered_json spheres = ordered_json::array();
      for (const PixelCircle& s : view.calibrationSpheres) {
        spheres.push_back({{"center", JsonDocument::array(s.centre_px)}, {"radius", s.radius_px}});
      }
      v["calibration_spheres_px"] = std::move(spheres);
    }
    viewsJson.push_back(std::move(v));
  }
  return JsonDocument::write(ordered_json{{"views", std::move(viewsJson)}}, path);
}

}  // namespace fct
