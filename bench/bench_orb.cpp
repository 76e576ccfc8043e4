// ORB extraction time per real 640x480 frame (bonn_crowd_dev), single-threaded.
// Run pinned to one core, e.g.
//   taskset -c 1 ./bench_orb --benchmark_repetitions=10 --benchmark_report_aggregates_only=true
// and read the median. Needs ../shared (or PSPSLAM_SHARED); skips with a message otherwise.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <vector>

#include "bonn_clip.h"

#include "pspslam/feature/hamming.h"
#include "pspslam/feature/orb_extractor.h"

namespace {

// Every 20th frame of the clip: static room and people walking, so the timing is not one image's.
std::vector<cv::Mat> load_frames() {
  const std::vector<std::filesystem::path> files = pspslam::bench::bonn_rgb_files();
  std::vector<cv::Mat> frames;
  for (std::size_t i = 0; i < files.size(); i += 20) {
    frames.push_back(cv::imread(files[i].string(), cv::IMREAD_GRAYSCALE));
  }
  return frames;
}

const std::vector<cv::Mat>& frames() {
  static const std::vector<cv::Mat> loaded = load_frames();
  return loaded;
}

void extract_orb(benchmark::State& state) {
  if (frames().empty()) {
    state.SkipWithError("no bonn_crowd_dev frames under shared_dir() (set PSPSLAM_SHARED)");
    return;
  }
  pspslam::OrbConfig config;
  config.n_features = static_cast<int>(state.range(0));
  pspslam::OrbExtractor extractor(config);
  pspslam::OrbFeatures features;
  const cv::Mat no_mask;
  std::size_t frame = 0;
  std::size_t keypoints = 0;
  for (auto _ : state) {
    extractor.extract(frames()[frame], no_mask, features);
    keypoints += features.keypoints.size();
    benchmark::DoNotOptimize(features.descriptors.data);
    frame = (frame + 1) % frames().size();
  }
  state.counters["keypoints"] =
      benchmark::Counter(static_cast<double>(keypoints), benchmark::Counter::kAvgIterations);
}
BENCHMARK(extract_orb)->Arg(1000)->Unit(benchmark::kMillisecond)->MinTime(1.0);

// Brute-force matching cost: 1000 x 1000 descriptor distances.
void hamming_all_pairs(benchmark::State& state) {
  cv::Mat a(1000, pspslam::kOrbDescriptorBytes, CV_8UC1);
  cv::Mat b(1000, pspslam::kOrbDescriptorBytes, CV_8UC1);
  cv::randu(a, 0, 256);
  cv::randu(b, 0, 256);
  for (auto _ : state) {
    long total = 0;
    for (int i = 0; i < a.rows; ++i) {
      for (int j = 0; j < b.rows; ++j) total += pspslam::hamming_distance(a.ptr(i), b.ptr(j));
    }
    benchmark::DoNotOptimize(total);
  }
  state.SetItemsProcessed(state.iterations() * a.rows * b.rows);
}
BENCHMARK(hamming_all_pairs)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  // One core: OpenCV's own worker threads would only compete with us for it.
  cv::setNumThreads(1);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
