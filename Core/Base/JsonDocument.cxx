#include "Base/JsonDocument.h"

#include <fmt/core.h>

#include <vector>

#include "Base/TextFile.h"

namespace fct {

namespace {

/// Tracks where the parser is (object keys and array indices) so a syntax error can name the key being read.
class KeyPathTracker {
 public:
  bool onEvent(nlohmann::json::parse_event_t event, const nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start: m_frames.push_back({false, 0, {}}); break;
      case Event::array_start: m_frames.push_back({true, 0, {}}); break;
      case Event::key: m_frames.back().key = parsed.get<std::string>(); break;
      case Event::object_end:
      case Event::array_end:
        m_frames.pop_back();
        advance();
        break;
      case Event::value: advance(); break;
    }
    return true;
  }

  /// E.g. "views[1].detector.cols"; empty at the top level.
  std::string path() const {
    std::string path;
    for (const Frame& frame : m_frames) {
      if (frame.isArray) {
        path += fmt::format("[{}]", frame.index);
      } else if (!frame.key.empty()) {
        if (!path.empty()) path += '.';
        path += frame.key;
      }
    }
    return path;
  }

 private:
  struct Frame {
    bool isArray;
    std::size_t index;
    std::string key;
  };
  void advance() {
    if (!m_frames.empty() && m_frames.back().isArray) ++m_frames.back().index;
  }
  std::vector<Frame> m_frames;
};

/// nlohmann's message without its "[json.exception.parse_error.101] " prefix.
std::string withoutExceptionId(const char* what) {
  std::string message = what;
  if (!message.empty() && message.front() == '[') {
    const auto end = message.find("] ");
    if (end != std::string::npos) message.erase(0, end + 2);
  }
  return message;
}

std::string dumpScalar(const nlohmann::ordered_json& value) {
  return value.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

void append(std::string& out, const nlohmann::ordered_json& value, int indent) {
  const auto newlineAndIndent = [&](int spaces) {
    out += '\n';
    out.append(static_cast<std::size_t>(spaces), ' ');
  };
  if (value.is_object() && !value.empty()) {
    out += '{';
    bool first = true;
    for (auto it = value.begin(); it != value.end(); ++it) {
      if (!first) out += ',';
      first = false;
      newlineAndIndent(indent + 2);
      out += dumpScalar(nlohmann::ordered_json(it.key()));
      out += ": ";
      append(out, it.value(), indent + 2);
    }
    newlineAndIndent(indent);
    out += '}';
  } else if (value.is_array() && !value.empty()) {
    bool flat = true;
    for (const auto& element : value) flat = flat && !element.is_structured();
    out += '[';
    bool first = true;
    for (const auto& element : value) {
      if (!first) out += flat ? ", " : ",";
      first = false;
      if (!flat) newlineAndIndent(indent + 2);
      append(out, element, indent + 2);
    }
    if (!flat) newlineAndIndent(indent);
    out += ']';
  } else {
    out += dumpScalar(value);
  }
}

}  // namespace

Result<nlohmann::json> JsonDocument::parseText(const std::string& text, const std::string& source) {
  KeyPathTracker tracker;
  try {
    return nlohmann::json::parse(
        text,
        [&tracker](int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
          return tracker.onEvent(event, parsed);
        },
        /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::exception& e) {  // parse_error, or out_of_range for numbers like 1e999
    std::string message = fmt::format("{}: not valid JSON: {}", source, withoutExceptionId(e.what()));
    if (const std::string key = tracker.path(); !key.empty()) message += fmt::format(" (while reading '{}')", key);
    if (message.find("invalid literal") != std::string::npos) {
      message += "; write numbers as plain finite decimals (JSON has no NaN or Infinity) and strings in double quotes";
    }
    return fail(message);
  }
}

Result<nlohmann::json> JsonDocument::parse(const std::filesystem::path& path) {
  auto text = TextFile::read(path);
  if (!text) return fail(text.error());
  return parseText(text.value(), path.string());
}

std::string JsonDocument::format(const nlohmann::ordered_json& document) {
  std::string out;
  append(out, document, 0);
  out += '\n';
  return out;
}

nlohmann::ordered_json JsonDocument::array(const Eigen::MatrixXd& matrix) {
  nlohmann::ordered_json result = nlohmann::ordered_json::array();
  if (matrix.cols() == 1) {
    for (int i = 0; i < matrix.rows(); ++i) result.push_back(matrix(i, 0));
    return result;
  }
  for (int r = 0; r < matrix.rows(); ++r) {
    nlohmann::ordered_json row = nlohmann::ordered_json::array();
    for (int c = 0; c < matrix.cols(); ++c) row.push_back(matrix(r, c));
    result.push_back(std::move(row));
  }
  return result;
}

Status JsonDocument::write(const nlohmann::ordered_json& document, const std::filesystem::path& path) {
  return TextFile::writeAtomically(path, format(document));
}

}  // namespace fct
