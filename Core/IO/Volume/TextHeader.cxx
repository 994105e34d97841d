#include "IO/Volume/TextHeader.h"

#include <fmt/core.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>

namespace fct {

std::string TextHeader::trim(std::string_view text) {
  const auto isSpace = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  while (!text.empty() && isSpace(text.front())) text.remove_prefix(1);
  while (!text.empty() && isSpace(text.back())) text.remove_suffix(1);
  return std::string(text);
}

std::string TextHeader::lower(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

Result<std::vector<double>> TextHeader::numbers(std::string_view text, std::size_t count, std::string_view field) {
  std::vector<double> values;
  const auto isSeparator = [](char c) {
    return std::isspace(static_cast<unsigned char>(c)) != 0 || c == ',' || c == '(' || c == ')';
  };
  std::size_t pos = 0;
  while (pos < text.size()) {
    if (isSeparator(text[pos])) {
      ++pos;
      continue;
    }
    std::size_t end = pos;
    while (end < text.size() && !isSeparator(text[end])) ++end;
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(text.data() + pos, text.data() + end, value);
    if (ec != std::errc() || ptr != text.data() + end || !std::isfinite(value)) {
      return fail(fmt::format("header field '{}' has '{}' where a finite number is expected", field,
                              text.substr(pos, end - pos)));
    }
    values.push_back(value);
    pos = end;
  }
  if (values.size() != count) {
    return fail(fmt::format("header field '{}' should hold {} numbers but holds {} ('{}')", field, count, values.size(),
                            trim(text)));
  }
  return values;
}

Result<std::array<int, 3>> TextHeader::sizes(std::string_view text, std::string_view field) {
  auto values = numbers(text, 3, field);
  if (!values.ok()) return fail(values.error());
  std::array<int, 3> sizes{};
  for (std::size_t a = 0; a < 3; ++a) {
    const double value = values.value()[a];
    if (value != std::floor(value) || std::abs(value) > std::numeric_limits<int>::max()) {
      return fail(fmt::format("header field '{}' has {:g} where a whole number of voxels (below 2^31) is expected",
                              field, value));
    }
    sizes[a] = static_cast<int>(value);
  }
  return sizes;
}

}  // namespace fct
