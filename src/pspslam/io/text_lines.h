#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace pspslam {

// One data line of a TUM-style text file, split into fields. Fields are separated by spaces,
// tabs or commas (the TUM tools accept all three); `line` is 1-based for error messages.
struct TextLine {
  size_t line = 0;
  std::vector<std::string_view> fields;
};

// Calls `visit` for every line of `file` that is neither blank nor a `#` comment.
// Throws pspslam::Error "<file>: cannot open <what>" when the file cannot be read.
void for_each_data_line(const std::filesystem::path& file, const std::string& what,
                        const std::function<void(const TextLine&)>& visit);

// Parses a complete field as a finite double; throws "<file>:<line>: <name> '<text>' is not a
// number" (or "... is not finite").
double parse_number(std::string_view text, const std::filesystem::path& file, size_t line,
                    const std::string& name);

// "<file>:<line>: " — the prefix of every line-level error message.
std::string line_prefix(const std::filesystem::path& file, size_t line);

}  // namespace pspslam
