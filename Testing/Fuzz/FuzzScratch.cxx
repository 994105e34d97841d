#include "FuzzScratch.h"

#include <unistd.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <vector>

#include "Geometry/Camera.h"
#include "Image/FloatImage.h"
#include "Image/Volume.h"
#include "IO/Project/LandmarkFile.h"
#include "IO/Project/ViewFile.h"
#include "IO/Volume/VolumeFileIO.h"
#include "IO/Xray/ImageFileWriter.h"

namespace fct::fuzz {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void abortWith(const std::string& message) {
  std::fprintf(stderr, "fuzz: %s\n", message.c_str());
  std::abort();
}

template <typename T>
void requireOk(const Result<T>& result, const char* what) {
  if (!result.ok()) abortWith(std::string(what) + ": " + result.error());
}

/// An 8^3 CT of 2 mm voxels, a ball of bone in water, centred on the world origin.
void writeFixtureCt(const fs::path& path) {
  const Eigen::Vector3d origin_mm(-7.0, -7.0, -7.0);
  auto ct = Volume::create({8, 8, 8}, {2.0, 2.0, 2.0}, origin_mm, Eigen::Matrix3d::Identity(), -1000.0f);
  requireOk(ct, "fixture CT");
  for (int k = 2; k < 6; ++k)
    for (int j = 2; j < 6; ++j)
      for (int i = 2; i < 6; ++i) ct.value().at(i, j, k) = 1000.0f;
  requireOk(VolumeFileIO::write(ct.value(), path), "fixture CT");
}

/// Two 16x12 views (AP and lateral) of the fixture CT, with their images, as a view file.
void writeFixtureViews(const fs::path& folder) {
  const Eigen::Matrix3d R_ap = (Eigen::Matrix3d() << 1, 0, 0, 0, 0, -1, 0, 1, 0).finished();
  const Eigen::Matrix3d R_lateral = Eigen::AngleAxisd(EIGEN_PI / 2, Eigen::Vector3d::UnitZ()) * R_ap;
  std::vector<ViewSpec> views;
  for (const auto& [name, R] : std::vector<std::pair<std::string, Eigen::Matrix3d>>{{"ap", R_ap}, {"lateral", R_lateral}}) {
    ViewSpec view;
    view.name = name;
    view.camera = Camera::lookingAt(Eigen::Vector3d::Zero(), R, 1000.0, 1500.0, 16, 12, 2.0);
    view.imagePath = folder / (name + ".png");
    FloatImage image = FloatImage::filled(16, 12, 30000.0f);
    for (int row = 4; row < 8; ++row)
      for (int col = 6; col < 10; ++col) image.pixels[static_cast<std::size_t>(row) * 16 + col] = 10000.0f;
    requireOk(ImageFileWriter::writePng16(image, view.imagePath, 0.0f, 65535.0f), "fixture image");
    views.push_back(std::move(view));
  }
  requireOk(ViewFile::write(views, folder / FuzzScratch::kViewFile), "fixture view file");
}

/// Four CT landmarks and their clicks in both views.
void writeFixtureLandmarks(const fs::path& folder) {
  const std::vector<CtLandmark> ct{{"a", {-4, -4, -4}}, {"b", {4, -4, -4}}, {"c", {-4, 4, 4}}, {"d", {4, 4, 0}}};
  requireOk(LandmarkFile::writeCt(ct, folder / FuzzScratch::kCtLandmarkFile), "fixture CT landmarks");
  std::map<std::string, std::vector<ImageLandmark>> clicks;
  for (const char* view : {"ap", "lateral"})
    clicks[view] = {{"a", {5, 4}}, {"b", {10, 4}}, {"c", {5, 8}}, {"d", {10, 7}}};
  requireOk(LandmarkFile::writeImage(clicks, folder / FuzzScratch::kImageLandmarkFile), "fixture X-ray landmarks");
}

fs::path makeFolder() {
  const fs::path shm = "/dev/shm";
  std::error_code ec;
  const fs::path base = fs::is_directory(shm, ec) ? shm : fs::temp_directory_path();
  const char* named = std::getenv("FCT_FUZZ_SCRATCH");  // scripts/fuzz.sh names it, to remove it after a crash
  const fs::path folder = named && *named ? fs::path(named) : base / ("fluoroct-fuzz-" + std::to_string(::getpid()));
  fs::remove_all(folder, ec);
  if (!fs::create_directories(folder, ec)) abortWith("cannot create the scratch folder " + folder.string());
  writeFixtureCt(folder / FuzzScratch::kCtFile);
  writeFixtureViews(folder);
  writeFixtureLandmarks(folder);
  return folder;
}

const fs::path* g_folder = nullptr;

void removeFolder() {
  std::error_code ec;
  if (g_folder) fs::remove_all(*g_folder, ec);
}

}  // namespace

const fs::path& FuzzScratch::folder() {
  static const fs::path folder = makeFolder();
  // Registered after `folder` is made, so that it runs before `folder` is destroyed.
  [[maybe_unused]] static const bool removedAtExit = (g_folder = &folder, std::atexit(removeFolder) == 0);
  return folder;
}

fs::path FuzzScratch::write(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const fs::path path = folder() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) abortWith("cannot write " + path.string());
  return path;
}

void FuzzScratch::require(bool condition, const char* what) {
  if (!condition) abortWith(std::string("contract broken: ") + what);
}

}  // namespace fct::fuzz
