#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace pspslam::cli {

// A sub-command registered on the root CLI11 app. Its flags are bound to an options struct that
// the `run` closure owns, so everything is parsed and range-checked by CLI11 before any work
// starts; `run` then does the work and returns the process exit status. Errors are thrown as
// pspslam::Error and reported by main().
// Exit status of `run --camera` and `record` when the camera stops delivering (unplugged): the
// outputs hold every frame so far.
inline constexpr int kCameraLostExit = 4;

struct GlobalOptions {
  bool quiet = false;  // --quiet: no progress bar, only warnings and errors
};

struct Command {
  CLI::App* app = nullptr;  // owned by the root app
  std::function<int(const GlobalOptions&)> run;
};

Command add_run_command(CLI::App& root);
Command add_record_command(CLI::App& root);
Command add_eval_command(CLI::App& root);
Command add_synth_command(CLI::App& root);
Command add_segment_command(CLI::App& root);
Command add_view_command(CLI::App& root);
Command add_vocab_train_command(CLI::App& vocab);
Command add_vocab_info_command(CLI::App& vocab);

}  // namespace pspslam::cli
