#include "fakenect_dump.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pspslam/capture/kinect_depth.h"
#include "pspslam/core/error.h"

namespace pspslam::testing {
namespace {

void write_file(const std::filesystem::path& file, const std::string& header, const void* data,
                size_t bytes) {
  std::ofstream out(file, std::ios::binary);
  out << header;
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  if (!out) throw Error("cannot write " + file.string());
}

}  // namespace

void write_fakenect_dump(const RecordedSequence& sequence, const std::filesystem::path& dir,
                         const FakenectDumpOptions& options) {
  std::filesystem::create_directories(dir);
  std::ofstream index(dir / "INDEX.txt");
  const size_t frames =
      options.frames == 0 ? sequence.size() : std::min(options.frames, sequence.size());
  for (size_t i = 0; i < frames; ++i) {
    const InputFrame frame = sequence.load(i);
    if (frame.bgr.cols != 640 || frame.bgr.rows != 480)
      throw Error("fakenect plays 640x480 frames only");
    const double elapsed = sequence.timestamp(i) - sequence.timestamp(0);
    const auto ticks = static_cast<uint32_t>(options.first_ticks +
                                             static_cast<uint64_t>(std::llround(elapsed * 60e6)));
    const double record_time =
        1000.0 + static_cast<double>(i) * options.interval_s +
        (options.pause_s > 0 && i > options.pause_after ? options.pause_s : 0);
    cv::Mat raw(frame.depth.size(), CV_16UC1);
    for (int y = 0; y < raw.rows; ++y)
      for (int x = 0; x < raw.cols; ++x)
        raw.at<uint16_t>(y, x) = kinect_metres_to_raw(frame.depth.at<float>(y, x));
    cv::Mat rgb;
    cv::cvtColor(frame.bgr, rgb, cv::COLOR_BGR2RGB);
    char depth_name[96], colour_name[96];
    std::snprintf(depth_name, sizeof(depth_name), "d-%.6f-%u-%zu.pgm", record_time, ticks, i);
    std::snprintf(colour_name, sizeof(colour_name), "r-%.6f-%u-%zu.ppm", record_time, ticks, i);
    write_file(dir / depth_name, "P5 640 480 2047\n", raw.data, raw.total() * raw.elemSize());
    write_file(dir / colour_name, "P6 640 480 255\n", rgb.data, rgb.total() * rgb.elemSize());
    index << depth_name << "\n" << colour_name << "\n";
  }
  if (!index) throw Error("cannot write " + (dir / "INDEX.txt").string());
}

std::string fakenect_environment(const std::filesystem::path& dump) {
  return "FAKENECT_PATH='" + dump.string() + "' LD_LIBRARY_PATH='" +
         fakenect_library_dir().string() + "' ";
}

std::filesystem::path fakenect_library_dir() {
  for (const char* dir :
       {"/usr/lib/x86_64-linux-gnu/fakenect", "/usr/lib/aarch64-linux-gnu/fakenect",
        "/usr/lib/fakenect", "/usr/local/lib/fakenect"}) {
    if (std::filesystem::exists(std::filesystem::path(dir) / "libfreenect.so.0.5")) return dir;
  }
  return {};
}

}  // namespace pspslam::testing
