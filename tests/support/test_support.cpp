#include "support/test_support.h"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

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

namespace {

// Removes the folders make_temp_dir handed out once they are no longer needed: a test's own
// folders when it ends without failing, a suite fixture's when the program ends without a failure.
// A failed test keeps its folders and names them, so its outputs can be read. Otherwise every
// ctest run would leave its outputs in /tmp, which the camera tests fill quickly.
class TempDirJanitor : public ::testing::EmptyTestEventListener {
 public:
  void add(const std::filesystem::path& dir, bool belongs_to_a_test) {
    (belongs_to_a_test ? test_dirs_ : program_dirs_).push_back(dir);
  }

 private:
  void OnTestEnd(const ::testing::TestInfo& test) override {
    release(test_dirs_, test.result()->Failed());
  }
  void OnTestProgramEnd(const ::testing::UnitTest& unit_test) override {
    release(program_dirs_, unit_test.Failed());
  }

  static void release(std::vector<std::filesystem::path>& dirs, bool failed) {
    const char* keep = std::getenv("PSPSLAM_KEEP_TEST_DIRS");
    const bool kept = failed || (keep != nullptr && std::string(keep) == "1");
    for (const auto& dir : dirs) {
      if (kept) {
        std::cerr << "test outputs kept in " << dir.string() << '\n';
      } else {
        std::error_code ignored;
        std::filesystem::remove_all(dir, ignored);
      }
    }
    dirs.clear();
  }

  std::vector<std::filesystem::path> test_dirs_;
  std::vector<std::filesystem::path> program_dirs_;
};

// The janitor is appended to GoogleTest's listeners on first use; GoogleTest owns and deletes it.
TempDirJanitor& janitor() {
  static TempDirJanitor* const instance = [] {
    auto* created = new TempDirJanitor;
    ::testing::UnitTest::GetInstance()->listeners().Append(created);
    return created;
  }();
  return *instance;
}

}  // namespace

std::filesystem::path make_temp_dir(const std::string& tag) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::ostringstream name;
  name << "pspslam_test_" << tag;
  if (info != nullptr) name << '_' << info->test_suite_name() << '_' << info->name();
  name << '_' << ::getpid();
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / name.str();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  janitor().add(dir, info != nullptr);
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
