#include "IO/Project/DewarpFile.h"

#include <fmt/core.h>

#include <cmath>

#include "Base/JsonDocument.h"
#include "Base/JsonReader.h"

namespace fct {

namespace {

constexpr const char* kFormat = "fluoroct-dewarp";
constexpr const char* kModel = "polynomial";

/// The calibration record (every key optional: the field does not depend on it).
DewarpCalibration readCalibration(const nlohmann::json& root) {
  DewarpCalibration c;
  const auto found = root.find("calibration");
  if (found == root.end() || !found->is_object()) return c;
  const auto number = [&](const char* key) {
    const auto value = found->find(key);
    return value != found->end() && value->is_number() ? value->get<double>() : 0.0;
  };
  if (const auto image = found->find("grid_image"); image != found->end() && image->is_string()) {
    c.gridImage = image->get<std::string>();
  }
  c.pitch_mm = number("pitch_mm");
  c.latticePitch_px = number("lattice_pitch_px");
  c.latticeRotation_deg = number("lattice_rotation_deg");
  c.magnification = number("magnification");
  c.beadCount = static_cast<int>(number("beads"));
  c.rejectedBeadCount = static_cast<int>(number("rejected_beads"));
  c.rmsResidual_px = number("rms_residual_px");
  c.maxResidual_px = number("max_residual_px");
  return c;
}

}  // namespace

Result<DewarpFileContents> DewarpFile::read(const std::filesystem::path& path) {
  auto document = JsonDocument::parse(path);
  if (!document) return fail(document.error());
  const nlohmann::json& root = document.value();
  JsonReader reader(root, path.string());
  reader.formatVersion(kFormat, "dewarp file", kVersion);
  const Eigen::VectorXd size = reader.vector("image_size", 2);
  const std::string model = reader.string("model");
  if (reader.ok() && model != kModel) {
    reader.rejectKey("model", fmt::format("is '{}'; this program reads the '{}' model", model, kModel));
  }
  const int degree = reader.integer("degree", DewarpField::kMinDegree);
  if (reader.ok() && degree > DewarpField::kMaxDegree) {
    reader.rejectKey("degree", fmt::format("is {}; the highest supported degree is {}", degree, DewarpField::kMaxDegree));
  }
  if (reader.ok() && (size.x() < 1 || size.y() < 1 || size.x() != std::floor(size.x()) || size.y() != std::floor(size.y()))) {
    reader.rejectKey("image_size", fmt::format("must be two positive whole numbers [cols, rows], got [{}, {}]",
                                               size.x(), size.y()));
  }
  if (!reader.ok()) return fail(reader.error());

  const auto terms = DewarpField::terms(degree);
  const int count = static_cast<int>(terms.size());
  const Eigen::MatrixXd storedTerms = reader.matrix("terms", count, 2);
  const Eigen::VectorXd col_px = reader.vector("col_coefficients_px", count);
  const Eigen::VectorXd row_px = reader.vector("row_coefficients_px", count);
  const Eigen::VectorXd centre_px = reader.vector("centre_px", 2);
  const double radius_px = reader.positiveNumber("radius_px");
  if (!reader.ok()) return fail(reader.error());
  for (int t = 0; t < count; ++t) {
    if (storedTerms(t, 0) != terms[t][0] || storedTerms(t, 1) != terms[t][1]) {
      return fail(fmt::format("{}: key 'terms' row {} is [{}, {}] but a degree-{} field has [{}, {}] there; the file "
                              "was not written by FluoroCT or was edited",
                              path.string(), t, storedTerms(t, 0), storedTerms(t, 1), degree, terms[t][0], terms[t][1]));
    }
  }
  auto field = DewarpField::create(static_cast<int>(size.x()), static_cast<int>(size.y()), degree, col_px, row_px);
  if (!field) return fail(fmt::format("{}: {}", path.string(), field.error()));
  if ((centre_px - field.value().centre_px()).norm() > 1e-6 || std::abs(radius_px - field.value().radius_px()) > 1e-6) {
    return fail(fmt::format("{}: centre_px [{}, {}] and radius_px {} are not those of a {}x{} image ([{}, {}], {}); "
                            "the file was edited or its image_size is wrong",
                            path.string(), centre_px.x(), centre_px.y(), radius_px, field.value().cols(),
                            field.value().rows(), field.value().centre_px().x(), field.value().centre_px().y(),
                            field.value().radius_px()));
  }
  Result<DewarpFileContents> result(DewarpFileContents{std::move(field).value(), readCalibration(root)});
  for (std::string& warning :
       reader.unknownKeys({"format", "version", "image_size", "model", "degree", "centre_px", "radius_px", "terms",
                           "col_coefficients_px", "row_coefficients_px", "calibration"})) {
    result.addWarning(std::move(warning));
  }
  return result;
}

Status DewarpFile::write(const DewarpFileContents& contents, const std::filesystem::path& path) {
  const DewarpField& f = contents.field;
  const DewarpCalibration& c = contents.calibration;
  nlohmann::ordered_json terms = nlohmann::ordered_json::array();
  for (const auto& term : DewarpField::terms(f.degree())) terms.push_back({term[0], term[1]});
  nlohmann::ordered_json document;
  document["format"] = kFormat;
  document["version"] = kVersion;
  document["image_size"] = {f.cols(), f.rows()};
  document["model"] = kModel;
  document["degree"] = f.degree();
  document["centre_px"] = JsonDocument::array(f.centre_px());
  document["radius_px"] = f.radius_px();
  document["terms"] = std::move(terms);
  document["col_coefficients_px"] = JsonDocument::array(f.colCoefficients_px());
  document["row_coefficients_px"] = JsonDocument::array(f.rowCoefficients_px());
  document["calibration"] = {{"grid_image", c.gridImage},
                             {"pitch_mm", c.pitch_mm},
                             {"lattice_pitch_px", c.latticePitch_px},
                             {"lattice_rotation_deg", c.latticeRotation_deg},
                             {"magnification", c.magnification},
                             {"beads", c.beadCount},
                             {"rejected_beads", c.rejectedBeadCount},
                             {"rms_residual_px", c.rmsResidual_px},
                             {"max_residual_px", c.maxResidual_px}};
  return JsonDocument::write(document, path);
}

}  // namespace fct
