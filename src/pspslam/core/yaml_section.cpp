#include "pspslam/core/yaml_section.h"

#include <vector>

#include "pspslam/core/suggest.h"

namespace pspslam {

YamlSection::YamlSection(const YAML::Node& node, std::string file, std::string path)
    : node_(node), file_(std::move(file)), path_(std::move(path)) {
  if (node_ && !node_.IsNull() && !node_.IsMap()) {
    const YAML::Mark mark = node_.Mark();
    std::string where = file_;
    if (!mark.is_null()) where.append(":").append(std::to_string(mark.line + 1));
    throw Error(where + ": '" + (path_.empty() ? std::string("<root>") : path_) +
                "' must be a mapping of key: value");
  }
}

bool YamlSection::contains(const std::string& key) const {
  return node_ && node_.IsMap() && node_[key];
}

std::string YamlSection::where(const std::string& key) const {
  if (!contains(key)) return file_ + ": ";
  return file_ + ":" + std::to_string(node_[key].Mark().line + 1) + ": ";
}

Error YamlSection::invalid(const std::string& key, const std::string& what) const {
  return Error(where(key) + "key '" + qualified(key) + "' " + what);
}

YamlSection YamlSection::section(const std::string& key) {
  used_.insert(key);
  const YAML::Node child = node_ && node_.IsMap() ? node_[key] : YAML::Node();
  return YamlSection(child, file_, qualified(key));
}

std::string YamlSection::key_name(const YAML::Node& key) const {
  // A key may be any YAML node ("? [a, b]: 1"); ours are plain names (found by
  // fuzz/fuzz_segmenter_metadata: converting such a key threw a yaml-cpp exception).
  if (!key.IsScalar()) {
    throw Error(file_ + ":" + std::to_string(key.Mark().line + 1) + ": a key must be a plain name" +
                (path_.empty() ? "" : " (in '" + path_ + "')"));
  }
  return key.Scalar();
}

void YamlSection::finish() const {
  if (!node_ || !node_.IsMap()) return;
  const std::vector<std::string> valid(used_.begin(), used_.end());
  for (const auto& entry : node_) {
    const std::string key = key_name(entry.first);
    if (!used_.count(key)) throw unknown_key(entry.first, nearest(key, valid));
  }
}

void YamlSection::throw_missing(const std::string& key) const {
  // A required key is most often "missing" because it was mistyped: name the typo, not only
  // the key that was expected.
  if (node_ && node_.IsMap()) {
    for (const auto& entry : node_) {
      const std::string present = key_name(entry.first);
      if (!used_.count(present) && nearest(present, {key})) throw unknown_key(entry.first, key);
    }
  }
  throw Error(file_ + ": missing key '" + qualified(key) + "'");
}

Error YamlSection::unknown_key(const YAML::Node& key,
                               const std::optional<std::string>& meant) const {
  return Error(file_ + ":" + std::to_string(key.Mark().line + 1) + ": unknown key '" +
               qualified(key_name(key)) + "'" +
               (meant ? " (did you mean '" + qualified(*meant) + "'?)" : std::string()));
}

}  // namespace pspslam
