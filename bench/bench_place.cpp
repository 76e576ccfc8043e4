// Costs of place recognition per keyframe / lost frame, single-threaded, on real bonn_crowd_dev
// frames (1000 ORB features each):
//   bow_transform       BoW vector + direct index of one frame (local mapping, per keyframe;
//                       relocalisation, per lost frame)
//   bow_match           match_by_bow between two frames 20 frames apart (per relocalisation
//                       candidate)
//   vocabulary_load     loading the shipped vocabulary (once per System)
// Run pinned to one core, e.g.
//   taskset -c 1 ./bench_place --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Needs ../shared (or PSPSLAM_SHARED); skips with a message otherwise.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <vector>

#include "bonn_clip.h"

#include "pspslam/feature/orb_extractor.h"
#include "pspslam/place/bow_matching.h"
#include "pspslam/place/place_recognition.h"

namespace {

// Descriptors of every 20th frame of the clip.
std::vector<cv::Mat> load_descriptors() {
  const std::vector<std::filesystem::path> files = pspslam::bench::bonn_rgb_files();
  pspslam::OrbExtractor extractor{pspslam::OrbConfig{}};
  pspslam::OrbFeatures features;
  std::vector<cv::Mat> descriptors;
  for (std::size_t i = 0; i < files.size(); i += 20) {
    extractor.extract(cv::imread(files[i].string(), cv::IMREAD_GRAYSCALE), cv::Mat(), features);
    descriptors.push_back(features.descriptors.clone());
  }
  return descriptors;
}

const std::vector<cv::Mat>& descriptors() {
  static const std::vector<cv::Mat> loaded = load_descriptors();
  return loaded;
}

const pspslam::Vocabulary& vocabulary() {
  static const pspslam::Vocabulary loaded =
      pspslam::Vocabulary::load(pspslam::default_vocabulary_path());
  return loaded;
}

void bow_transform(benchmark::State& state) {
  if (descriptors().empty()) {
    state.SkipWithError("no bonn_crowd_dev frames under shared_dir() (set PSPSLAM_SHARED)");
    return;
  }
  pspslam::BowVector bow;
  pspslam::FeatureVector features;
  std::size_t frame = 0;
  for (auto _ : state) {
    vocabulary().transform(descriptors()[frame], bow, features,
                           pspslam::PlaceRecognition::kDirectIndexLevel);
    benchmark::DoNotOptimize(bow.entries.data());
    frame = (frame + 1) % descriptors().size();
  }
}
BENCHMARK(bow_transform)->Unit(benchmark::kMillisecond);

void bow_match(benchmark::State& state) {
  if (descriptors().size() < 2) {
    state.SkipWithError("no bonn_crowd_dev frames under shared_dir() (set PSPSLAM_SHARED)");
    return;
  }
  const std::size_t n = descriptors().size();
  std::vector<pspslam::BowVector> bows(n);
  std::vector<pspslam::FeatureVector> features(n);
  for (std::size_t i = 0; i < n; ++i) {
    vocabulary().transform(descriptors()[i], bows[i], features[i],
                           pspslam::PlaceRecognition::kDirectIndexLevel);
  }
  std::vector<pspslam::BowMatch> matches;
  std::size_t pair = 0;
  std::size_t matched = 0;
  for (auto _ : state) {
    const std::size_t a = pair % (n - 1);
    pspslam::match_by_bow(features[a], descriptors()[a], {}, features[a + 1], descriptors()[a + 1],
                          {}, pspslam::BowMatchOptions{}, matches);
    matched += matches.size();
    ++pair;
  }
  state.counters["matches"] =
      benchmark::Counter(static_cast<double>(matched), benchmark::Counter::kAvgIterations);
}
BENCHMARK(bow_match)->Unit(benchmark::kMillisecond);

void vocabulary_load(benchmark::State& state) {
  for (auto _ : state) {
    const pspslam::Vocabulary loaded =
        pspslam::Vocabulary::load(pspslam::default_vocabulary_path());
    benchmark::DoNotOptimize(loaded.word_count());
  }
}
BENCHMARK(vocabulary_load)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
