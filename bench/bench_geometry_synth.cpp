// Geometry module (paper III.C) on `pspslam synth` sequences rendered in memory, with the
// project's ORB extractor as the candidate source and the synth masks as ground truth
// (label != 0 = dynamic). Plain table output; numbers and commands in docs/geometry.md.
//
//   bench_geometry_synth [--seeds N] [--frames-per-seed N] [--bodies N] [--pose_noise_mm X]
//                        [--pose_noise_deg X] [--key value ...]   (GeometryParams overrides)
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <map>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "geometry_bench_common.h"
#include "pspslam/feature/orb_extractor.h"
#include "pspslam/geometry/geometry_stage.h"
#include "pspslam/synth/scene.h"

namespace {

using namespace pspslam;

struct Options {
  int seeds = 3;
  int frames_per_seed = 8;
  int bodies = 3;
  double pose_noise_mm = 0.0;
  double pose_noise_deg = 0.0;
  std::vector<std::pair<std::string, double>> overrides;
};

using bench::apply_geometry_override;
using bench::perturbed;

struct Frame {
  std::vector<DepthView> references;
  cv::Mat depth, labels;
  Pose T_world_camera;
  std::vector<Eigen::Vector2d> keypoints;
};

struct Counts {
  long tp = 0, fp = 0, fn = 0, test_tp = 0, test_fp = 0, test_fn = 0, tested = 0, points = 0;
  std::vector<double> cpu_ms, search_cpu_ms;
  double recall() const { return double(tp) / std::max(1L, tp + fn); }
  double precision() const { return double(tp) / std::max(1L, tp + fp); }
  double test_recall() const { return double(test_tp) / std::max(1L, test_tp + test_fn); }
  double test_precision() const { return double(test_tp) / std::max(1L, test_tp + test_fp); }
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

Counts run(const GeometryParams& params, const PinholeCamera& camera,
           const std::vector<Frame>& frames, std::vector<std::uint8_t>* tested_dynamic) {
  Counts c;
  GeometryStage stage(camera, params);
  for (const Frame& f : frames) {
    GeometryFrameInput input;
    input.depth = f.depth;
    input.T_world_camera = f.T_world_camera;
    input.keypoints = f.keypoints;
    input.references = f.references;
    const GeometryFrameResult r = stage.process(input);
    for (size_t i = 0; i < f.keypoints.size(); ++i) {
      const bool truth = f.labels.at<std::uint8_t>(int(f.keypoints[i].y() + 0.5),
                                                   int(f.keypoints[i].x() + 0.5)) != 0;
      const bool flag = r.keypoint_dynamic[i], test = r.keypoint_tested_dynamic[i];
      c.tp += truth && flag;
      c.fp += !truth && flag;
      c.fn += truth && !flag;
      c.test_tp += truth && test;
      c.test_fp += !truth && test;
      c.test_fn += truth && !test;
      if (tested_dynamic) tested_dynamic->push_back(test);
    }
    c.tested += r.tested_count;
    c.points += long(f.keypoints.size());
    c.cpu_ms.push_back(r.timing.total_cpu_ms);
    c.search_cpu_ms.push_back(r.timing.search_cpu_ms);
  }
  return c;
}

void row(const char* name, const Counts& c) {
  std::printf("%-12s %7.3f %7.3f %7.3f %7.3f %7.3f %8.3f %10.3f\n", name, c.recall(), c.precision(),
              c.test_recall(), c.test_precision(), double(c.tested) / std::max(1L, c.points),
              median(c.cpu_ms), median(c.search_cpu_ms));
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = std::string(argv[i]).substr(2);
    const double value = std::stod(argv[i + 1]);
    if (key == "seeds")
      o.seeds = int(value);
    else if (key == "frames-per-seed")
      o.frames_per_seed = int(value);
    else if (key == "bodies")
      o.bodies = int(value);
    else if (key == "pose_noise_mm")
      o.pose_noise_mm = value;
    else if (key == "pose_noise_deg")
      o.pose_noise_deg = value;
    else
      o.overrides.emplace_back(key, value);
  }
  GeometryParams params;
  for (const auto& [k, v] : o.overrides) apply_geometry_override(params, k, v);

  std::vector<Frame> frames;
  PinholeCamera camera;
  OrbExtractor orb(OrbConfig{});
  long dynamic_points = 0, all_points = 0;
  for (int seed = 1; seed <= o.seeds; ++seed) {
    SynthOptions so;
    so.frames = 60 + 12 * o.frames_per_seed;
    so.bodies = o.bodies;
    so.seed = static_cast<std::uint64_t>(seed);
    so.threads = 2;
    const SyntheticScene scene(so);
    camera = scene.camera();
    std::mt19937_64 rng(seed * 31);
    for (int k = 0; k < o.frames_per_seed; ++k) {
      const size_t current = 55 + 12 * static_cast<size_t>(k);
      Frame f;
      // Reference views: earlier frames every 10, up to 5 (keyframe-like spacing).
      for (int r = 1; r <= 5; ++r) {
        SynthFrame ref;
        scene.render(current - 10 * r, ref, 2);
        f.references.push_back(
            {perturbed(ref.T_world_camera, o.pose_noise_mm, o.pose_noise_deg, rng),
             ref.depth_sensor.clone()});
      }
      SynthFrame now;
      scene.render(current, now, 2);
      f.depth = now.depth_sensor.clone();
      f.labels = now.labels.clone();
      f.T_world_camera = perturbed(now.T_world_camera, o.pose_noise_mm, o.pose_noise_deg, rng);
      cv::Mat gray;
      cv::cvtColor(now.bgr, gray, cv::COLOR_BGR2GRAY);
      OrbFeatures features;
      orb.extract(gray, cv::Mat(), features);
      for (const cv::KeyPoint& kp : features.keypoints) {
        const int u = int(kp.pt.x + 0.5f), v = int(kp.pt.y + 0.5f);
        if (u < 0 || v < 0 || u >= f.depth.cols || v >= f.depth.rows) continue;
        if (!(f.depth.at<float>(v, u) > 0.0f)) continue;  // candidates need a depth reading
        f.keypoints.emplace_back(kp.pt.x, kp.pt.y);
        dynamic_points += f.labels.at<std::uint8_t>(v, u) != 0;
        ++all_points;
      }
      frames.push_back(std::move(f));
    }
  }
  std::printf(
      "synth: %d seeds x %d frames, %d bodies, pose noise %.1f mm / %.2f deg; %.0f ORB "
      "candidates/frame, dynamic share %.3f\n",
      o.seeds, o.frames_per_seed, o.bodies, o.pose_noise_mm, o.pose_noise_deg,
      double(all_points) / frames.size(), double(dynamic_points) / std::max(1L, all_points));
  std::printf("%-12s %7s %7s %7s %7s %7s %8s %10s\n", "strategy", "recall", "prec", "t_rec",
              "t_prec", "tested", "cpu_ms", "search_cpu");
  GeometryParams ant = params, exhaustive = params;
  ant.search.strategy = SearchStrategy::ant_colony;
  exhaustive.search.strategy = SearchStrategy::exhaustive;
  std::vector<double> ratios, search_ratios;
  Counts ca, ce;
  std::vector<std::uint8_t> flags_ant, flags_exhaustive;
  for (int repeat = 0; repeat < 5; ++repeat) {
    flags_ant.clear();
    flags_exhaustive.clear();
    ce = run(exhaustive, camera, frames, &flags_exhaustive);
    ca = run(ant, camera, frames, &flags_ant);
    ratios.push_back(median(ca.cpu_ms) / median(ce.cpu_ms));
    search_ratios.push_back(median(ca.search_cpu_ms) / median(ce.search_cpu_ms));
  }
  row("exhaustive", ce);
  row("ant_colony", ca);
  long kept = 0, found = 0;
  for (size_t i = 0; i < flags_exhaustive.size(); ++i) {
    found += flags_exhaustive[i];
    kept += flags_exhaustive[i] && flags_ant[i];
  }
  std::printf(
      "ant colony keeps %.3f of the exhaustive test's dynamic detections (%ld of %ld); "
      "time ratio ant/exhaustive (median of 5 runs): module %.3f, search %.3f\n",
      double(kept) / std::max(1L, found), kept, found, median(ratios), median(search_ratios));
  return 0;
}
