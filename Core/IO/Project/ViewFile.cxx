#include "IO/Project/ViewFile.h"

#include <fmt/core.h>

#include <set>
#include <tuple>

#include "Base/JsonDocument.h"
#include "Base/JsonReader.h"
#include "IO/Dicom/XrayDicomReader.h"

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

/// `relative` made absolute against `folder`; rejects `key` when the file does not exist.
std::filesystem::path existingFile(JsonReader& reader, const std::string& key, const std::filesystem::path& folder,
                                   const std::string& relative) {
  std::filesystem::path path = (folder / std::filesystem::path(relative)).lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    reader.rejectKey(key, fmt::format("names '{}', which does not exist; paths are relative to the view file's "
                                      "folder '{}'",
                                      path.string(), folder.string()));
  }
  return path;
}

/// The frame range of a multi-frame sequence: "all" or [first, last] (0-based, inclusive), checked against the file's
/// frame count (its DICOM header).
void readFrameRange(JsonReader& reader, ViewSequence& sequence) {
  const json* frames = reader.find("sequence.frames");
  const bool all = !frames || (frames->is_string() && frames->get<std::string>() == "all");
  if (!all && !(frames->is_array() && frames->size() == 2 && (*frames)[0].is_number_integer() &&
                (*frames)[1].is_number_integer())) {
    return reader.rejectKey("sequence.frames", fmt::format("must be \"all\" or [first, last] (0-based frame numbers), "
                                                           "got {}",
                                                           JsonReader::describe(*frames)));
  }
  auto header = XrayDicomReader::readHeader(sequence.multiFramePath);
  if (!header) return reader.rejectKey("sequence.path", header.error());
  const int count = header.value().frames;
  sequence.allFrames = all;
  sequence.firstFrame = all ? 0 : (*frames)[0].get<int>();
  sequence.lastFrame = all ? count - 1 : (*frames)[1].get<int>();
  if (sequence.firstFrame < 0 || sequence.lastFrame < sequence.firstFrame || sequence.lastFrame >= count) {
    reader.rejectKey("sequence.frames", fmt::format("[{}, {}] is not a frame range of '{}', which has {} frames (0 to "
                                                    "{}); give first <= last within them",
                                                    sequence.firstFrame, sequence.lastFrame,
                                                    sequence.multiFramePath.string(), count, count - 1));
  }
}

/// A view's frame sequence: {"path": "cine.dcm", "frames": "all" | [first, last]} or ["f000.tif", ...] (paths relative
/// to `folder`); the view's imagePath/frame become the first frame.
void readSequence(JsonReader& reader, const std::filesystem::path& folder, ViewSpec& view,
                  std::vector<std::string>& warnings) {
  const json* sequenceJson = reader.find("sequence");
  if (!sequenceJson) return;
  if (reader.has("image")) return reader.reject("gives both \"image\" and \"sequence\"; keep only one");
  ViewSequence sequence;
  if (sequenceJson->is_array() && !sequenceJson->empty()) {
    for (std::size_t i = 0; i < sequenceJson->size() && reader.ok(); ++i) {
      const std::string key = fmt::format("sequence[{}]", i);
      if (!(*sequenceJson)[i].is_string()) return reader.rejectKey(key, "must be an image file name");
      sequence.files.push_back(existingFile(reader, key, folder, (*sequenceJson)[i].get<std::string>()));
    }
  } else if (sequenceJson->is_object()) {
    const std::string relative = reader.string("sequence.path");
    if (!reader.ok()) return;
    sequence.multiFramePath = existingFile(reader, "sequence.path", folder, relative);
    if (!reader.ok()) return;
    readFrameRange(reader, sequence);
    addWarnings(warnings, reader.unknownKeys({"path", "frames"}, "sequence"));
  } else {
    return reader.rejectKey("sequence", fmt::format("must be a non-empty list of image files or {{\"path\": "
                                                    "\"cine.dcm\", \"frames\": \"all\" | [first, last]}}, got {}",
                                                    JsonReader::describe(*sequenceJson)));
  }
  if (!reader.ok()) return;
  std::tie(view.imagePath, view.frame) = sequence.frame(0);
  view.sequence = std::move(sequence);
}

/// Fails unless every view has a sequence of the same frame count, or none has one.
Status checkFrameCounts(const std::vector<ViewSpec>& views, const std::string& file) {
  const ViewSpec& first = views.front();
  for (const ViewSpec& view : views) {
    const int count = view.sequence ? view.sequence->frameCount() : 0;
    const int firstCount = first.sequence ? first.sequence->frameCount() : 0;
    if (count == firstCount) continue;
    const auto describe = [](const ViewSpec& v) {
      return v.sequence ? fmt::format("{} frames", v.sequence->frameCount()) : std::string("no sequence");
    };
    return fail(fmt::format("{}: view '{}' has {} but view '{}' has {}; every view needs a sequence of the same "
                            "number of frames",
                            file, view.name, describe(view), first.name, describe(first)));
  }
  return Ok{};
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

/// A sequence as the view file gives it (paths as pathForFile writes them).
ordered_json sequenceJson(const ViewSequence& sequence, const std::filesystem::path& folder) {
  if (sequence.multiFramePath.empty()) {
    ordered_json files = ordered_json::array();
    for (const std::filesystem::path& file : sequence.files) files.push_back(pathForFile(file, folder));
    return files;
  }
  ordered_json frames = sequence.allFrames ? ordered_json("all") : ordered_json::array({sequence.firstFrame, sequence.lastFrame});
  return ordered_json{{"path", pathForFile(sequence.multiFramePath, folder)}, {"frames", std::move(frames)}};
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
    readSequence(reader, folder, view, warnings);
    readDewarp(reader, folder, view);
    readCamera(reader, view);
    readSpheres(reader, view, warnings);
    if (!reader.ok()) return fail(reader.error());
    addWarnings(warnings, reader.unknownKeys({"name", "image", "detector", "source_to_detector_mm",
                                              "principal_point_px", "T_world_from_camera", "projection_matrix",
                                              "calibration_spheres_px", "dewarp", "sequence"}));
    addWarnings(warnings, reader.unknownKeys({"cols", "rows", "pixel_spacing_mm"}, "detector"));
    views.push_back(std::move(view));
  }
  if (Status counts = checkFrameCounts(views, file); !counts) return fail(counts.error());
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
    if (view.sequence) {
      v["sequence"] = sequenceJson(*view.sequence, folder);
    } else if (!view.imagePath.empty()) {
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
