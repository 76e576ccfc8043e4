#include <gtest/gtest.h>

#include <unistd.h>

#include <fstream>
#include <functional>

#include "pspslam/core/error.h"
#include "pspslam/core/output_paths.h"

namespace pspslam {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& tag) {
  const fs::path dir = fs::temp_directory_path() / ("pspslam_output_paths_" + tag);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string error_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(OutputPaths, CreatesMissingFolders) {
  const fs::path dir = fresh_dir("create");
  prepare_output_folder(dir / "a" / "b", "--out");
  EXPECT_TRUE(fs::is_directory(dir / "a" / "b"));
  EXPECT_FALSE(fs::exists(dir / "a" / "b" / ".pspslam_write_test"));  // the probe is removed
  prepare_output_file(dir / "maps" / "room.map", "--save-map");
  EXPECT_TRUE(fs::is_directory(dir / "maps"));
  EXPECT_FALSE(fs::exists(dir / "maps" / "room.map"));
}

TEST(OutputPaths, AFileInThePathIsNamed) {
  const fs::path dir = fresh_dir("file");
  std::ofstream(dir / "plain") << "x";
  EXPECT_EQ(error_of([&] { prepare_output_folder(dir / "plain" / "run", "--out"); }),
            "--out '" + (dir / "plain" / "run").string() + "': '" + (dir / "plain").string() +
                "' is a file, not a folder");
  EXPECT_EQ(error_of([&] { prepare_output_folder(dir / "plain", "--out"); }),
            "--out '" + (dir / "plain").string() + "': '" + (dir / "plain").string() +
                "' is a file, not a folder");
  EXPECT_EQ(error_of([&] { prepare_output_file(dir, "--save-map"); }),
            "--save-map '" + dir.string() + "' is a folder; give a file name");
  EXPECT_EQ(error_of([&] { prepare_output_file(dir / "plain" / "m.ply", "--export-map"); }),
            "--export-map '" + (dir / "plain").string() + "': '" + (dir / "plain").string() +
                "' is a file, not a folder");
}

TEST(OutputPaths, UnwritableFolderIsRefusedUpFront) {
  if (::geteuid() == 0) GTEST_SKIP() << "root may write into read-only folders";
  const fs::path dir = fresh_dir("readonly");
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_EQ(error_of([&] { prepare_output_folder(dir, "--out"); }),
            "--out '" + dir.string() + "': cannot write into the folder");
  fs::permissions(dir, fs::perms::owner_all);
}

}  // namespace
}  // namespace pspslam
