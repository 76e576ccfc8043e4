// `pspslam`: the command line. CLI11 parses and range-checks every flag of the chosen
// sub-command before any work starts; spdlog carries the diagnostics (warnings, errors, debug)
// to stderr while results go to stdout.
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

#include "commands.h"
#include "pspslam/core/error.h"
#include "pspslam/core/suggest.h"
#include "pspslam/core/version.h"

namespace {

// "pspslam vocab train" for the deepest sub-command the arguments reached.
const CLI::App* chosen_command(const CLI::App& root) {
  const CLI::App* app = &root;
  for (bool deeper = true; deeper;) {
    deeper = false;
    for (const CLI::App* sub : app->get_subcommands()) {
      app = sub;
      deeper = true;
      break;
    }
  }
  return app;
}

std::string command_path(const CLI::App* app) {
  std::string path = app->get_name();
  for (const CLI::App* parent = app->get_parent(); parent; parent = parent->get_parent())
    path = parent->get_name() + " " + path;
  return path;
}

// CLI11 names what it did not expect; we also suggest the flag the user probably meant, and
// list the commands when none was given.
std::string explain(const CLI::ParseError& error, const CLI::App* app,
                    const std::vector<std::string>& words) {
  std::string message = error.what();
  if (dynamic_cast<const CLI::ExtrasError*>(&error) != nullptr) {
    std::vector<std::string> names;
    for (const CLI::App* scope = app; scope != nullptr; scope = scope->get_parent()) {
      for (const CLI::Option* option : scope->get_options()) {
        for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
      }
    }
    for (const std::string& word : words) {
      const std::string flag = word.substr(0, word.find('='));
      if (flag.rfind("--", 0) != 0) continue;
      if (std::find(names.begin(), names.end(), flag) != names.end()) continue;
      if (const auto best = pspslam::nearest(flag, names)) {
        message += " (did you mean " + *best + "?)";
        break;
      }
    }
  }
  return message;
}

// "  run       run SLAM on ..." lines, when the error is that no command was given.
std::string command_list(const CLI::ParseError& error, const CLI::App* app) {
  if (dynamic_cast<const CLI::RequiredError*>(&error) == nullptr ||
      app->get_subcommands({}).empty() || !app->get_subcommands().empty()) {
    return "";
  }
  std::string list = "commands:\n";
  for (const CLI::App* sub : app->get_subcommands({})) {
    const std::string& name = sub->get_name();
    list += "  " + name + std::string(name.size() < 10 ? 10 - name.size() : 1, ' ') +
            sub->get_description().substr(0, sub->get_description().find('\n')) + "\n";
  }
  return list;
}

void configure_logging(const std::string& level, bool quiet) {
  auto logger = spdlog::stderr_logger_st("pspslam");
  // "warning: ...", "error: ...": the plain form that tests and users grep for.
  logger->set_pattern("%l: %v");
  logger->set_level(quiet ? spdlog::level::warn : spdlog::level::from_str(level));
  logger->flush_on(spdlog::level::trace);
  spdlog::set_default_logger(logger);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App root{
      "pspslam: dynamic-scene SLAM (ORB-SLAM2 core, PSPNet semantic masks, "
      "multi-view geometry)",
      "pspslam"};
  root.require_subcommand(1);
  root.set_version_flag("--version", pspslam::version_string());
  std::string log_level = "info";
  bool quiet = false;
  root.add_option("--log-level", log_level,
                  "diagnostics on stderr: trace|debug|info|warn|error|off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
  root.add_flag("--quiet,-q", quiet, "only warnings and errors on stderr, no progress bar");

  std::vector<pspslam::cli::Command> commands = {
      pspslam::cli::add_run_command(root),    pspslam::cli::add_eval_command(root),
      pspslam::cli::add_synth_command(root),  pspslam::cli::add_segment_command(root),
      pspslam::cli::add_record_command(root), pspslam::cli::add_view_command(root)};
  CLI::App* vocab = root.add_subcommand("vocab", "train / inspect the bag-of-words vocabulary");
  vocab->require_subcommand(1);
  commands.push_back(pspslam::cli::add_vocab_train_command(*vocab));
  commands.push_back(pspslam::cli::add_vocab_info_command(*vocab));
  // Global flags may also follow the sub-command name.
  for (CLI::App* sub : root.get_subcommands({})) sub->fallthrough();
  vocab->fallthrough();

  // An unknown command word is named (CLI11 would only say that a sub-command is required).
  std::vector<std::string> names;
  for (const CLI::App* sub : root.get_subcommands({})) names.push_back(sub->get_name());
  if (argc > 1 && argv[1][0] != '-' &&
      std::find(names.begin(), names.end(), argv[1]) == names.end()) {
    const auto meant = pspslam::nearest(argv[1], names);
    std::cerr << "error: pspslam: unknown command '" << argv[1] << "'"
              << (meant ? " (did you mean " + *meant + "?)" : std::string()) << "\n"
              << command_list(CLI::RequiredError("command"), &root);
    return 2;
  }
  try {
    root.parse(argc, argv);
  } catch (const CLI::CallForHelp& help) {
    return root.exit(help);
  } catch (const CLI::CallForAllHelp& help) {
    return root.exit(help);
  } catch (const CLI::CallForVersion& version) {
    return root.exit(version);
  } catch (const CLI::ParseError& error) {
    const CLI::App* app = chosen_command(root);
    const std::vector<std::string> words(argv + 1, argv + argc);
    std::cerr << "error: " << command_path(app) << ": " << explain(error, app, words) << " (see '"
              << command_path(app) << " --help')\n"
              << command_list(error, app);
    return 2;
  }
  configure_logging(log_level, quiet);
  for (const pspslam::cli::Command& command : commands) {
    if (!command.app->parsed()) continue;
    try {
      return command.run(pspslam::cli::GlobalOptions{quiet});
    } catch (const pspslam::Error& e) {
      spdlog::error("{}", e.what());
      return 2;
    } catch (const std::exception& e) {
      spdlog::error("internal error: {}", e.what());
      return 3;
    }
  }
  std::cerr << root.help();
  return 2;
}
