#pragma once

#include <CLI/CLI.hpp>

#include <charconv>
#include <sstream>
#include <string>
#include <type_traits>

namespace pspslam::cli {

// A CLI11 check for a numeric flag: the text must be a whole number of type T (or a real number
// for floating T) within [low, high]. Messages name the range and what was typed, e.g.
// "--mask-margin: must be an integer in [0, 100], got '1000000000'".
template <typename T>
CLI::Validator in_range(T low, T high) {
  std::ostringstream range;
  range << "[" << low << ", " << high << "]";
  const std::string kind =
      std::string(std::is_floating_point_v<T> ? "a number" : "an integer") + " in " + range.str();
  return CLI::Validator(
      [low, high, kind](std::string& text) -> std::string {
        T value{};
        const char* end = text.data() + text.size();
        const auto [stop, status] = std::from_chars(text.data(), end, value);
        if (text.empty() || status != std::errc() || stop != end || !(value >= low) ||
            !(value <= high)) {
          return "must be " + kind + ", got '" + text + "'";
        }
        return {};
      },
      range.str());
}

}  // namespace pspslam::cli
