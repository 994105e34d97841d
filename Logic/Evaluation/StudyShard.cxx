#include "Evaluation/StudyShard.h"

#include <fmt/format.h>

#include <charconv>
#include <system_error>

namespace fct {

namespace {

/// Parses all of `text` as a decimal int; false on anything else.
bool parseWhole(std::string_view text, int& out) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return !text.empty() && ec == std::errc() && end == text.data() + text.size();
}

}  // namespace

Result<StudyShard> StudyShard::create(const StudyDefinition& study, int index, int count) {
  if (count < 1 || count > kMaxCount || index < 1 || index > count) {
    return fail(fmt::format("shard {}/{} does not exist: a shard is K/N with 1 <= K <= N <= {}", index, count,
                            kMaxCount));
  }
  StudyShard shard;
  shard.m_index = index;
  shard.m_count = count;
  long position = 0;
  for (const StudyCondition& c : study.conditions) {
    shard.m_firstPosition.emplace(c.name, position);
    position += c.trials;
  }
  shard.m_totalTrials = position;
  return shard;
}

Result<StudyShard> StudyShard::parse(const StudyDefinition& study, std::string_view text) {
  const std::size_t slash = text.find('/');
  int index = 0, count = 0;
  if (slash == std::string_view::npos || !parseWhole(text.substr(0, slash), index) ||
      !parseWhole(text.substr(slash + 1), count)) {
    return fail(fmt::format("shard '{}' is not of the form K/N (e.g. 2/8: the second of 8 shards)", text));
  }
  return create(study, index, count);
}

std::string StudyShard::text() const { return fmt::format("{}/{}", m_index, m_count); }

int StudyShard::shardOf(const std::string& condition, int trial) const {
  const auto found = m_firstPosition.find(condition);
  if (found == m_firstPosition.end() || trial < 0) return 0;
  return static_cast<int>((found->second + trial) % m_count) + 1;
}

}  // namespace fct
