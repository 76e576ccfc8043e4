#include "pspslam/semantic/semantic_delay.h"

#include <charconv>
#include <optional>
#include <string_view>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

constexpr int kMaxDelayMs = 10000;

std::optional<int> parse_milliseconds(std::string_view text) {
  int value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value < 0 || value > kMaxDelayMs)
    return std::nullopt;
  return value;
}

}  // namespace

SemanticDelay parse_semantic_delay(const std::string& value, const std::string& flag) {
  const auto fail = [&]() -> Error {
    return Error(flag + " expects MS or random:MIN:MAX (whole milliseconds, 0-" +
                 std::to_string(kMaxDelayMs) + ", MIN <= MAX), got '" + value + "'");
  };
  constexpr std::string_view kRandom = "random:";
  const std::string_view text = value;
  if (!text.starts_with(kRandom)) {
    const std::optional<int> fixed = parse_milliseconds(text);
    if (!fixed) throw fail();
    return {*fixed, *fixed};
  }
  const std::string_view range = text.substr(kRandom.size());
  const size_t colon = range.find(':');
  if (colon == std::string_view::npos) throw fail();
  const std::optional<int> low = parse_milliseconds(range.substr(0, colon));
  const std::optional<int> high = parse_milliseconds(range.substr(colon + 1));
  if (!low || !high || *low > *high) throw fail();
  return {*low, *high};
}

SemanticDelayDraw::SemanticDelayDraw(const SemanticDelay& delay)
    : delay_(delay), generator_(delay.seed) {}

std::chrono::milliseconds SemanticDelayDraw::next() {
  if (delay_.min_ms >= delay_.max_ms) return std::chrono::milliseconds(delay_.max_ms);
  std::uniform_int_distribution<int> uniform(delay_.min_ms, delay_.max_ms);
  return std::chrono::milliseconds(uniform(generator_));
}

}  // namespace pspslam
