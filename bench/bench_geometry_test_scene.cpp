// Accuracy / cost of the geometry module (paper III.C) on the analytic synthetic scene with
// ground-truth labels (pspslam::GeometryTestScene). Plain table output; see docs/geometry.md.
//
//   bench_geometry_synthetic [--frames N] [--seeds S] [--width W] [--sweep NAME] [--key value ...]
//
// Keys override GeometryParams fields by name (e.g. --depth_threshold_relative 0.03).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "geometry_bench_common.h"
#include "pspslam/geometry/geometry_stage.h"
#include "pspslam/geometry/test_scene.h"

namespace {

using namespace pspslam;

struct Metrics {
  long tp = 0, fp = 0, fn = 0, tn = 0;         // final per-keypoint flags
  long test_tp = 0, test_fp = 0, test_fn = 0;  // tested-dynamic flags only
  long tested = 0, candidates = 0;
  std::vector<double> total_ms, search_ms, region_ms;
  void add(const Metrics& o) {
    tp += o.tp;
    fp += o.fp;
    fn += o.fn;
    tn += o.tn;
    test_tp += o.test_tp;
    test_fp += o.test_fp;
    test_fn += o.test_fn;
    tested += o.tested;
    candidates += o.candidates;
    total_ms.insert(total_ms.end(), o.total_ms.begin(), o.total_ms.end());
    search_ms.insert(search_ms.end(), o.search_ms.begin(), o.search_ms.end());
    region_ms.insert(region_ms.end(), o.region_ms.begin(), o.region_ms.end());
  }
  double recall() const { return tp + fn ? double(tp) / (tp + fn) : 1.0; }
  double precision() const { return tp + fp ? double(tp) / (tp + fp) : 1.0; }
  double test_recall() const {
    return test_tp + test_fn ? double(test_tp) / (test_tp + test_fn) : 1.0;
  }
  double test_precision() const {
    return test_tp + test_fp ? double(test_tp) / (test_tp + test_fp) : 1.0;
  }
  double median_ms() const { return median(total_ms); }
  static double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  }
};

struct Options {
  int frames = 6;
  int seeds = 3;
  int width = 640;
  int keypoints = 1000;
  double pose_noise_mm = 0.0;
  double pose_noise_deg = 0.0;
  std::map<std::string, double> overrides;
};

using bench::apply_geometry_override;
using bench::perturbed;

struct CachedFrame {
  std::vector<DepthView> references;
  cv::Mat depth, labels;
  Pose T_world_camera;
  std::vector<Eigen::Vector2d> keypoints;
};

struct Dataset {
  PinholeCamera camera;
  std::vector<CachedFrame> frames;
  double dynamic_fraction = 0.0;
};

// Rendering dominates the run time, so frames are rendered once and every setting reuses them.
Dataset render_dataset(const Options& o) {
  Dataset data;
  const double scale = o.width / 640.0;
  data.camera.width = o.width;
  data.camera.height = int(480 * scale);
  data.camera.fx = data.camera.fy = 525.0 * scale;
  data.camera.cx = data.camera.width / 2.0 - 0.5;
  data.camera.cy = data.camera.height / 2.0 - 0.5;
  long dynamic = 0, total = 0;
  for (int seed = 1; seed <= o.seeds; ++seed) {
    GeometryTestSceneParams sp;
    sp.camera = data.camera;
    sp.seed = seed;
    const GeometryTestScene scene(sp);
    std::mt19937_64 rng(seed * 77);
    for (int f = 0; f < o.frames; ++f) {
      const int current = 50 + 7 * f;
      CachedFrame frame;
      for (int k = 1; k <= 5; ++k) {
        cv::Mat depth, labels;
        scene.render(current - 10 * k, depth, labels);
        frame.references.push_back(
            {perturbed(scene.camera_pose(current - 10 * k), o.pose_noise_mm, o.pose_noise_deg, rng),
             depth});
      }
      scene.render(current, frame.depth, frame.labels);
      frame.T_world_camera =
          perturbed(scene.camera_pose(current), o.pose_noise_mm, o.pose_noise_deg, rng);
      frame.keypoints = sample_candidate_pixels(frame.depth, o.keypoints, seed * 1000 + f);
      for (const Eigen::Vector2d& k : frame.keypoints) {
        dynamic += frame.labels.at<std::uint8_t>(int(k.y()), int(k.x())) != 0;
        ++total;
      }
      data.frames.push_back(std::move(frame));
    }
  }
  data.dynamic_fraction = double(dynamic) / std::max(1L, total);
  return data;
}

// Per-point flags of one setting over the whole dataset, for strategy comparisons.
struct RunFlags {
  std::vector<std::uint8_t> tested_dynamic;
};

Metrics evaluate(const GeometryParams& params, const Dataset& data, RunFlags* flags = nullptr) {
  Metrics total;
  GeometryStage stage(data.camera, params);
  for (const CachedFrame& frame : data.frames) {
    GeometryFrameInput input;
    input.depth = frame.depth;
    input.T_world_camera = frame.T_world_camera;
    input.keypoints = frame.keypoints;
    input.references = frame.references;
    timespec cpu_start{}, cpu_end{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu_start);
    const GeometryFrameResult r = stage.process(input);
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu_end);
    Metrics m;
    for (size_t i = 0; i < frame.keypoints.size(); ++i) {
      const bool truth = frame.labels.at<std::uint8_t>(int(frame.keypoints[i].y()),
                                                       int(frame.keypoints[i].x())) != 0;
      const bool flag = r.keypoint_dynamic[i];
      const bool tested_flag = r.keypoint_tested_dynamic[i];
      m.tp += truth && flag;
      m.fp += !truth && flag;
      m.fn += truth && !flag;
      m.tn += !truth && !flag;
      m.test_tp += truth && tested_flag;
      m.test_fp += !truth && tested_flag;
      m.test_fn += truth && !tested_flag;
      if (flags != nullptr) flags->tested_dynamic.push_back(tested_flag);
    }
    m.tested = r.tested_count;
    m.candidates = long(frame.keypoints.size());
    m.search_ms.push_back(r.timing.search_cpu_ms);
    m.region_ms.push_back(r.timing.region_cpu_ms);
    // Thread CPU time: the machine is shared (load ~7 per core), wall time mostly measures that.
    m.total_ms.push_back((cpu_end.tv_sec - cpu_start.tv_sec) * 1e3 +
                         (cpu_end.tv_nsec - cpu_start.tv_nsec) * 1e-6);
    total.add(m);
  }
  return total;
}

void print_header() {
  std::printf("%-34s %7s %7s %7s %7s %7s %8s %9s %9s\n", "setting", "recall", "prec", "t_rec",
              "t_prec", "tested", "cpu_ms", "search_cpu", "region_cpu");
}
void print_row(const std::string& name, const Metrics& m) {
  std::printf("%-34s %7.3f %7.3f %7.3f %7.3f %7.3f %8.2f %9.3f %9.3f\n", name.c_str(), m.recall(),
              m.precision(), m.test_recall(), m.test_precision(),
              double(m.tested) / std::max(1L, m.candidates), m.median_ms(),
              Metrics::median(m.search_ms), Metrics::median(m.region_ms));
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  std::string sweep;
  std::vector<std::pair<std::string, double>> overrides;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = std::string(argv[i]).substr(2);
    const std::string value = argv[i + 1];
    if (key == "frames")
      o.frames = std::stoi(value);
    else if (key == "seeds")
      o.seeds = std::stoi(value);
    else if (key == "width")
      o.width = std::stoi(value);
    else if (key == "keypoints")
      o.keypoints = std::stoi(value);
    else if (key == "pose_noise_mm")
      o.pose_noise_mm = std::stod(value);
    else if (key == "pose_noise_deg")
      o.pose_noise_deg = std::stod(value);
    else if (key == "sweep")
      sweep = value;
    else
      overrides.emplace_back(key, std::stod(value));
  }
  GeometryParams base;
  for (const auto& [k, v] : overrides) apply_geometry_override(base, k, v);
  const Dataset data = render_dataset(o);
  std::printf("frames %zu, candidates/frame %d, ground-truth dynamic fraction %.3f\n",
              data.frames.size(), o.keypoints, data.dynamic_fraction);
  print_header();
  if (sweep == "strategy") {
    // Ant colony vs exhaustive on the same frames: detections kept, tested share, time ratio.
    GeometryParams exhaustive = base, ant = base;
    exhaustive.search.strategy = SearchStrategy::exhaustive;
    ant.search.strategy = SearchStrategy::ant_colony;
    RunFlags exhaustive_flags, ant_flags;
    std::vector<double> ratios;
    Metrics me, ma;
    for (int repeat = 0; repeat < 5; ++repeat) {
      exhaustive_flags.tested_dynamic.clear();
      ant_flags.tested_dynamic.clear();
      me = evaluate(exhaustive, data, &exhaustive_flags);
      ma = evaluate(ant, data, &ant_flags);
      ratios.push_back(ma.median_ms() / me.median_ms());
    }
    print_row("exhaustive", me);
    print_row("ant_colony", ma);
    long kept = 0, found = 0;
    for (size_t i = 0; i < exhaustive_flags.tested_dynamic.size(); ++i) {
      found += exhaustive_flags.tested_dynamic[i];
      kept += exhaustive_flags.tested_dynamic[i] && ant_flags.tested_dynamic[i];
    }
    std::sort(ratios.begin(), ratios.end());
    std::printf(
        "ant colony keeps %.3f of exhaustive detections (%ld of %ld); time ratio (median of "
        "5 runs) %.3f\n",
        double(kept) / std::max(1L, found), kept, found, ratios[ratios.size() / 2]);
    return 0;
  }
  if (sweep.empty()) {
    print_row("current", evaluate(base, data));
    return 0;
  }
  // --sweep key:v1,v2,v3
  const size_t colon = sweep.find(':');
  const std::string key = sweep.substr(0, colon);
  std::string list = sweep.substr(colon + 1);
  size_t start = 0;
  while (start <= list.size()) {
    const size_t comma = list.find(',', start);
    const std::string item =
        list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    GeometryParams p = base;
    apply_geometry_override(p, key, std::stod(item));
    print_row(key + "=" + item, evaluate(p, data));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return 0;
}
