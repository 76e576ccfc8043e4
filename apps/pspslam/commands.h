#pragma once

#include <string>
#include <vector>

namespace pspslam::cli {

// Each sub-command receives the arguments after its name and returns the process exit code.
// Errors are thrown as pspslam::Error and reported by main().
int run_command(const std::vector<std::string>& args);
int eval_command(const std::vector<std::string>& args);
int synth_command(const std::vector<std::string>& args);
int segment_command(const std::vector<std::string>& args);
int vocab_command(const std::vector<std::string>& args);

}  // namespace pspslam::cli
