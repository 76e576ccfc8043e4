#include "pspslam/config/yaml_section.h"

namespace pspslam {

YamlSection::YamlSection(const YAML::Node& node, std::string file, std::string path)
    : node_(node), file_(std::move(file)), path_(std::move(path)) {
  if (node_ && !node_.IsNull() && !node_.IsMap()) {
    throw Error(file_ + ": '" + (path_.empty() ? std::string("<root>") : path_) +
                "' must be a mapping of key: value");
  }
}

bool YamlSection::contains(const std::string& key) const {
  return node_ && node_.IsMap() && node_[key];
}

YamlSection YamlSection::section(const std::string& key) {
  used_.insert(key);
  const YAML::Node child = node_ && node_.IsMap() ? node_[key] : YAML::Node();
  return YamlSection(child, file_, qualified(key));
}

void YamlSection::finish() const {
  if (!node_ || !node_.IsMap()) return;
  for (const auto& entry : node_) {
    const std::string key = entry.first.as<std::string>();
    if (!used_.count(key)) {
      throw Error(file_ + ":" + std::to_string(entry.first.Mark().line + 1) + ": unknown key '" +
                  qualified(key) + "'");
    }
  }
}

}  // namespace pspslam
