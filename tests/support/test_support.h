#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "pspslam/core/error.h"

namespace pspslam::testing {

// The ../shared folder, or std::nullopt-like empty path when it is absent.
std::filesystem::path shared_dir_if_present();

// True when PSPSLAM_REQUIRE_SHARED=1 (set by .ci/run): then a missing ../shared is a failure.
bool shared_required();

// A fresh, empty temporary directory unique to the running test and process: ctest runs each
// test of a suite in its own process, in parallel, and a suite-level fixture (no current test)
// must not share its folder with the same suite's other processes. The folder is removed when the
// test (or, for a suite fixture, the program) ends without a failure; a failure keeps it and
// prints its path, and PSPSLAM_KEEP_TEST_DIRS=1 keeps every folder.
std::filesystem::path make_temp_dir(const std::string& tag);

// Runs a shell command, returns its exit status; stdout+stderr land in *output.
int run_shell(const std::string& command, std::string* output);

// A whole text file ("" when it cannot be read), and a file written with `text`.
std::string read_text(const std::filesystem::path& file);
void write_text(const std::filesystem::path& file, const std::string& text);

// The message of the pspslam::Error that `call()` throws, or "(no error)".
template <typename Call>
std::string error_of(Call&& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace pspslam::testing

// Use at the top of a test that reads ../shared:
//   PSPSLAM_SHARED_OR_SKIP(shared);   // declares `std::filesystem::path shared`
// Skips with the reason when ../shared is missing, fails instead under PSPSLAM_REQUIRE_SHARED=1.
#define PSPSLAM_SHARED_OR_SKIP(var)                                                        \
  const std::filesystem::path var = ::pspslam::testing::shared_dir_if_present();           \
  if (var.empty()) {                                                                       \
    if (::pspslam::testing::shared_required()) {                                           \
      FAIL() << "../shared is required (PSPSLAM_REQUIRE_SHARED=1) but was not found; set " \
                "PSPSLAM_SHARED";                                                          \
    }                                                                                      \
    GTEST_SKIP() << "../shared not found (set PSPSLAM_SHARED to its path); skipping test " \
                    "that needs real data";                                                \
  }
