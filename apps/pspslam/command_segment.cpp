#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <string>
#include <vector>

#include "commands.h"
#include "pspslam/core/arg_parser.h"
#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/semantic/onnx_segmenter.h"

namespace pspslam::cli {
namespace {

std::vector<std::filesystem::path> list_images(const std::filesystem::path& dir) {
  if (!std::filesystem::is_directory(dir)) {
    throw Error("segment: --images '" + dir.string() + "' is not a directory");
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (entry.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg")) {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw Error("segment: no .png/.jpg images in '" + dir.string() + "'");
  return files;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int segment_command(const std::vector<std::string>& args) {
  ArgParser parser("pspslam segment",
                   "Segment images with an ONNX network described by a metadata YAML; writes "
                   "<name>_overlay.png (class colours), <name>_labels.png (class ids) and "
                   "<name>_mask.png (255 = dynamic class) and prints the inference time.");
  parser.add_option("model", "segmenter metadata YAML",
                    (source_dir() / "models" / "pspnet" / "pspnet.yaml").string());
  parser.add_option("images", "folder of .png/.jpg images (sorted by name)", "", true);
  parser.add_option("out", "output folder (created when missing)", "", true);
  parser.add_option("limit", "segment at most N images (0 = all)", "0");
  parser.add_option("start", "skip the first N images", "0");
  parser.add_option("step", "take every N-th image", "1");
  parser.add_option("threads", "OpenCV CPU threads", "2");
  parser.add_option("dilation", "dynamic mask margin in pixels", "0");
  if (!parser.parse(args)) return 0;

  const int limit = parser.get_int("limit");
  const int start = parser.get_int("start");
  const int step = parser.get_int("step");
  const int threads = parser.get_int("threads");
  const int dilation = parser.get_int("dilation");
  if (limit < 0) throw Error("segment: flag --limit must be >= 0, got " + parser.get("limit"));
  if (start < 0) throw Error("segment: flag --start must be >= 0, got " + parser.get("start"));
  if (step < 1) throw Error("segment: flag --step must be >= 1, got " + parser.get("step"));
  if (threads < 1)
    throw Error("segment: flag --threads must be >= 1, got " + parser.get("threads"));
  if (dilation < 0) {
    throw Error("segment: flag --dilation must be >= 0, got " + parser.get("dilation"));
  }
  cv::setNumThreads(threads);

  const auto files = list_images(parser.get("images"));
  std::vector<std::filesystem::path> chosen;
  for (size_t i = static_cast<size_t>(start); i < files.size(); i += static_cast<size_t>(step)) {
    if (limit > 0 && chosen.size() >= static_cast<size_t>(limit)) break;
    chosen.push_back(files[i]);
  }
  if (chosen.empty()) throw Error("segment: --start/--step/--limit select no image");

  auto segmenter = OnnxSegmenter::from_file(parser.get("model"));
  const auto dynamic_ids = segmenter->default_dynamic_classes();
  const std::filesystem::path out = parser.get("out");
  std::filesystem::create_directories(out);

  std::vector<double> times;
  for (size_t i = 0; i < chosen.size(); ++i) {
    const cv::Mat bgr = cv::imread(chosen[i].string(), cv::IMREAD_COLOR);
    if (bgr.empty()) throw Error("segment: cannot read image '" + chosen[i].string() + "'");
    const auto t0 = std::chrono::steady_clock::now();
    const LabelMap labels = segmenter->segment(bgr);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    times.push_back(ms);
    const cv::Mat mask = dynamic_mask(labels, dynamic_ids, dilation);
    const std::string stem = chosen[i].stem().string();
    const bool ok =
        cv::imwrite((out / (stem + "_overlay.png")).string(), overlay_labels(bgr, labels)) &&
        cv::imwrite((out / (stem + "_labels.png")).string(), labels) &&
        cv::imwrite((out / (stem + "_mask.png")).string(), mask);
    if (!ok) throw Error("segment: cannot write images into '" + out.string() + "'");
    const double dynamic_share = cv::countNonZero(mask) * 100.0 / static_cast<double>(mask.total());
    std::cout << stem << "  " << std::fixed << std::setprecision(1) << ms << " ms  dynamic "
              << dynamic_share << " %\n";
  }
  const auto& meta = segmenter->metadata();
  // The first inference includes OpenCV's one-off set-up, so the summary leaves it out.
  std::vector<double> steady(times.begin() + (times.size() > 1 ? 1 : 0), times.end());
  std::cout << std::fixed << std::setprecision(1) << "model " << meta.name << " input "
            << meta.input_width << "x" << meta.input_height << ", " << threads
            << " threads: median " << median(steady) << " ms over " << steady.size()
            << " images (first " << times.front() << " ms), outputs in " << out.string() << "\n";
  return 0;
}

}  // namespace pspslam::cli
