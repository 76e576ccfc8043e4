#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace pspslam {

// Minimal `--flag value` / `--switch` parser shared by the CLI sub-commands.
// Unknown flags, missing values and malformed numbers raise pspslam::Error naming the flag.
class ArgParser {
 public:
  ArgParser(std::string command, std::string summary);

  // Declares a flag taking a value. An empty default with required=true means "must be given".
  void add_option(const std::string& name, const std::string& help, std::string default_value = "",
                  bool required = false);
  // Declares a flag taking a value that may be given several times (e.g. --images A --images B).
  void add_multi_option(const std::string& name, const std::string& help);
  void add_switch(const std::string& name, const std::string& help);

  // Returns false when --help was asked (help text already printed to stdout).
  bool parse(const std::vector<std::string>& args);

  std::string help() const;

  bool has(const std::string& name) const;
  std::string get(const std::string& name) const;
  std::vector<std::string> get_all(const std::string& name) const;
  bool flag(const std::string& name) const;
  int get_int(const std::string& name) const;
  double get_double(const std::string& name) const;

 private:
  struct Spec {
    std::string help;
    std::string default_value;
    bool takes_value = true;
    bool required = false;
    bool multi = false;
  };
  const Spec& spec(const std::string& name) const;

  std::string command_;
  std::string summary_;
  std::vector<std::string> order_;
  std::map<std::string, Spec> specs_;
  std::map<std::string, std::vector<std::string>> values_;
};

}  // namespace pspslam
