// Segmentation accuracy and speed through the C++ path (OpenCV DNN, CPU).
//
//   bench_segmentation [--models a.yaml,b.yaml] [--threads 2] [--frames 20] [--no-iou]
//                      [--profile] [--no-fusion] [google-benchmark flags]
//
// 1. Prints the person IoU (mean over the human_seg validation split of
//    models/pspnet/human_seg_split.json, masks resized to the photo) of each model.
// 2. Times segment() on bonn_crowd_dev frames (640x480, including pre/post-processing) with
//    cv::setNumThreads(threads); the counter median_ms is the median wall time over --frames
//    frames, cpu_ms the median CPU time of the whole process (all OpenCV threads) per frame.
//    On the shared, loaded machine wall time includes waiting for a core; CPU time does not.
// 3. With --profile, first prints per model the median wall time of the stages of segment()
//    (pre-processing, network, post-processing), of dynamic_mask() (run after segment() by the
//    semantic thread) and of the network's layers summed by type and the five slowest layers
//    (cv::dnn::Net::getPerfProfile), over the same frames, and the DNN backend/target pairs
//    this OpenCV build offers. --no-fusion disables OpenCV's layer fusion (for comparison).
// Needs ../shared (PSPSLAM_SHARED); defaults to our PSPNet at its three exported sizes and the
// three teachers.
#include <benchmark/benchmark.h>
#include <yaml-cpp/yaml.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bonn_clip.h"
#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/semantic/onnx_segmenter.h"
#include "pspslam/semantic/semantic_params.h"

namespace {

using pspslam::OnnxSegmenter;
namespace fs = std::filesystem;

struct Options {
  std::vector<fs::path> models;
  int threads = 2;
  int frames = 20;
  bool iou = true;
  bool profile = false;
  bool fusion = true;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double validation_iou(OnnxSegmenter& segmenter, const fs::path& shared, int* count) {
  const YAML::Node split = YAML::LoadFile(
      (pspslam::source_dir() / "models" / "pspnet" / "human_seg_split.json").string());
  double sum = 0;
  *count = 0;
  for (int id : split["val"].as<std::vector<int>>()) {
    const fs::path root = shared / "data" / "human_seg";
    const cv::Mat bgr = cv::imread((root / "images" / (std::to_string(id) + ".jpg")).string());
    cv::Mat gt =
        cv::imread((root / "masks" / (std::to_string(id) + ".png")).string(), cv::IMREAD_GRAYSCALE);
    if (bgr.empty() || gt.empty()) throw pspslam::Error("human_seg sample " + std::to_string(id));
    if (gt.size() != bgr.size()) cv::resize(gt, gt, bgr.size(), 0, 0, cv::INTER_NEAREST);
    const cv::Mat pred = segmenter.segment(bgr) == 15;
    const cv::Mat truth = gt > 127;
    const double uni = cv::countNonZero(pred | truth);
    sum += uni == 0 ? 1.0 : cv::countNonZero(pred & truth) / uni;
    ++*count;
  }
  return sum / *count;
}

std::vector<cv::Mat> bonn_frames(int count) {
  const std::vector<fs::path> files = pspslam::bench::bonn_rgb_files();
  std::vector<cv::Mat> frames;
  // Frames with people (from ~220 on), spread over the clip.
  for (size_t i = 220; i < files.size() && static_cast<int>(frames.size()) < count; i += 8) {
    frames.push_back(cv::imread(files[i].string()));
  }
  return frames;
}

// Median stage and per-layer-type times of segment() over `frames` (after one warm-up call).
void print_profile(OnnxSegmenter& segmenter, const std::vector<cv::Mat>& frames) {
  segmenter.segment(frames.front());
  cv::dnn::Net& net = segmenter.network();
  const std::vector<std::string> names = net.getLayerNames();
  std::vector<std::string> layer_types;
  for (const std::string& name : names) layer_types.push_back(net.getLayer(name)->type);
  const std::vector<int> dynamic_ids = segmenter.default_dynamic_classes();
  const int dilation_px = pspslam::SemanticParams{}.mask_dilation_px;
  std::vector<double> pre, network, post, mask;
  std::map<std::string, std::vector<double>> by_type;
  std::vector<std::vector<double>> by_layer(names.size());
  std::vector<double> layer_ticks;
  for (const cv::Mat& frame : frames) {
    const pspslam::LabelMap labels = segmenter.segment(frame);
    const auto mask_start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(pspslam::dynamic_mask(labels, dynamic_ids, dilation_px));
    mask.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - mask_start)
            .count());
    const auto& stages = segmenter.last_stage_times();
    pre.push_back(stages.preprocess_ms);
    network.push_back(stages.network_ms);
    post.push_back(stages.postprocess_ms);
    net.getPerfProfile(layer_ticks);  // indexed like getLayerNames()
    std::map<std::string, double> sums;
    for (size_t i = 0; i < layer_ticks.size() && i < layer_types.size(); ++i) {
      const double ms = 1000.0 * layer_ticks[i] / cv::getTickFrequency();
      sums[layer_types[i]] += ms;
      by_layer[i].push_back(ms);
    }
    for (const auto& [type, ms] : sums) by_type[type].push_back(ms);
  }
  const auto& meta = segmenter.metadata();
  std::printf(
      "%s %dx%d, median over %zu frames: pre-processing %.2f ms, network %.2f ms, "
      "post-processing %.2f ms; dynamic_mask (%d px dilation, semantic thread) %.2f ms"
      "\n  network layers by type (ms):",
      meta.name.c_str(), meta.input_width, meta.input_height, frames.size(), median(pre),
      median(network), median(post), dilation_px, median(mask));
  for (const auto& [type, ms] : by_type) std::printf(" %s %.2f", type.c_str(), median(ms));
  std::vector<std::pair<double, size_t>> slowest;
  for (size_t i = 0; i < by_layer.size(); ++i) {
    if (!by_layer[i].empty()) slowest.emplace_back(median(by_layer[i]), i);
  }
  const size_t shown = std::min<size_t>(5, slowest.size());
  std::partial_sort(slowest.begin(), slowest.begin() + static_cast<std::ptrdiff_t>(shown),
                    slowest.end(), std::greater<>());
  std::printf("\n  slowest layers (ms):");
  for (size_t k = 0; k < shown; ++k) {
    std::printf(" %s %.2f;", names[slowest[k].second].c_str(), slowest[k].first);
  }
  std::printf("\n");
  std::fflush(stdout);
}

Options parse(int* argc, char** argv) {
  Options o;
  std::vector<char*> rest = {argv[0]};
  for (int i = 1; i < *argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= *argc) throw pspslam::Error("flag " + a + " needs a value");
      return argv[++i];
    };
    if (a == "--models") {
      std::stringstream list(value());
      for (std::string m; std::getline(list, m, ',');) o.models.emplace_back(m);
    } else if (a == "--threads") {
      o.threads = std::stoi(value());
    } else if (a == "--frames") {
      o.frames = std::stoi(value());
    } else if (a == "--no-iou") {
      o.iou = false;
    } else if (a == "--profile") {
      o.profile = true;
    } else if (a == "--no-fusion") {
      o.fusion = false;
    } else {
      rest.push_back(argv[i]);
    }
  }
  for (size_t i = 0; i < rest.size(); ++i) argv[i] = rest[i];
  *argc = static_cast<int>(rest.size());
  if (o.models.empty()) {
    const fs::path src = pspslam::source_dir() / "models";
    o.models = {src / "pspnet" / "pspnet.yaml",
                src / "pspnet" / "pspnet_288x192.yaml",
                src / "pspnet" / "pspnet_480x384.yaml",
                src / "teachers" / "deeplabv3_mnv2_pascal.yaml",
                src / "teachers" / "deeplabv3_mnv2_dm05_pascal.yaml",
                src / "teachers" / "espnetv2_s2.0_pascal_384x384.yaml"};
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options options = parse(&argc, argv);
    const fs::path shared = pspslam::shared_dir();
    if (!fs::exists(shared / "data" / "human_seg")) {
      std::cerr << "bench_segmentation needs ../shared (set PSPSLAM_SHARED)\n";
      return 2;
    }
    cv::setNumThreads(options.threads);
    const std::vector<cv::Mat> frames = bonn_frames(options.frames);
    if (options.iou) {
      std::printf("%-34s %-9s %s\n", "model", "input", "person IoU (human_seg validation)");
      for (const fs::path& m : options.models) {
        auto segmenter = OnnxSegmenter::from_file(m);
        int count = 0;
        const double iou = validation_iou(*segmenter, shared, &count);
        const auto& meta = segmenter->metadata();
        std::printf("%-34s %4dx%-4d %.4f (%d photos)\n", meta.name.c_str(), meta.input_width,
                    meta.input_height, iou, count);
        std::fflush(stdout);
      }
    }
    if (options.profile) {
      std::printf("DNN backend/target pairs available:");
      for (const auto& [backend, target] : cv::dnn::getAvailableBackends()) {
        std::printf(" %d/%d", backend, target);
      }
      std::printf(" (3/0 = DNN_BACKEND_OPENCV/DNN_TARGET_CPU)\n");
      for (const fs::path& m : options.models) {
        auto segmenter = OnnxSegmenter::from_file(m);
        segmenter->network().enableFusion(options.fusion);
        print_profile(*segmenter, frames);
      }
    }
    for (const fs::path& m : options.models) {
      auto meta = pspslam::load_segmenter_metadata(m);
      const std::string name = meta.name + "/" + std::to_string(meta.input_width) + "x" +
                               std::to_string(meta.input_height) +
                               "/threads:" + std::to_string(options.threads) +
                               (options.fusion ? "" : "/no-fusion");
      benchmark::RegisterBenchmark(
          name.c_str(),
          [meta, &frames, fusion = options.fusion](benchmark::State& state) {
            OnnxSegmenter segmenter(meta);
            segmenter.network().enableFusion(fusion);
            segmenter.segment(frames.front());  // one-off set-up outside the timing
            std::vector<double> ms;
            std::vector<double> cpu_ms;
            size_t i = 0;
            for (auto _ : state) {
              const auto t0 = std::chrono::steady_clock::now();
              const std::clock_t c0 = std::clock();  // process CPU time, all threads
              benchmark::DoNotOptimize(segmenter.segment(frames[i++ % frames.size()]));
              cpu_ms.push_back(1000.0 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
              ms.push_back(
                  std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                      .count());
            }
            state.counters["median_ms"] = median(ms);
            state.counters["cpu_ms"] = median(cpu_ms);
            state.counters["frames"] = static_cast<double>(ms.size());
          })
          ->Unit(benchmark::kMillisecond)
          ->Iterations(static_cast<benchmark::IterationCount>(frames.size()))
          ->UseRealTime();
    }
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
  } catch (const pspslam::Error& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
