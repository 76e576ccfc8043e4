#include "support/test_support.h"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include <unistd.h>

#include "pspslam/core/shared_paths.h"

namespace pspslam::testing {

std::filesystem::path shared_dir_if_present() {
  const std::filesystem::path dir = pspslam::shared_dir();
  if (std::filesystem::exists(dir / "README.md") && std::filesystem::is_directory(dir / "data")) {
    return dir;
  }
  return {};
}

bool shared_required() {
  const char* env = std::getenv("PSPSLAM_REQUIRE_SHARED");
  return env != nullptr && std::string(env) == "1";
}

std::filesystem::path make_temp_dir(const std::string& tag) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::ostringstream name;
  name << "pspslam_test_" << tag;
  if (info != nullptr) name << '_' << info->test_suite_name() << '_' << info->name();
  name << '_' << ::getpid();
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / name.str();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

int run_shell(const std::string& command, std::string* output) {
  const std::string full = command + " 2>&1";
  FILE* pipe = popen(full.c_str(), "r");
  if (pipe == nullptr) return -1;
  std::array<char, 4096> buffer{};
  std::string text;
  while (fgets(buffer.data(), buffer.size(), pipe) != nullptr) text += buffer.data();
  const int status = pclose(pipe);
  if (output != nullptr) *output = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream stream(file);
  return std::string(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
}

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file) << text;
}

}  // namespace pspslam::testing
