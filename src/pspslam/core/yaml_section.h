#pragma once

#include <yaml-cpp/yaml.h>

#include <optional>
#include <set>
#include <string>

#include "pspslam/core/error.h"

namespace pspslam {

// Reads one YAML mapping strictly: every key read is remembered, and finish() rejects any key
// that was not read, so a typo ("fxx: 500") is an error naming the key instead of being ignored,
// with the nearest valid key as a suggestion ("unknown key 'camera.fxx' (did you mean
// 'camera.fx'?)"); a required key that is absent because it was mistyped is reported the same way.
class YamlSection {
 public:
  YamlSection(const YAML::Node& node, std::string file, std::string path);

  bool contains(const std::string& key) const;
  // "<file>:<line>: " of a key that is present ("<file>: " when it is not).
  std::string where(const std::string& key) const;
  // A key whose value is not allowed: "<file>:<line>: key '<section.key>' <what>".
  Error invalid(const std::string& key, const std::string& what) const;
  // Throws invalid(key, what) unless `ok`.
  void require(bool ok, const std::string& key, const std::string& what) const {
    if (!ok) throw invalid(key, what);
  }

  template <typename T>
  T required(const std::string& key) {
    used_.insert(key);
    const YAML::Node value = node_[key];
    if (!value) throw_missing(key);
    return convert<T>(value, key);
  }

  template <typename T>
  T optional(const std::string& key, const T& fallback) {
    used_.insert(key);
    const YAML::Node value = node_[key];
    if (!value) return fallback;
    return convert<T>(value, key);
  }

  // A nested mapping; absent sections read as empty so that all their keys take defaults.
  YamlSection section(const std::string& key);

  void finish() const;

  const std::string& file() const { return file_; }
  std::string qualified(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }

 private:
  [[noreturn]] void throw_missing(const std::string& key) const;
  std::string key_name(const YAML::Node& key) const;
  Error unknown_key(const YAML::Node& key, const std::optional<std::string>& meant) const;

  template <typename T>
  T convert(const YAML::Node& value, const std::string& key) const {
    try {
      return value.as<T>();
    } catch (const YAML::Exception&) {
      throw Error(file_ + ":" + std::to_string(value.Mark().line + 1) + ": key '" + qualified(key) +
                  "' has an invalid value");
    }
  }

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> used_;
};

}  // namespace pspslam
