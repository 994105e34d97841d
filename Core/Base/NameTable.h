#pragma once
// NameTable: the names an enumeration is written with in files and messages ("ncc", "genetic", "ok", ...), the
// lookups both ways, and reading one from a JSON key. One table per enumeration, next to where it is read and written:
//   constexpr NameTable<SimilarityMetric, 3> kMetrics{{{"ncc", SimilarityMetric::Ncc}, ...}};

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "Base/JsonReader.h"

namespace fct {

/// Each value of an enumeration with its name.
template <typename Enum, std::size_t N>
using NameTable = std::array<std::pair<std::string_view, Enum>, N>;

/// The value named `text`, or nullopt when no entry has that name.
template <typename Enum, std::size_t N>
std::optional<Enum> valueNamed(std::string_view text, const NameTable<Enum, N>& names) {
  for (const auto& [name, value] : names) {
    if (text == name) return value;
  }
  return std::nullopt;
}

/// The name of `value`, or "unknown" when the table lacks it.
template <typename Enum, std::size_t N>
std::string_view nameOf(Enum value, const NameTable<Enum, N>& names) {
  for (const auto& [name, v] : names) {
    if (v == value) return name;
  }
  return "unknown";
}

/// The names of a table, comma-separated, for messages ("ncc, vlnc, gc").
template <typename Enum, std::size_t N>
std::string namesOf(const NameTable<Enum, N>& names) {
  std::vector<std::string_view> accepted;
  for (const auto& entry : names) accepted.push_back(entry.first);
  return fmt::format("{}", fmt::join(accepted, ", "));
}

/// The value named by the string at `key`; nullopt when the key is bad or names no entry, which the reader then
/// records as "key '<key>' is '<text>'; use <accepted>" (`accepted` lists the names for a person, e.g. "'a' or 'b'").
template <typename Enum, std::size_t N>
std::optional<Enum> readNamed(JsonReader& reader, std::string_view key, const NameTable<Enum, N>& names,
                              std::string_view accepted) {
  const std::string text = reader.string(key);
  if (!reader.ok()) return std::nullopt;
  if (const std::optional<Enum> value = valueNamed(text, names)) return value;
  reader.rejectKey(key, fmt::format("is '{}'; use {}", text, accepted));
  return std::nullopt;
}

}  // namespace fct
