#include "Base/JsonReader.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace fct {

JsonReader::JsonReader(const nlohmann::json& object, std::string where) : m_object(object), m_where(std::move(where)) {
  if (!m_object.is_object()) reject(fmt::format("must be a JSON object {{...}}, got {}", describe(m_object)));
}

const nlohmann::json* JsonReader::find(std::string_view key) const {
  const nlohmann::json* node = &m_object;
  std::size_t start = 0;
  while (true) {
    if (!node->is_object()) return nullptr;
    const std::size_t dot = key.find('.', start);
    const std::string part(key.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start));
    const auto it = node->find(part);
    if (it == node->end() || it->is_null()) return nullptr;
    node = &*it;
    if (dot == std::string_view::npos) return node;
    start = dot + 1;
  }
}

bool JsonReader::has(std::string_view key) const { return find(key) != nullptr; }

const nlohmann::json* JsonReader::required(std::string_view key) {
  if (!ok()) return nullptr;
  const nlohmann::json* value = find(key);
  if (!value) rejectKey(key, "is missing");
  return value;
}

std::string JsonReader::string(std::string_view key) {
  const nlohmann::json* value = required(key);
  if (!value) return {};
  if (!value->is_string()) {
    rejectKey(key, fmt::format("must be a string in double quotes, got {}", describe(*value)));
    return {};
  }
  std::string text = value->get<std::string>();
  if (text.empty()) rejectKey(key, "must not be empty");
  return text;
}

bool JsonReader::boolean(std::string_view key) {
  const nlohmann::json* value = required(key);
  if (!value) return false;
  if (!value->is_boolean()) {
    rejectKey(key, fmt::format("must be true or false, got {}", describe(*value)));
    return false;
  }
  return value->get<bool>();
}

double JsonReader::numberAt(const nlohmann::json& value, std::string_view key) {
  if (!value.is_number()) {
    rejectKey(key, fmt::format("must be a number, got {}", describe(value)));
    return 0.0;
  }
  const double number = value.get<double>();
  if (!std::isfinite(number)) {
    rejectKey(key, fmt::format("must be a finite number, got {}", number));
    return 0.0;
  }
  return number;
}

double JsonReader::number(std::string_view key) {
  const nlohmann::json* value = required(key);
  return value ? numberAt(*value, key) : 0.0;
}

double JsonReader::positiveNumber(std::string_view key) {
  const double value = number(key);
  if (ok() && value <= 0.0) {
    rejectKey(key, fmt::format("must be positive, got {}", value));
    return 0.0;
  }
  return value;
}

int JsonReader::integer(std::string_view key, int minimum) {
  const nlohmann::json* value = required(key);
  if (!value) return 0;
  const double number = numberAt(*value, key);
  if (!ok()) return 0;
  if (number != std::floor(number) || number < minimum || number > 1e9) {
    rejectKey(key, fmt::format("must be a whole number >= {}, got {}", minimum, describe(*value)));
    return 0;
  }
  return static_cast<int>(number);
}

Eigen::VectorXd JsonReader::vector(std::string_view key, int size) {
  Eigen::VectorXd result = Eigen::VectorXd::Zero(size);
  const nlohmann::json* value = required(key);
  if (!value) return result;
  if (!value->is_array() || value->size() != static_cast<std::size_t>(size)) {
    rejectKey(key, fmt::format("must be an array of {} numbers, got {}", size, describe(*value)));
    return result;
  }
  for (int i = 0; i < size && ok(); ++i) {
    result[i] = numberAt((*value)[static_cast<std::size_t>(i)], fmt::format("{}[{}]", key, i));
  }
  if (!ok()) result.setZero();
  return result;
}

Eigen::MatrixXd JsonReader::matrix(std::string_view key, int rows, int cols) {
  Eigen::MatrixXd result = Eigen::MatrixXd::Zero(rows, cols);
  const nlohmann::json* value = required(key);
  if (!value) return result;
  const auto isRow = [cols](const nlohmann::json& row) {
    return row.is_array() && row.size() == static_cast<std::size_t>(cols);
  };
  if (!value->is_array() || value->size() != static_cast<std::size_t>(rows) ||
      !std::all_of(value->begin(), value->end(), isRow)) {
    rejectKey(key, fmt::format("must be {} rows of {} numbers ([[...], [...], ...]), got {}", rows, cols,
                               describe(*value)));
    return result;
  }
  for (int r = 0; r < rows && ok(); ++r) {
    for (int c = 0; c < cols && ok(); ++c) {
      result(r, c) = numberAt((*value)[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)],
                              fmt::format("{}[{}][{}]", key, r, c));
    }
  }
  if (!ok()) result.setZero();
  return result;
}

const nlohmann::json* JsonReader::array(std::string_view key, std::string_view what) {
  const nlohmann::json* value = required(key);
  if (!value || value->is_array()) return value;
  rejectKey(key, fmt::format("must be {}, got {}", what, describe(*value)));
  return nullptr;
}

const nlohmann::json* JsonReader::object(std::string_view key, std::string_view what) {
  const nlohmann::json* value = required(key);
  if (!value || value->is_object()) return value;
  rejectKey(key, fmt::format("must be {}, got {}", what, describe(*value)));
  return nullptr;
}

int JsonReader::formatVersion(std::string_view format, std::string_view kind, int newest) {
  const std::string stored = string("format");
  if (ok() && stored != format) {
    rejectKey("format", fmt::format("is '{}', not '{}': this is not a FluoroCT {}", stored, format, kind));
  }
  const int version = integer("version", 1);
  if (ok() && version > newest) {
    rejectKey("version", fmt::format("is {}; this program reads versions 1 to {} (update FluoroCT)", version, newest));
  }
  return ok() ? version : 0;
}

void JsonReader::rejectKey(std::string_view key, std::string_view problem) {
  reject(fmt::format("key '{}' {}", key, problem));
}

void JsonReader::reject(std::string_view problem) {
  if (ok()) m_error = fmt::format("{}: {}", m_where, problem);
}

void JsonReader::adoptError(const JsonReader& inner) {
  if (ok()) m_error = inner.error();
}

std::vector<std::string> JsonReader::unknownKeys(std::initializer_list<std::string_view> known,
                                                 std::string_view objectKey) const {
  std::vector<std::string> warnings;
  const nlohmann::json* object = objectKey.empty() ? &m_object : find(objectKey);
  if (!object || !object->is_object()) return warnings;
  for (auto it = object->begin(); it != object->end(); ++it) {
    if (std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
    const std::string name = objectKey.empty() ? it.key() : fmt::format("{}.{}", objectKey, it.key());
    warnings.push_back(fmt::format("{}: unknown key '{}' ignored", m_where, name));
  }
  return warnings;
}

std::string JsonReader::describe(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null: return "null";
    case nlohmann::json::value_t::string:
      return fmt::format("the string {}", value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
    case nlohmann::json::value_t::array: return fmt::format("an array of {} values", value.size());
    case nlohmann::json::value_t::object: return "an object";
    default: return value.dump();
  }
}

}  // namespace fct
