#pragma once
// JsonReader: checked reads of keys of one JSON object, with messages that name the place ("views.json: view
// 'AP'") and the key ("detector.cols"). The first error wins and later reads return zeros, so a reader of a whole
// object is a sequence of reads followed by one ok() check.

#include <Eigen/Core>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace fct {

/// Checked access to the keys of a JSON object. Keys may be dotted paths into nested objects ("detector.cols").
class JsonReader {
 public:
  /// Reads `object`; `where` prefixes every message. Records an error at once if `object` is not a JSON object.
  JsonReader(const nlohmann::json& object, std::string where);

  /// True if the key is present (and not null).
  bool has(std::string_view key) const;
  /// The value at the key, or nullptr if absent or null.
  const nlohmann::json* find(std::string_view key) const;

  /// A required non-empty string; "" after an error.
  std::string string(std::string_view key);
  /// A required true or false; false after an error.
  bool boolean(std::string_view key);
  /// A required finite number; 0 after an error.
  double number(std::string_view key);
  /// A required finite number > 0; 0 after an error.
  double positiveNumber(std::string_view key);
  /// A required integer >= minimum (800 and 800.0 both accepted); 0 after an error.
  int integer(std::string_view key, int minimum);
  /// A required array of `size` finite numbers; zeros after an error.
  Eigen::VectorXd vector(std::string_view key, int size);
  /// A required array of `rows` arrays of `cols` finite numbers each (row-major); zeros after an error.
  Eigen::MatrixXd matrix(std::string_view key, int rows, int cols);
  /// A required JSON array; `what` describes it in the message ("an array of stage reports"). nullptr after an error.
  const nlohmann::json* array(std::string_view key, std::string_view what);
  /// A required JSON object; `what` describes it in the message ("an object {<view>: fraction}"). nullptr after an
  /// error.
  const nlohmann::json* object(std::string_view key, std::string_view what);
  /// The file-type keys of a FluoroCT file: "format" must be `format` and "version" a whole number from 1 to `newest`.
  /// Returns the version; 0 after an error, which names the file type `kind` ("Studio session file") or says to
  /// update FluoroCT for a newer version.
  int formatVersion(std::string_view format, std::string_view kind, int newest);

  /// Records "<where>: key '<key>' <problem>" unless an error is already recorded.
  void rejectKey(std::string_view key, std::string_view problem);
  /// Records "<where>: <problem>" unless an error is already recorded.
  void reject(std::string_view problem);

  /// Takes over the error of a reader of a nested value (its message already names the place), if any.
  void adoptError(const JsonReader& inner);

  /// True while no read has failed.
  bool ok() const { return m_error.empty(); }
  /// The first error message; empty when ok().
  const std::string& error() const { return m_error; }
  /// The place prefix given at construction.
  const std::string& where() const { return m_where; }

  /// Warnings "<where>: unknown key 'x' ignored" for the keys of the object (or of the nested object at
  /// `objectKey`) that are not in `known`.
  std::vector<std::string> unknownKeys(std::initializer_list<std::string_view> known,
                                       std::string_view objectKey = {}) const;

  /// A short description of a JSON value for messages: `the string "abc"`, `null`, `an array of 3 values`, `12.5`.
  static std::string describe(const nlohmann::json& value);

 private:
  /// The finite number in `value`, or records an error naming `key` and returns 0.
  double numberAt(const nlohmann::json& value, std::string_view key);
  /// The value at a required key, or records "is missing" and returns nullptr.
  const nlohmann::json* required(std::string_view key);

  const nlohmann::json& m_object;
  std::string m_where;
  std::string m_error;
};

}  // namespace fct
