#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "flag_checks.h"
#include "pspslam/core/error.h"
#include "pspslam/core/output_paths.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/semantic/onnx_segmenter.h"
#include "pspslam/semantic/overlay.h"

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

struct SegmentFlags {
  std::string model = (data_dir() / "models" / "pspnet" / "pspnet.yaml").string();
  std::string images;
  std::string out;
  int limit = 0;
  int start = 0;
  int step = 1;
  int threads = 2;
  int dilation = 0;
};

int segment(const SegmentFlags& flags) {
  const int limit = flags.limit, start = flags.start, step = flags.step, threads = flags.threads,
            dilation = flags.dilation;
  prepare_output_folder(flags.out, "--out");
  cv::setNumThreads(threads);

  const auto files = list_images(flags.images);
  std::vector<std::filesystem::path> chosen;
  for (size_t i = static_cast<size_t>(start); i < files.size(); i += static_cast<size_t>(step)) {
    if (limit > 0 && chosen.size() >= static_cast<size_t>(limit)) break;
    chosen.push_back(files[i]);
  }
  if (chosen.empty()) throw Error("segment: --start/--step/--limit select no image");

  auto segmenter = OnnxSegmenter::from_file(flags.model);
  const auto dynamic_ids = segmenter->default_dynamic_classes();
  const std::filesystem::path out = flags.out;

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
        cv::imwrite((out / (stem + "_overlay.png")).string(),
                    overlay_segmentation(bgr, labels, dynamic_ids, segmenter->class_names())) &&
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

}  // namespace

Command add_segment_command(CLI::App& root) {
  CLI::App* app = root.add_subcommand(
      "segment",
      "segment images with an ONNX network (overlays, masks, timing).\n"
      "Writes <name>_overlay.png (dynamic classes in strong colours with an outline, static "
      "classes muted, legend of the classes present), <name>_labels.png (class ids) and "
      "<name>_mask.png (255 = dynamic class) and prints the inference time.");
  auto flags = std::make_shared<SegmentFlags>();
  app->add_option("--model", flags->model, "segmenter metadata YAML")->capture_default_str();
  app->add_option("--images", flags->images, "folder of .png/.jpg images (sorted by name)")
      ->required();
  app->add_option("--out", flags->out, "output folder (created when missing)")->required();
  app->add_option("--limit", flags->limit, "segment at most N images (0 = all)")
      ->check(in_range(0, 1000000000))
      ->capture_default_str();
  app->add_option("--start", flags->start, "skip the first N images")
      ->check(in_range(0, 1000000000))
      ->capture_default_str();
  app->add_option("--step", flags->step, "take every N-th image")
      ->check(in_range(1, 1000000))
      ->capture_default_str();
  app->add_option("--threads", flags->threads, "OpenCV CPU threads")
      ->check(in_range(1, 256))
      ->capture_default_str();
  app->add_option("--dilation", flags->dilation, "dynamic mask margin in pixels")
      ->check(in_range(0, 200))
      ->capture_default_str();
  return {app, [flags](const GlobalOptions&) { return segment(*flags); }};
}

}  // namespace pspslam::cli
