// Geometry module (paper III.C) on `pspslam synth` sequences rendered in memory, with the
// project's ORB extractor as the candidate source and the synth masks as ground truth
// (label != 0 = dynamic). Plain table output; numbers and commands in docs/geometry.md.
//
// The benchmark set: for each seed, `runs` runs of `run-length` consecutive frames (the first
// run starts at frame 100, the next ones `run-gap` frames later), processed in order as the SLAM
// system does: each frame gets the previous frame's dynamic mask, warped by the compensated
// homography of ORB matches, as its priority prior (none for a run's first frame). The reference
// pool is the frames 5, 10, ..., 5 * pool-size before the current one (keyframe-like spacing);
// the stage picks `max_reference_views` of them by coverage (reference_selection.h).
// --reference-mode 1 instead passes exactly the frames 10, 20, ..., 50 before (the old set-up).
//
//   bench_geometry_synth [--seeds N] [--runs N] [--run-length N] [--run-gap N] [--pool-size N]
//                        [--reference-mode 0|1] [--bodies N] [--pose_noise_mm X]
//                        [--pose_noise_deg X] [--diagnose 1] [--repeats N] [--key value ...]
//                        [--sweep KEY:v1,v2,...]
//   (other keys are GeometryParams overrides, geometry_bench_common.h)
#include <algorithm>
#include <cstdio>
#include <map>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "geometry_bench_common.h"
#include "pspslam/feature/orb_extractor.h"
#include "pspslam/geometry/geometry_stage.h"
#include "pspslam/geometry/multiview_test.h"
#include "pspslam/synth/scene.h"

namespace {

using namespace pspslam;

struct Options {
  int seeds = 4;
  int runs = 3;
  int run_length = 8;
  int run_gap = 60;
  int pool_size = 20;
  int reference_mode = 0;
  int bodies = 3;
  int diagnose = 0;
  int repeats = 5;
  int bookkeeping = 0;  // --bookkeeping 1: split the search time into its own cost and the tests
  double pose_noise_mm = 0.0;
  double pose_noise_deg = 0.0;
  std::vector<std::pair<std::string, double>> overrides;
  // --sweep KEY:v1,v2,...: the comparison is repeated for each value (frames rendered once);
  // several --sweep flags are run one after the other, each from the base parameters.
  std::vector<std::pair<std::string, std::vector<double>>> sweeps;
};

using bench::apply_geometry_override;
using bench::perturbed;

struct Frame {
  bool run_start = false;
  std::vector<DepthView> references;
  std::vector<cv::Mat> reference_labels;
  cv::Mat depth, labels;
  Pose T_world_camera;
  std::vector<Eigen::Vector2d> keypoints;
  Eigen::Matrix3d H_previous_to_current = Eigen::Matrix3d::Identity();
  bool have_H = false;
};

struct Counts {
  long tp = 0, fp = 0, fn = 0, test_tp = 0, test_fp = 0, test_fn = 0, tested = 0, points = 0;
  std::vector<double> cpu_ms, search_cpu_ms, selection_cpu_ms, region_cpu_ms;
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

// One strategy's stage over the frames in order, chaining each frame's previous mask like
// System does.
struct StrategyRun {
  StrategyRun(const GeometryParams& params, const PinholeCamera& camera) : stage(camera, params) {}
  GeometryStage stage;
  cv::Mat previous_mask;
  Counts c;

  // Appends each keypoint's test verdict to `tested_dynamic` and its final verdict (tested
  // dynamic or inside the grown mask: what SLAM uses) to `final_dynamic`.
  void step(const Frame& f, std::vector<std::uint8_t>* tested_dynamic,
            std::vector<std::uint8_t>* final_dynamic, std::vector<std::vector<int>>* priorities) {
    GeometryFrameInput input;
    input.depth = f.depth;
    input.T_world_camera = f.T_world_camera;
    input.keypoints = f.keypoints;
    input.references = f.references;
    if (!f.run_start && !previous_mask.empty() && f.have_H)
      input.previous_dynamic_mask =
          warp_to_current(previous_mask, f.H_previous_to_current, f.depth.size(), true);
    if (priorities) {
      // The stage's priority points: inside the previous mask (no matches given here, so the
      // stage maps pixels with the identity, as below).
      std::vector<int>& priority = priorities->emplace_back();
      const cv::Mat& mask = input.previous_dynamic_mask;
      for (size_t i = 0; i < f.keypoints.size() && !mask.empty(); ++i) {
        const int u = int(std::floor(f.keypoints[i].x())), v = int(std::floor(f.keypoints[i].y()));
        if (u >= 0 && v >= 0 && u < mask.cols && v < mask.rows && mask.at<std::uint8_t>(v, u))
          priority.push_back(int(i));
      }
    }
    const GeometryFrameResult r = stage.process(input);
    previous_mask = r.dynamic_mask;
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
      if (final_dynamic) final_dynamic->push_back(flag);
    }
    c.tested += r.tested_count;
    c.points += long(f.keypoints.size());
    c.cpu_ms.push_back(r.timing.total_cpu_ms);
    c.search_cpu_ms.push_back(r.timing.search_cpu_ms);
    c.selection_cpu_ms.push_back(r.timing.selection_cpu_ms);
    c.region_cpu_ms.push_back(r.timing.region_cpu_ms);
  }
};

// Both strategies frame by frame in one pass, so both see the same machine load; the one that
// runs first on a frame reads the reference depth images out of cache, so the order alternates
// (frame by frame, and between passes via `first_ant`).
void run_both(const GeometryParams& ant, const GeometryParams& exhaustive,
              const PinholeCamera& camera, const std::vector<Frame>& frames, bool first_ant,
              Counts& ca, Counts& ce, std::vector<std::uint8_t>& flags_ant,
              std::vector<std::uint8_t>& flags_exhaustive, std::vector<std::uint8_t>& final_ant,
              std::vector<std::uint8_t>& final_exhaustive,
              std::vector<std::vector<int>>& priorities) {
  StrategyRun a(ant, camera), e(exhaustive, camera);
  for (size_t k = 0; k < frames.size(); ++k) {
    if ((k % 2 == 0) == first_ant) {
      a.step(frames[k], &flags_ant, &final_ant, &priorities);
      e.step(frames[k], &flags_exhaustive, &final_exhaustive, nullptr);
    } else {
      e.step(frames[k], &flags_exhaustive, &final_exhaustive, nullptr);
      a.step(frames[k], &flags_ant, &final_ant, &priorities);
    }
  }
  ca = std::move(a.c);
  ce = std::move(e.c);
}

// Why does the multi-view test miss dynamic keypoints? Each ground-truth dynamic keypoint the
// test calls static (with the references the stage would select) is put in one class, from what
// its references show at the projected pixel (reference labels are ground truth).
void diagnose(const GeometryParams& params, const PinholeCamera& camera,
              const std::vector<Frame>& frames) {
  MultiViewTest test(camera, params.multiview);
  ReferenceSelector selector(
      camera, {params.multiview.max_reference_views, params.references.wanted_coverage,
               params.references.point_stride, params.multiview.reference_patch_radius,
               params.multiview.max_parallax_deg, params.references.older_view_gain_share});
  long dynamic = 0, caught = 0, no_valid = 0, all_refs_on_mover = 0, some_static = 0;
  long mostly_closer = 0;
  std::vector<CandidatePoint> candidates;
  std::vector<DepthView> views;
  std::vector<const cv::Mat*> view_labels;
  for (const Frame& f : frames) {
    candidates.clear();
    for (const Eigen::Vector2d& kp : f.keypoints)
      candidates.push_back({kp, f.depth.at<float>(int(kp.y() + 0.5), int(kp.x() + 0.5))});
    views.clear();
    view_labels.clear();
    for (int v : selector.select(f.T_world_camera, candidates, f.references)) {
      views.push_back(f.references[v]);
      view_labels.push_back(&f.reference_labels[v]);
    }
    test.set_frame(f.T_world_camera, views);
    for (const CandidatePoint& point : candidates) {
      const int u = int(point.pixel.x() + 0.5), v = int(point.pixel.y() + 0.5);
      if (f.labels.at<std::uint8_t>(v, u) == 0) continue;
      ++dynamic;
      const MultiViewVerdict verdict = test.evaluate(point);
      if (verdict.dynamic) {
        ++caught;
      } else if (verdict.valid_references == 0) {
        ++no_valid;
      } else {
        const Eigen::Vector3d p_world =
            f.T_world_camera * camera.unproject(point.pixel, point.depth);
        int on_mover = 0, projected = 0, closer = 0;
        for (size_t r = 0; r < views.size(); ++r) {
          const Eigen::Vector3d p_ref = views[r].T_world_camera.inverse() * p_world;
          if (p_ref.z() <= 0.1) continue;
          const Eigen::Vector2d px = camera.project(p_ref);
          const int ru = int(px.x() + 0.5), rv = int(px.y() + 0.5);
          if (ru < 0 || rv < 0 || ru >= f.depth.cols || rv >= f.depth.rows) continue;
          ++projected;
          on_mover += view_labels[r]->at<std::uint8_t>(rv, ru) != 0;
          const float measured = views[r].depth.at<float>(rv, ru);
          closer += measured > 0.0f && measured < p_ref.z() - 0.04 - 0.04 * p_ref.z();
        }
        if (on_mover == projected) {
          ++all_refs_on_mover;
          if (closer * 2 > projected) ++mostly_closer;
        } else
          ++some_static;
      }
    }
  }
  std::printf(
      "diagnosis (the test alone on every ground-truth dynamic keypoint): %ld, caught %ld; "
      "missed: no valid reference %ld, every reference shows a mover at the projection %ld (in "
      "most of them closer than the point: %ld), some reference shows static background %ld\n",
      dynamic, caught, no_valid, all_refs_on_mover, mostly_closer, some_static);
}

double thread_cpu_ms() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return double(now.tv_sec) * 1e3 + double(now.tv_nsec) * 1e-6;
}

// Where does the search's time go? Replays each frame's search with the exhaustive run's verdicts
// (a table look-up instead of the multi-view test) — the search's own cost — and times the real
// test separately on dynamic and static points (with the references the stage selects). Thread
// CPU medians per frame over `repeats` passes.
void bookkeeping_report(const GeometryParams& params, const PinholeCamera& camera,
                        const std::vector<Frame>& frames,
                        const std::vector<std::uint8_t>& verdict_flags,
                        const std::vector<std::vector<int>>& priorities, int repeats) {
  std::vector<double> own_ant, own_exhaustive, test_dynamic_us, test_static_us;
  std::vector<std::vector<double>> per_frame_ant(frames.size()), per_frame_exh(frames.size());
  std::vector<Eigen::Vector2f> points;
  long communities = 0, rounds = 0, runs = 0;
  // The replay is cheap, so it is repeated 20x more often than the stage runs (steadier medians).
  for (int pass = 0; pass < 20 * std::max(1, repeats); ++pass) {
    AntColonyParams ant = params.search, exhaustive = params.search;
    ant.strategy = SearchStrategy::ant_colony;
    exhaustive.strategy = SearchStrategy::exhaustive;
    DynamicPointSearch ant_search(ant), exhaustive_search(exhaustive);
    size_t offset = 0;
    for (size_t k = 0; k < frames.size(); ++k) {
      const Frame& f = frames[k];
      points.clear();
      for (const Eigen::Vector2d& p : f.keypoints) points.push_back(p.cast<float>());
      const std::uint8_t* verdicts = verdict_flags.data() + offset;
      offset += f.keypoints.size();
      const PointPredicate lookup = [verdicts](int i) { return verdicts[i] != 0; };
      double t0 = thread_cpu_ms();
      exhaustive_search.run(points, f.depth.size(), lookup);
      per_frame_exh[k].push_back(thread_cpu_ms() - t0);
      t0 = thread_cpu_ms();
      const SearchResult& r = ant_search.run(points, f.depth.size(), lookup, priorities[k]);
      per_frame_ant[k].push_back(thread_cpu_ms() - t0);
      communities += r.communities;
      rounds += r.band_rounds;
      runs += 1;
    }
  }
  for (size_t k = 0; k < frames.size(); ++k) {
    own_ant.push_back(median(per_frame_ant[k]));
    own_exhaustive.push_back(median(per_frame_exh[k]));
  }
  MultiViewTest test(camera, params.multiview);
  ReferenceSelector selector(
      camera, {params.multiview.max_reference_views, params.references.wanted_coverage,
               params.references.point_stride, params.multiview.reference_patch_radius,
               params.multiview.max_parallax_deg, params.references.older_view_gain_share});
  std::vector<CandidatePoint> candidates;
  std::vector<DepthView> views;
  size_t offset = 0;
  for (const Frame& f : frames) {
    candidates.clear();
    for (const Eigen::Vector2d& kp : f.keypoints)
      candidates.push_back({kp, f.depth.at<float>(int(kp.y() + 0.5), int(kp.x() + 0.5))});
    views.clear();
    for (int v : selector.select(f.T_world_camera, candidates, f.references))
      views.push_back(f.references[v]);
    test.set_frame(f.T_world_camera, views);
    for (int want = 0; want < 2; ++want) {
      int count = 0, sink = 0;
      const double t0 = thread_cpu_ms();
      for (int pass = 0; pass < 5; ++pass) {
        for (size_t i = 0; i < candidates.size(); ++i) {
          if (verdict_flags[offset + i] != want) continue;
          sink += test.is_dynamic(candidates[i]);
          ++count;
        }
      }
      const double us = (thread_cpu_ms() - t0) * 1e3 / std::max(1, count);
      if (count > 0) (want ? test_dynamic_us : test_static_us).push_back(us + 0.0 * sink);
    }
    offset += f.keypoints.size();
  }
  std::printf(
      "search's own cost (verdicts looked up), cpu median per frame: ant colony %.4f ms, "
      "exhaustive %.4f ms (%.1f communities, %.1f band rounds per frame); multi-view test per "
      "point: dynamic %.3f us, static %.3f us\n",
      median(own_ant), median(own_exhaustive), double(communities) / std::max(1L, runs),
      double(rounds) / std::max(1L, runs), median(test_dynamic_us), median(test_static_us));
}

void row(const char* name, const Counts& c) {
  std::printf("%-12s %7.3f %7.3f %7.3f %7.3f %7.3f %8.3f %10.3f %9.3f %9.3f\n", name, c.recall(),
              c.precision(), c.test_recall(), c.test_precision(),
              double(c.tested) / std::max(1L, c.points), median(c.cpu_ms), median(c.search_cpu_ms),
              median(c.selection_cpu_ms), median(c.region_cpu_ms));
}

// Rendered frames of one seed, each index rendered once (pool frames are shared).
class RenderCache {
 public:
  explicit RenderCache(const SyntheticScene& scene) : scene_(scene) {}
  const SynthFrame& get(size_t index) {
    auto it = frames_.find(index);
    if (it == frames_.end()) {
      it = frames_.emplace(index, SynthFrame{}).first;
      scene_.render(index, it->second, 2);
    }
    return it->second;
  }

 private:
  const SyntheticScene& scene_;
  std::map<size_t, SynthFrame> frames_;
};

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = std::string(argv[i]).substr(2);
    if (key == "sweep") {
      const std::string spec = argv[i + 1];
      const size_t colon = spec.find(':');
      std::vector<double> values;
      for (size_t at = colon + 1; at < spec.size();) {
        const size_t comma = std::min(spec.find(',', at), spec.size());
        values.push_back(std::stod(spec.substr(at, comma - at)));
        at = comma + 1;
      }
      o.sweeps.emplace_back(spec.substr(0, colon), values);
      continue;
    }
    const double value = std::stod(argv[i + 1]);
    if (key == "seeds")
      o.seeds = int(value);
    else if (key == "runs")
      o.runs = int(value);
    else if (key == "run-length")
      o.run_length = int(value);
    else if (key == "run-gap")
      o.run_gap = int(value);
    else if (key == "pool-size")
      o.pool_size = int(value);
    else if (key == "reference-mode")
      o.reference_mode = int(value);
    else if (key == "bodies")
      o.bodies = int(value);
    else if (key == "diagnose")
      o.diagnose = int(value);
    else if (key == "repeats")
      o.repeats = int(value);
    else if (key == "bookkeeping")
      o.bookkeeping = int(value);
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
  cv::BFMatcher matcher(cv::NORM_HAMMING, true);
  long dynamic_points = 0, all_points = 0;
  for (int seed = 1; seed <= o.seeds; ++seed) {
    SynthOptions so;
    so.frames = static_cast<size_t>(100 + o.run_gap * o.runs + o.run_length);
    so.bodies = o.bodies;
    so.seed = static_cast<std::uint64_t>(seed);
    so.threads = 2;
    const SyntheticScene scene(so);
    camera = scene.camera();
    RenderCache cache(scene);
    std::mt19937_64 rng(seed * 31);
    for (int run_index = 0; run_index < o.runs; ++run_index) {
      OrbFeatures previous_features;
      for (int k = 0; k < o.run_length; ++k) {
        const size_t current = 100 + static_cast<size_t>(o.run_gap * run_index + k);
        Frame f;
        f.run_start = k == 0;
        std::vector<size_t> reference_frames;
        if (o.reference_mode == 1) {
          for (int r = 1; r <= 5; ++r) reference_frames.push_back(current - 10 * r);
        } else {
          // Newest first: keyframes every 5 frames before the current one.
          for (size_t r = (current - 1) / 5 * 5; reference_frames.size() < size_t(o.pool_size);
               r -= 5) {
            reference_frames.push_back(r);
            if (r < 5) break;
          }
        }
        for (size_t index : reference_frames) {
          const SynthFrame& ref = cache.get(index);
          f.references.push_back(
              {perturbed(ref.T_world_camera, o.pose_noise_mm, o.pose_noise_deg, rng),
               ref.depth_sensor});
          f.reference_labels.push_back(ref.labels);
        }
        const SynthFrame& now = cache.get(current);
        f.depth = now.depth_sensor;
        f.labels = now.labels;
        f.T_world_camera = perturbed(now.T_world_camera, o.pose_noise_mm, o.pose_noise_deg, rng);
        cv::Mat gray;
        cv::cvtColor(now.bgr, gray, cv::COLOR_BGR2GRAY);
        OrbFeatures features;
        orb.extract(gray, cv::Mat(), features);
        OrbFeatures kept;
        for (size_t i = 0; i < features.keypoints.size(); ++i) {
          const cv::KeyPoint& kp = features.keypoints[i];
          const int u = int(kp.pt.x + 0.5f), v = int(kp.pt.y + 0.5f);
          if (u < 0 || v < 0 || u >= f.depth.cols || v >= f.depth.rows) continue;
          if (!(f.depth.at<float>(v, u) > 0.0f)) continue;  // candidates need a depth reading
          f.keypoints.emplace_back(kp.pt.x, kp.pt.y);
          kept.keypoints.push_back(kp);
          kept.descriptors.push_back(features.descriptors.row(static_cast<int>(i)));
          dynamic_points += f.labels.at<std::uint8_t>(v, u) != 0;
          ++all_points;
        }
        // Camera-motion compensation previous -> current from ORB matches (System does this
        // with LK flow before the stage; it is not part of the stage's time there either).
        if (!f.run_start && !previous_features.keypoints.empty()) {
          std::vector<cv::DMatch> matches;
          matcher.match(previous_features.descriptors, kept.descriptors, matches);
          std::vector<Eigen::Vector2d> x, y;
          for (const cv::DMatch& m : matches) {
            if (m.distance >= 50) continue;
            const cv::Point2f& a = previous_features.keypoints[m.queryIdx].pt;
            const cv::Point2f& b = kept.keypoints[m.trainIdx].pt;
            x.emplace_back(a.x, a.y);
            y.emplace_back(b.x, b.y);
          }
          if (x.size() >= 8) {
            const CompensatedHomography h =
                estimate_compensated_homography(x, y, params.homography);
            f.have_H = h.valid;
            if (h.valid) f.H_previous_to_current = h.H;
          }
        }
        previous_features = std::move(kept);
        frames.push_back(std::move(f));
      }
    }
  }
  std::printf(
      "synth: %d seeds x %d runs x %d consecutive frames (%zu frames), %d bodies, pose noise "
      "%.1f mm / %.2f deg, reference %s; %.0f ORB candidates/frame, dynamic share %.3f\n",
      o.seeds, o.runs, o.run_length, frames.size(), o.bodies, o.pose_noise_mm, o.pose_noise_deg,
      o.reference_mode == 1 ? "frames 10..50 before" : "pool, coverage selection",
      double(all_points) / frames.size(), double(dynamic_points) / std::max(1L, all_points));
  if (o.diagnose) diagnose(params, camera, frames);
  const auto compare = [&](const GeometryParams& base) {
    std::printf("%-12s %7s %7s %7s %7s %7s %8s %10s %9s %9s\n", "strategy", "recall", "prec",
                "t_rec", "t_prec", "tested", "cpu_ms", "search_cpu", "select", "region");
    GeometryParams ant = base, exhaustive = base;
    ant.search.strategy = SearchStrategy::ant_colony;
    exhaustive.search.strategy = SearchStrategy::exhaustive;
    std::vector<double> ratios, search_ratios;
    Counts ca, ce;
    std::vector<std::uint8_t> flags_ant, flags_exhaustive, final_ant, final_exhaustive;
    std::vector<std::vector<int>> priorities;
    for (int repeat = 0; repeat < std::max(1, o.repeats); ++repeat) {
      for (std::vector<std::uint8_t>* v :
           {&flags_ant, &flags_exhaustive, &final_ant, &final_exhaustive})
        v->clear();
      priorities.clear();
      run_both(ant, exhaustive, camera, frames, repeat % 2 == 0, ca, ce, flags_ant,
               flags_exhaustive, final_ant, final_exhaustive, priorities);
      ratios.push_back(median(ca.cpu_ms) / median(ce.cpu_ms));
      search_ratios.push_back(median(ca.search_cpu_ms) / median(ce.search_cpu_ms));
    }
    row("exhaustive", ce);
    row("ant_colony", ca);
    // "Kept" on the test's own detections and on the final verdicts (tested dynamic or in the
    // grown mask), which is what SLAM uses.
    const auto kept_share = [](const std::vector<std::uint8_t>& ex,
                               const std::vector<std::uint8_t>& an, long& kept, long& found) {
      kept = found = 0;
      for (size_t i = 0; i < ex.size(); ++i) {
        found += ex[i];
        kept += ex[i] && an[i];
      }
      return double(kept) / std::max(1L, found);
    };
    long kept = 0, found = 0, kept_final = 0, found_final = 0;
    const double kept_tested = kept_share(flags_exhaustive, flags_ant, kept, found);
    const double kept_verdicts = kept_share(final_exhaustive, final_ant, kept_final, found_final);
    std::printf(
        "ant colony keeps %.3f of the exhaustive test's dynamic detections (%ld of %ld) and %.3f "
        "of its final dynamic verdicts (%ld of %ld); time ratio ant/exhaustive (median of %d "
        "runs): module %.3f, search %.3f\n",
        kept_tested, kept, found, kept_verdicts, kept_final, found_final, std::max(1, o.repeats),
        median(ratios), median(search_ratios));
    if (o.bookkeeping)
      bookkeeping_report(base, camera, frames, flags_exhaustive, priorities, o.repeats);
  };
  if (o.sweeps.empty()) compare(params);
  for (const auto& [key, values] : o.sweeps) {
    for (double value : values) {
      GeometryParams swept = params;
      apply_geometry_override(swept, key, value);
      std::printf("--- %s = %g\n", key.c_str(), value);
      compare(swept);
    }
  }
  return 0;
}
