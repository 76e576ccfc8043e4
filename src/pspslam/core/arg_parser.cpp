#include "pspslam/core/arg_parser.h"

#include <charconv>
#include <iostream>
#include <sstream>

#include "pspslam/core/error.h"

namespace pspslam {

ArgParser::ArgParser(std::string command, std::string summary)
    : command_(std::move(command)), summary_(std::move(summary)) {}

void ArgParser::add_option(const std::string& name, const std::string& help,
                           std::string default_value, bool required) {
  order_.push_back(name);
  specs_[name] = Spec{help, std::move(default_value), true, required, false};
}

void ArgParser::add_multi_option(const std::string& name, const std::string& help) {
  order_.push_back(name);
  specs_[name] = Spec{help, "", true, false, true};
}

void ArgParser::add_switch(const std::string& name, const std::string& help) {
  order_.push_back(name);
  specs_[name] = Spec{help, "", false, false, false};
}

const ArgParser::Spec& ArgParser::spec(const std::string& name) const {
  const auto it = specs_.find(name);
  if (it == specs_.end()) throw Error("internal: flag --" + name + " was never declared");
  return it->second;
}

bool ArgParser::parse(const std::vector<std::string>& args) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << help();
      return false;
    }
    if (arg.rfind("--", 0) != 0) {
      throw Error(command_ + ": unexpected argument '" + arg + "' (see '" + command_ + " --help')");
    }
    std::string name = arg.substr(2);
    std::optional<std::string> inline_value;
    if (const auto eq = name.find('='); eq != std::string::npos) {
      inline_value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    const auto it = specs_.find(name);
    if (it == specs_.end()) {
      throw Error(command_ + ": unknown flag --" + name + " (see '" + command_ + " --help')");
    }
    if (!it->second.takes_value) {
      if (inline_value) throw Error(command_ + ": flag --" + name + " takes no value");
      values_[name] = {"1"};
      continue;
    }
    std::string value;
    if (inline_value) {
      value = *inline_value;
    } else {
      if (i + 1 >= args.size()) throw Error(command_ + ": flag --" + name + " needs a value");
      value = args[++i];
    }
    if (it->second.multi) {
      values_[name].push_back(value);
    } else {
      values_[name] = {value};
    }
  }
  for (const auto& name : order_) {
    const Spec& s = specs_.at(name);
    if (s.required && !values_.count(name)) {
      throw Error(command_ + ": missing required flag --" + name + " (see '" + command_ +
                  " --help')");
    }
  }
  return true;
}

std::string ArgParser::help() const {
  std::ostringstream out;
  out << "usage: " << command_ << " [flags]\n\n" << summary_ << "\n\nflags:\n";
  for (const auto& name : order_) {
    const Spec& s = specs_.at(name);
    std::string left = "  --" + name + (s.takes_value ? " VALUE" : "");
    out << left;
    if (left.size() < 26)
      out << std::string(26 - left.size(), ' ');
    else
      out << "\n" << std::string(26, ' ');
    out << s.help;
    if (s.required)
      out << " (required)";
    else if (!s.default_value.empty())
      out << " (default: " << s.default_value << ")";
    if (s.multi) out << " (repeatable)";
    out << "\n";
  }
  out << "  --help                  show this help\n";
  return out.str();
}

bool ArgParser::has(const std::string& name) const {
  spec(name);
  return values_.count(name) > 0;
}

std::string ArgParser::get(const std::string& name) const {
  const Spec& s = spec(name);
  const auto it = values_.find(name);
  return it == values_.end() ? s.default_value : it->second.back();
}

std::vector<std::string> ArgParser::get_all(const std::string& name) const {
  spec(name);
  const auto it = values_.find(name);
  return it == values_.end() ? std::vector<std::string>{} : it->second;
}

bool ArgParser::flag(const std::string& name) const { return has(name); }

int ArgParser::get_int(const std::string& name) const {
  const std::string text = get(name);
  int value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size()) {
    throw Error(command_ + ": flag --" + name + " expects an integer, got '" + text + "'");
  }
  return value;
}

double ArgParser::get_double(const std::string& name) const {
  const std::string text = get(name);
  try {
    size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == text.size()) return value;
  } catch (const std::exception&) {
  }
  throw Error(command_ + ": flag --" + name + " expects a number, got '" + text + "'");
}

}  // namespace pspslam
