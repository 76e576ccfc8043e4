#include "pspslam/io/text_lines.h"

#include <charconv>
#include <cmath>
#include <fstream>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

bool is_separator(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; }

}  // namespace

std::string line_prefix(const std::filesystem::path& file, size_t line) {
  return file.string() + ":" + std::to_string(line) + ": ";
}

void for_each_data_line(const std::filesystem::path& file, const std::string& what,
                        const std::function<void(const TextLine&)>& visit) {
  std::ifstream stream(file);
  if (!stream) throw Error(file.string() + ": cannot open " + what);
  std::string text;
  TextLine parsed;
  while (std::getline(stream, text)) {
    ++parsed.line;
    parsed.fields.clear();
    const std::string_view view(text);
    size_t i = 0;
    while (i < view.size()) {
      while (i < view.size() && is_separator(view[i])) ++i;
      const size_t begin = i;
      while (i < view.size() && !is_separator(view[i])) ++i;
      if (i > begin) parsed.fields.push_back(view.substr(begin, i - begin));
    }
    if (parsed.fields.empty() || parsed.fields.front().front() == '#') continue;
    visit(parsed);
  }
  if (stream.bad()) throw Error(file.string() + ": read error in " + what);
}

double parse_number(std::string_view text, const std::filesystem::path& file, size_t line,
                    const std::string& name) {
  double value = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end) {
    throw Error(line_prefix(file, line) + name + " '" + std::string(text) + "' is not a number");
  }
  if (!std::isfinite(value)) {
    throw Error(line_prefix(file, line) + name + " '" + std::string(text) + "' is not finite");
  }
  return value;
}

}  // namespace pspslam
