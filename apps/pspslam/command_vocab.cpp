#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "commands.h"
#include "flag_checks.h"
#include "pspslam/core/error.h"
#include "pspslam/core/output_paths.h"
#include "pspslam/core/progress.h"
#include "pspslam/feature/orb_extractor.h"
#include "pspslam/place/vocabulary.h"
#include "pspslam/synth/scene.h"

namespace pspslam::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Synthetic training frames: kFramesPerSeed frames spread over one hand-held sequence per seed,
// seeds first_seed, first_seed + 1, ... Tests and benchmarks use seeds below 1000.
constexpr int kFramesPerSeed = 20;
constexpr size_t kSynthSequenceFrames = 300;

// Photographs are seen at three scales: the whole picture fitted into 640 x 480 (the size of the
// frames the SLAM system sees), and fitted into 1280 x 960 and 2560 x 1920 cut into 640 x 480
// tiles, which gives the finer texture a camera close to a surface sees (and more descriptors
// from the few dozen photographs Debian ships).
constexpr int kTileWidth = 640;
constexpr int kTileHeight = 480;

std::vector<fs::path> find_images(const std::vector<std::string>& dirs) {
  std::vector<fs::path> images;
  for (const std::string& dir : dirs) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
      throw Error("vocab train: --images '" + dir + "' is not a directory");
    }
    for (auto it =
             fs::recursive_directory_iterator(dir, fs::directory_options::follow_directory_symlink);
         it != fs::recursive_directory_iterator(); ++it) {
      if (!it->is_regular_file()) continue;
      std::string ext = it->path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(),
                     [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      if (ext == ".jpg" || ext == ".jpeg" || ext == ".png") images.push_back(it->path());
    }
  }
  std::sort(images.begin(), images.end());
  images.erase(std::unique(images.begin(), images.end()), images.end());
  return images;
}

cv::Mat fit_into(const cv::Mat& gray, int width, int height) {
  const double scale = std::min(
      {1.0, static_cast<double>(width) / gray.cols, static_cast<double>(height) / gray.rows});
  if (scale >= 1.0) return gray;
  cv::Mat resized;
  cv::resize(gray, resized, cv::Size(), scale, scale, cv::INTER_AREA);
  return resized;
}

// The training views of one photograph (see kTileWidth); pictures are never enlarged.
std::vector<cv::Mat> photo_views(const cv::Mat& gray) {
  std::vector<cv::Mat> views{fit_into(gray, kTileWidth, kTileHeight)};
  cv::Size previous = views.front().size();
  for (const int factor : {2, 4}) {
    const cv::Mat large = fit_into(gray, factor * kTileWidth, factor * kTileHeight);
    if (large.size() == previous) break;  // the picture is smaller than this scale
    previous = large.size();
    // Tiles at least half a tile high/wide; smaller edge remnants add little.
    for (int y = 0; y + kTileHeight / 2 <= large.rows; y += kTileHeight) {
      for (int x = 0; x + kTileWidth / 2 <= large.cols; x += kTileWidth) {
        const cv::Rect tile(x, y, std::min(kTileWidth, large.cols - x),
                            std::min(kTileHeight, large.rows - y));
        views.push_back(large(tile).clone());
      }
    }
  }
  return views;
}

struct TrainFlags {
  std::vector<std::string> images;
  int synthetic_frames = 0;
  int synthetic_seed = 1000;
  std::string out;
  VocabularyParams params;
  int max_descriptors = 1500000;
  bool progress = true;
};

// The ORB descriptors of every training view, one matrix per view.
struct TrainingDescriptors {
  std::vector<cv::Mat> images;
  std::size_t total = 0;
  size_t photo_views = 0;
  size_t synthetic_frames = 0;
};

class DescriptorCollector {
 public:
  explicit DescriptorCollector(TrainingDescriptors& collected) : collected_(collected) {}

  // Views without a single keypoint (smooth sky, gradients) are no training images.
  bool add_view(const cv::Mat& gray) {
    extractor_.extract(gray, cv::Mat(), features_);
    if (features_.descriptors.rows == 0) return false;
    collected_.images.push_back(features_.descriptors.clone());
    collected_.total += static_cast<std::size_t>(features_.descriptors.rows);
    return true;
  }

 private:
  TrainingDescriptors& collected_;
  OrbExtractor extractor_{OrbConfig{}};
  OrbFeatures features_;
};

TrainingDescriptors extract_training_descriptors(const std::vector<fs::path>& photos,
                                                 const TrainFlags& flags) {
  const int synthetic_frames = flags.synthetic_frames;
  TrainingDescriptors collected;
  DescriptorCollector collector(collected);
  ProgressBar extract_progress("orb", photos.size() + static_cast<size_t>(synthetic_frames),
                               std::cerr, flags.progress);
  size_t done = 0;
  for (const fs::path& photo : photos) {
    const cv::Mat gray = cv::imread(photo.string(), cv::IMREAD_GRAYSCALE);
    if (gray.empty()) throw Error("vocab train: cannot read image '" + photo.string() + "'");
    for (const cv::Mat& view : photo_views(gray))
      collected.photo_views += collector.add_view(view) ? 1 : 0;
    extract_progress.update(++done);
  }
  if (synthetic_frames > 0) {
    SynthFrame frame;
    cv::Mat gray;
    for (int first = 0; first < synthetic_frames; first += kFramesPerSeed) {
      SynthOptions options;
      options.frames = kSynthSequenceFrames;
      options.seed = static_cast<std::uint64_t>(flags.synthetic_seed + first / kFramesPerSeed);
      const SyntheticScene scene(options);
      const int count = std::min(kFramesPerSeed, synthetic_frames - first);
      for (int i = 0; i < count; ++i) {
        scene.render(static_cast<size_t>(i) * (kSynthSequenceFrames / kFramesPerSeed), frame, 0);
        cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
        collected.synthetic_frames += collector.add_view(gray) ? 1 : 0;
        extract_progress.update(++done);
      }
    }
  }
  extract_progress.finish();
  return collected;
}

// Uniform random subsample for the tree (k-means cost grows with it); IDF uses every image.
cv::Mat sample_descriptors(const TrainingDescriptors& collected, std::size_t sample,
                           std::uint64_t seed) {
  std::vector<std::uint32_t> order(collected.total);
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::uint32_t>(i);
  std::mt19937_64 rng(seed);
  if (sample < collected.total) {
    std::shuffle(order.begin(), order.end(), rng);
    order.resize(sample);
    std::sort(order.begin(), order.end());
  }
  cv::Mat tree_descriptors(static_cast<int>(sample), kOrbDescriptorBytes, CV_8UC1);
  std::size_t image = 0;
  std::size_t image_start = 0;
  for (std::size_t i = 0; i < sample; ++i) {
    while (order[i] >= image_start + static_cast<std::size_t>(collected.images[image].rows)) {
      image_start += static_cast<std::size_t>(collected.images[image].rows);
      ++image;
    }
    collected.images[image]
        .row(static_cast<int>(order[i] - image_start))
        .copyTo(tree_descriptors.row(static_cast<int>(i)));
  }
  return tree_descriptors;
}

// k-means tree and IDF weights, each with its progress bar.
Vocabulary train_vocabulary(const cv::Mat& tree_descriptors,
                            const std::vector<cv::Mat>& image_descriptors,
                            const VocabularyParams& params, bool progress) {
  ProgressBar tree_progress("k-means", static_cast<size_t>(tree_descriptors.rows), std::cerr,
                            progress);
  ProgressBar idf_progress("idf", image_descriptors.size(), std::cerr, progress);
  return Vocabulary::train(tree_descriptors, image_descriptors, params,
                           [&](const std::string& stage, std::size_t n, std::size_t total) {
                             if (stage == "tree") {
                               tree_progress.update(n);
                               if (n == total) tree_progress.finish();
                             } else {
                               idf_progress.update(n);
                               if (n == total) idf_progress.finish();
                             }
                           });
}

int train(const TrainFlags& flags) {
  const VocabularyParams& params = flags.params;
  params.validate();
  const int synthetic_frames = flags.synthetic_frames;
  const int max_descriptors = flags.max_descriptors;
  if (max_descriptors < params.branching) {
    throw Error("vocab train: --max-descriptors must be >= --k, got " +
                std::to_string(max_descriptors));
  }
  const fs::path out = flags.out;
  prepare_output_file(out, "--out");
  const std::vector<fs::path> photos = find_images(flags.images);
  if (photos.empty() && synthetic_frames == 0) {
    throw Error(
        "vocab train: no training data: give --images DIR (with jpg/png files) and/or "
        "--synthetic-frames N");
  }

  const auto start = Clock::now();
  std::cout << "training images: " << photos.size() << " photographs, " << synthetic_frames
            << " synthetic frames\n";
  const TrainingDescriptors collected = extract_training_descriptors(photos, flags);
  std::cout << "descriptors: " << collected.total << " from " << collected.images.size()
            << " images (" << collected.photo_views << " photograph views, "
            << collected.synthetic_frames << " synthetic frames), extraction "
            << seconds_since(start) << " s\n";
  if (collected.total < static_cast<std::size_t>(params.branching)) {
    throw Error("vocab train: only " + std::to_string(collected.total) +
                " descriptors found, need at least --k");
  }
  const std::size_t sample = std::min(collected.total, static_cast<std::size_t>(max_descriptors));
  const cv::Mat tree_descriptors = sample_descriptors(collected, sample, params.seed);

  const auto kmeans_start = Clock::now();
  const Vocabulary vocabulary =
      train_vocabulary(tree_descriptors, collected.images, params, flags.progress);
  const double kmeans_seconds = seconds_since(kmeans_start);
  vocabulary.save(out);
  const double total_seconds = seconds_since(start);

  const auto load_start = Clock::now();
  const Vocabulary reloaded = Vocabulary::load(out);
  const double load_seconds = seconds_since(load_start);
  std::cout << "vocabulary: k " << vocabulary.branching() << ", L " << vocabulary.levels() << ", "
            << vocabulary.node_count() << " nodes, " << vocabulary.word_count() << " words, "
            << sample << " descriptors clustered (of " << collected.total << "), "
            << collected.images.size() << " images for IDF\n"
            << "time: k-means + IDF " << kmeans_seconds << " s, total " << total_seconds
            << " s\nwrote " << out.string() << " (" << fs::file_size(out) << " bytes), loads in "
            << load_seconds * 1e3 << " ms (" << reloaded.word_count() << " words)\n";
  return 0;
}

struct InfoFlags {
  std::string vocabulary;
  int frames = 20;
  int repeat = 5;
};

int info(const InfoFlags& flags) {
  const fs::path file = flags.vocabulary;
  const int frames = flags.frames;
  const int repeat = flags.repeat;

  const auto load_start = Clock::now();
  const Vocabulary vocabulary = Vocabulary::load(file);
  const double load_ms = seconds_since(load_start) * 1e3;
  std::size_t weighted = 0;
  for (WordId w = 0; w < vocabulary.word_count(); ++w) weighted += vocabulary.word_weight(w) > 0;
  std::cout << file.string() << ": " << fs::file_size(file) << " bytes, loaded in " << load_ms
            << " ms\n  k " << vocabulary.branching() << ", L " << vocabulary.levels() << ", "
            << vocabulary.node_count() << " nodes, " << vocabulary.word_count() << " words ("
            << weighted << " with IDF > 0), trained on " << vocabulary.training_images()
            << " images\n";

  SynthOptions options;
  options.frames = 300;
  options.seed = 1;
  const SyntheticScene scene(options);
  OrbExtractor extractor{OrbConfig{}};
  OrbFeatures features;
  SynthFrame frame;
  cv::Mat gray;
  std::vector<cv::Mat> descriptors;
  std::size_t count = 0;
  for (int i = 0; i < frames; ++i) {
    scene.render(static_cast<size_t>(i * 7) % options.frames, frame, 0);
    cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
    extractor.extract(gray, cv::Mat(), features);
    descriptors.push_back(features.descriptors.clone());
    count += static_cast<std::size_t>(features.descriptors.rows);
  }
  std::uint64_t checksum = 0;  // keeps the lookups from being optimised away
  // CPU time next to wall time: on a loaded machine the wall clock also counts waiting.
  const std::clock_t lookup_cpu_start = std::clock();
  const auto lookup_start = Clock::now();
  for (int r = 0; r < repeat; ++r) {
    for (const cv::Mat& d : descriptors) {
      for (int row = 0; row < d.rows; ++row) checksum += vocabulary.word(d.ptr<std::uint8_t>(row));
    }
  }
  const double lookup_us = seconds_since(lookup_start) * 1e6;
  const double lookup_cpu_us =
      static_cast<double>(std::clock() - lookup_cpu_start) * 1e6 / CLOCKS_PER_SEC;
  BowVector bow;
  FeatureVector direct;
  const auto transform_start = Clock::now();
  for (int r = 0; r < repeat; ++r) {
    for (const cv::Mat& d : descriptors) {
      vocabulary.transform(d, bow, direct, std::min(2, vocabulary.levels()));
      checksum += bow.size();
    }
  }
  const double transform_us = seconds_since(transform_start) * 1e6;
  std::cout << std::fixed << std::setprecision(1)
            << "  lookup: " << lookup_us / (static_cast<double>(count) * repeat) * 1000.0
            << " us per 1000 descriptors wall, "
            << lookup_cpu_us / (static_cast<double>(count) * repeat) * 1000.0 << " us CPU ("
            << count << " descriptors from " << frames << " synthetic frames x " << repeat
            << ")\n  transform (BoW + direct index, level 2): "
            << transform_us / (static_cast<double>(frames) * repeat) << " us per frame (~"
            << count / frames << " descriptors)  [" << checksum % 10 << "]\n";
  return 0;
}

}  // namespace

Command add_vocab_train_command(CLI::App& vocab) {
  CLI::App* app = vocab.add_subcommand(
      "train",
      "train a bag-of-words vocabulary (hierarchical k-means over ORB descriptors, TF-IDF "
      "weights) from photographs and/or synthetic frames");
  auto flags = std::make_shared<TrainFlags>();
  app->add_option("--images", flags->images,
                  "directory of training images (read recursively: jpg, png; repeatable)");
  app->add_option("--synthetic-frames", flags->synthetic_frames,
                  "synthetic frames to add (20 per seed)")
      ->check(in_range(0, 1000000))
      ->capture_default_str();
  app->add_option("--synthetic-seed", flags->synthetic_seed,
                  "first synth seed (>= 1000: seeds below are reserved for tests and benchmarks)")
      ->check(in_range(1000, 1000000000))
      ->capture_default_str();
  app->add_option("--out", flags->out, "vocabulary file to write")->required();
  app->add_option("--k", flags->params.branching, "branching factor")
      ->check(in_range(2, 64))
      ->capture_default_str();
  app->add_option("--levels", flags->params.levels, "tree depth L")
      ->check(in_range(1, 8))
      ->capture_default_str();
  app->add_option("--max-descriptors", flags->max_descriptors,
                  "random subsample of descriptors for k-means")
      ->check(in_range(2, 100000000))
      ->capture_default_str();
  app->add_option("--iterations", flags->params.max_iterations,
                  "k-means iterations per node (at most)")
      ->check(in_range(1, 1000))
      ->capture_default_str();
  app->add_option("--seed", flags->params.seed, "random seed (subsampling, k-means++)")
      ->check(in_range(uint64_t{0}, uint64_t{4294967295}))
      ->capture_default_str();
  return {app, [flags](const GlobalOptions& global) {
            TrainFlags run = *flags;
            run.progress = !global.quiet;
            return train(run);
          }};
}

Command add_vocab_info_command(CLI::App& vocab) {
  CLI::App* app = vocab.add_subcommand(
      "info", "load a vocabulary, print its shape, load time and lookup speed");
  auto flags = std::make_shared<InfoFlags>();
  app->add_option("--vocabulary", flags->vocabulary, "vocabulary file")->required();
  app->add_option("--frames", flags->frames, "synthetic frames to time lookups on")
      ->check(in_range(1, 300))
      ->capture_default_str();
  app->add_option("--repeat", flags->repeat, "lookup passes over the descriptors")
      ->check(in_range(1, 1000))
      ->capture_default_str();
  return {app, [flags](const GlobalOptions&) { return info(*flags); }};
}

}  // namespace pspslam::cli
