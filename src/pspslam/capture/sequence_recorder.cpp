#include "pspslam/capture/sequence_recorder.h"

#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <system_error>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

std::string stamp(Timestamp t) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6f", t);
  return text;
}

std::ofstream open_list(const std::filesystem::path& file, const char* what) {
  std::ofstream list(file);
  if (!list) throw Error("--out: cannot write " + file.string());
  list << "# " << what << "\n# file: pspslam record\n# timestamp filename\n";
  list.flush();
  return list;
}

void write_image(const std::filesystem::path& file, const cv::Mat& image) {
  if (!cv::imwrite(file.string(), image)) throw Error("--out: cannot write " + file.string());
}

}  // namespace

SequenceRecorder::SequenceRecorder(const std::filesystem::path& dir,
                                   const std::filesystem::path& config_file, double depth_factor)
    : dir_(dir), depth_factor_(depth_factor) {
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) &&
      (!std::filesystem::is_directory(dir, ec) || !std::filesystem::is_empty(dir, ec))) {
    throw Error("--out: " + dir.string() +
                " exists and is not an empty folder (a recording needs a folder of its own)");
  }
  for (const char* sub : {"rgb", "depth"}) {
    std::filesystem::create_directories(dir / sub, ec);
    if (ec) throw Error("--out: cannot create " + (dir / sub).string() + ": " + ec.message());
  }
  std::filesystem::copy_file(config_file, dir / "config.yaml", ec);
  if (ec)
    throw Error("--out: cannot copy " + config_file.string() + " to " +
                (dir / "config.yaml").string() + ": " + ec.message());
  rgb_list_ = open_list(dir / "rgb.txt", "color images");
  depth_list_ = open_list(dir / "depth.txt", "depth maps");
}

void SequenceRecorder::add(const InputFrame& frame) {
  const std::string rgb_file = "rgb/" + stamp(frame.timestamp) + ".png";
  const std::string depth_file = "depth/" + stamp(frame.depth_timestamp) + ".png";
  cv::Mat depth;
  // saturate_cast rounds and clamps: beyond 65535 / depth_factor m (13 m at 5000) is clipped.
  frame.depth.convertTo(depth, CV_16U, depth_factor_);
  write_image(dir_ / rgb_file, frame.bgr);
  write_image(dir_ / depth_file, depth);
  rgb_list_ << stamp(frame.timestamp) << " " << rgb_file << "\n";
  depth_list_ << stamp(frame.depth_timestamp) << " " << depth_file << "\n";
  rgb_list_.flush();
  depth_list_.flush();
  if (!rgb_list_ || !depth_list_) throw Error("--out: cannot write the lists in " + dir_.string());
  ++frames_;
}

}  // namespace pspslam
