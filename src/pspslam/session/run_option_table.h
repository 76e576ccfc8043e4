#pragma once

#include <functional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "pspslam/session/run_settings.h"

namespace pspslam {

// The one declaration of the options that shape a run's System: `pspslam run` registers each as
// its flag and the Python module accepts each as its keyword, with the same default (a member of
// RunSettings), the same range or choices and the same message for a bad value. How a new option
// is added: a member of RunSettings (its default there), what it sets in system_options()
// (run_settings.cpp), and one entry in run_option_table() (run_option_table.cpp).
enum class RunOptionKind {
  flag,          // --x sets true; keyword x=True
  negated_flag,  // --no-x sets false; keyword x=False
  integer,       // whole number in [low, high]
  real,          // number in [low, high]
  choice,        // one of `choices`
  text,          // any text, checked by `check_text` when there is one
  path,          // a path (must_exist: a file or folder that exists)
  real_pair,     // two numbers, each in [low, high]
};

enum class PathMustBe { anything, existing_file, existing_folder };

using RunValue = std::variant<bool, long long, double, std::string, std::pair<double, double>>;

struct RunOption {
  std::string flag;     // "--mask-margin"; empty: a keyword only (the CLI sets it otherwise)
  std::string keyword;  // "mask_margin"
  RunOptionKind kind = RunOptionKind::integer;
  std::string help;
  double low = 0.0;
  double high = 0.0;
  std::vector<std::string> choices;
  PathMustBe path_must_be = PathMustBe::anything;
  std::string value_name;  // for text and pairs in help: "MS|random:MIN:MAX", "MM DEG"
  // text: empty when the value is good, else what is wrong with it.
  std::function<std::string(const std::string&)> check_text;
  std::function<void(RunSettings&, const RunValue&)> set;
  // The value in these settings as text (help shows RunSettings{}'s as the default); empty: the
  // run's own default, which `help` states.
  std::function<std::string(const RunSettings&)> value_text;
  // The value the System got, where the run resolves it (live defaults, shipped files); none:
  // value_text.
  std::function<std::string(const SystemOptions&)> effective_text;
};

// Every option, in the order `pspslam run --help` lists them.
const std::vector<RunOption>& run_option_table();

// The option of this flag or keyword; nullptr when there is none.
const RunOption* find_run_option_by_flag(const std::string& flag);
const RunOption* find_run_option_by_keyword(const std::string& keyword);

// What is wrong with a value given as text (a pair: two words): empty when nothing, else the
// message both front ends print after the option's name, e.g. "must be an integer in [0, 100],
// got '101'".
std::string run_text_problem(const RunOption& option, const std::vector<std::string>& words);
// The value of good text (run_text_problem empty).
RunValue parse_run_text(const RunOption& option, const std::vector<std::string>& words);
// What is wrong with a typed value (Python's): the same messages, `shown` being the value as
// the caller's language prints it.
std::string run_value_problem(const RunOption& option, const RunValue& value,
                              const std::vector<std::string>& shown);

// Checks across options, named as the front end names them (flags, or keywords when
// names.keywords): --localization needs --load-map, --semantic-delay-seed needs
// --semantic-delay-ms. Throws Error.
void check_run_settings(const RunSettings& settings, const SettingNames& names);

// The settings a run's System got, option by option, with the run's own defaults resolved
// (keyword, value as text), in table order: stats.json's "settings" and Python's
// System.settings, so the two front ends can be compared.
std::vector<std::pair<std::string, std::string>> effective_settings(const RunSettings& settings,
                                                                    const SystemOptions& system);

}  // namespace pspslam
