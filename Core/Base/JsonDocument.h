#pragma once
// JsonDocument: reading a JSON file with errors a person can act on (file, line, column and the key being read),
// and writing one atomically in a layout people can edit (numeric arrays and matrix rows on one line).

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "Base/Result.h"

namespace fct {

/// Parsing and writing the project's JSON files. `//` and `/* */` comments are accepted on read.
class JsonDocument {
 public:
  /// Parses a JSON file. A syntax error (including NaN or Infinity, which JSON does not allow) names the file,
  /// line, column and the key path being read, e.g. "views[0].source_to_detector_mm".
  static Result<nlohmann::json> parse(const std::filesystem::path& path);

  /// Parses JSON text; `source` names it in error messages (usually the file path).
  static Result<nlohmann::json> parseText(const std::string& text, const std::string& source);

  /// Text of a document, indented by 2, with arrays of numbers or strings kept on one line; keys in insertion order.
  static std::string format(const nlohmann::ordered_json& document);

  /// A matrix as an array of rows (a vector, i.e. one column, as a flat array).
  static nlohmann::ordered_json array(const Eigen::MatrixXd& matrix);

  /// Writes format(document) to `path` atomically (temporary file + rename); fails naming the path.
  static Status write(const nlohmann::ordered_json& document, const std::filesystem::path& path);
};

}  // namespace fct
