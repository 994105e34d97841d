#include "IO/Xray/XrayImageFileReader.h"

#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace fct {

namespace {

/// True when the file starts with the signature of its format (PNG: 89 'PNG' 0D 0A 1A 0A; TIFF: "II*\0", "MM\0*", or
/// BigTIFF "II+\0", "MM\0+"). OpenCV picks its decoder from the content, not the name: without this check a file
/// named .png holding, say, DICOM bytes reaches a decoder (GDCM) that aborts the program on damaged input.
bool hasSignature(const std::filesystem::path& path, const std::string& modality) {
  std::ifstream file(path, std::ios::binary);
  char head[8] = {};
  file.read(head, sizeof head);
  const std::string bytes(head, static_cast<std::size_t>(file.gcount()));
  if (modality == "PNG") return bytes == std::string("\x89PNG\r\n\x1a\n", 8);
  const std::string first4 = bytes.substr(0, 4);
  for (const char* tiff : {"II*\0", "MM\0*", "II+\0", "MM\0+"}) {
    if (first4 == std::string(tiff, 4)) return true;
  }
  return false;
}

/// True when every pixel has equal B, G and R values (a grey image stored as colour).
bool channelsEqual(const cv::Mat& bgr) {
  std::vector<cv::Mat> planes;
  cv::split(bgr, planes);
  return cv::countNonZero(planes[0] != planes[1]) == 0 && cv::countNonZero(planes[1] != planes[2]) == 0;
}

}  // namespace

Result<XrayImage> XrayImageFileReader::read(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::string modality;
  if (extension == ".png") {
    modality = "PNG";
  } else if (extension == ".tif" || extension == ".tiff") {
    modality = "TIFF";
  } else {
    return fail(fmt::format("'{}' is not a PNG or TIFF file (extension '{}'); DICOM X-rays go through the DICOM reader",
                            path.filename().string(), extension));
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fail(fmt::format("X-ray file '{}' does not exist", path.string()));

  if (!hasSignature(path, modality)) {
    return fail(fmt::format("'{}' is not a {} file: it does not start with the {} signature (damaged, or another format "
                            "under a .{} name)",
                            path.filename().string(), modality, modality, extension.substr(1)));
  }
  std::vector<std::string> warnings;
  cv::Mat grey;
  try {
    cv::Mat loaded = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    if (loaded.empty()) {
      return fail(fmt::format("cannot decode '{}' as {}; the file may be truncated or not an image",
                              path.filename().string(), modality));
    }
    if (loaded.channels() == 1) {
      grey = loaded;
    } else if (loaded.channels() == 3 || loaded.channels() == 4) {
      cv::Mat bgr;
      if (loaded.channels() == 4) {
        cv::cvtColor(loaded, bgr, cv::COLOR_BGRA2BGR);
        warnings.push_back(fmt::format("'{}': alpha channel ignored", path.filename().string()));
      } else {
        bgr = loaded;
      }
      if (channelsEqual(bgr)) {
        cv::extractChannel(bgr, grey, 0);
      } else {
        cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
        warnings.push_back(fmt::format("'{}' is a colour image; converted to grey (luma 0.299 R + 0.587 G + 0.114 B)",
                                       path.filename().string()));
      }
    } else {
      return fail(fmt::format("'{}' has {} channels; expected a grey-scale or RGB image", path.filename().string(),
                              loaded.channels()));
    }
  } catch (const cv::Exception& e) {
    return fail(fmt::format("cannot read '{}': {}", path.filename().string(), e.what()));
  }

  XrayImage image;
  switch (grey.depth()) {
    case CV_8U: image.bitsStored = 8; break;
    case CV_16U: image.bitsStored = 16; break;
    case CV_32F: image.bitsStored = 32; break;
    default:
      return fail(fmt::format("'{}' has an unsupported pixel type (OpenCV depth {}); use unsigned 8- or 16-bit grey "
                              "or float32 TIFF",
                              path.filename().string(), grey.depth()));
  }
  image.cols = grey.cols;
  image.rows = grey.rows;
  image.photometric = "MONOCHROME2";
  image.modality = modality;
  image.sourcePath = path.string();
  image.pixels.resize(static_cast<std::size_t>(grey.cols) * grey.rows);
  cv::Mat wrapped(grey.rows, grey.cols, CV_32F, image.pixels.data());
  grey.convertTo(wrapped, CV_32F);
  if (!std::all_of(image.pixels.begin(), image.pixels.end(), [](float v) { return std::isfinite(v); })) {
    return fail(fmt::format("'{}' contains NaN or infinite pixel values", path.filename().string()));
  }
  Result<XrayImage> result(std::move(image));
  for (auto& w : warnings) result.addWarning(std::move(w));
  return result;
}

}  // namespace fct
