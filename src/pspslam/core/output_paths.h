#pragma once

#include <filesystem>
#include <string>

namespace pspslam {

// Output paths are checked before a run starts, so that minutes of computing never end in a
// failed write. Both create what is missing and throw pspslam::Error naming the flag:
//   "--out 'a/b': 'a' is a file, not a folder"
//   "--out 'a/b': cannot create the folder: <reason>"
// A folder that receives the run's files (created with its parents).
void prepare_output_folder(const std::filesystem::path& folder, const std::string& flag);
// A file to be written later: its folder is created, the path must not be a folder itself.
void prepare_output_file(const std::filesystem::path& file, const std::string& flag);

}  // namespace pspslam
