#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "commands.h"
#include "pspslam/core/error.h"

namespace {

struct Command {
  const char* name;
  const char* summary;
  std::function<int(const std::vector<std::string>&)> run;
};

const std::vector<Command>& commands() {
  static const std::vector<Command> table = {
      {"run", "run SLAM on an RGB-D sequence and write the trajectory", pspslam::cli::run_command},
      {"eval", "ATE / RPE of an estimated trajectory against ground truth",
       pspslam::cli::eval_command},
      {"synth", "render a synthetic dynamic RGB-D sequence", pspslam::cli::synth_command},
      {"segment", "segment images with an ONNX network (overlays, masks, timing)",
       pspslam::cli::segment_command},
      {"vocab", "train / inspect the bag-of-words vocabulary", pspslam::cli::vocab_command},
  };
  return table;
}

void print_usage(std::ostream& out) {
  out << "usage: pspslam <command> [flags]   (pspslam <command> --help for its flags)\n\n"
         "commands:\n";
  for (const Command& c : commands()) {
    out << "  " << c.name << std::string(10 - std::string(c.name).size(), ' ') << c.summary << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    print_usage(argc < 2 ? std::cerr : std::cout);
    return argc < 2 ? 2 : 0;
  }
  const std::string name = argv[1];
  const std::vector<std::string> args(argv + 2, argv + argc);
  for (const Command& c : commands()) {
    if (name != c.name) continue;
    try {
      return c.run(args);
    } catch (const pspslam::Error& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "internal error: " << e.what() << "\n";
      return 3;
    }
  }
  std::cerr << "error: unknown command '" << name << "'\n\n";
  print_usage(std::cerr);
  return 2;
}
