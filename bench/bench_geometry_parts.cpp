// Google Benchmark of the geometry module's parts on one synthetic frame (640x480, 1000
// candidates, 5 references): compensated homography, multi-view test, both search strategies,
// region growing, whole stage. Run by bench/experiments/geometry_timing.toml.
#include <benchmark/benchmark.h>

#include <random>

#include "pspslam/geometry/geometry_stage.h"
#include "support/geometry_test_scene.h"

namespace {

using namespace pspslam;

struct Frame {
  PinholeCamera camera;
  std::vector<DepthView> references;
  cv::Mat depth, labels;
  Pose T_world_camera;
  std::vector<Eigen::Vector2d> keypoints;
  std::vector<Eigen::Vector2f> points;
  std::vector<CandidatePoint> candidates;
  std::vector<Eigen::Vector2d> matched_previous, matched_current;
};

const Frame& frame() {
  static const Frame f = [] {
    Frame out;
    GeometryTestSceneParams sp;
    sp.seed = 1;
    const GeometryTestScene scene(sp);
    out.camera = sp.camera;
    const int current = 64;
    for (int k = 1; k <= 5; ++k) {
      cv::Mat labels;
      DepthView view;
      scene.render(current - 10 * k, view.depth, labels);
      view.T_world_camera = scene.camera_pose(current - 10 * k);
      out.references.push_back(view);
    }
    scene.render(current, out.depth, out.labels);
    out.T_world_camera = scene.camera_pose(current);
    out.keypoints = sample_candidate_pixels(out.depth, 1000, 5);
    for (const Eigen::Vector2d& k : out.keypoints) {
      out.points.push_back(k.cast<float>());
      out.candidates.push_back({k, out.depth.at<float>(int(k.y()), int(k.x()))});
    }
    // 500 matches of a mild homography with 0.5 px noise and 20% outliers.
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0, 640), v(0, 480), coin(0, 1);
    std::normal_distribution<double> noise(0, 0.5);
    Eigen::Matrix3d H;
    H << 1.01, 0.02, 4.0, -0.01, 0.995, -3.0, 1e-5, -2e-5, 1.0;
    for (int i = 0; i < 500; ++i) {
      const Eigen::Vector2d x(u(rng), v(rng));
      Eigen::Vector2d y = transfer_point(H, x) + Eigen::Vector2d(noise(rng), noise(rng));
      if (coin(rng) < 0.2) y = {u(rng), v(rng)};
      out.matched_previous.push_back(x);
      out.matched_current.push_back(y);
    }
    return out;
  }();
  return f;
}

void BM_CompensatedHomography(benchmark::State& state) {
  const Frame& f = frame();
  HomographyParams params;
  params.lm_max_iterations = static_cast<int>(state.range(0));
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        estimate_compensated_homography(f.matched_previous, f.matched_current, params));
  }
}
BENCHMARK(BM_CompensatedHomography)->Arg(0)->Arg(30)->Unit(benchmark::kMicrosecond);

void BM_MultiViewTestAllPoints(benchmark::State& state) {
  const Frame& f = frame();
  MultiViewTest test(f.camera, MultiViewParams{});
  test.set_frame(f.T_world_camera, f.references);
  for (auto _ : state) {
    int dynamic = 0;
    for (const CandidatePoint& c : f.candidates) dynamic += test.is_dynamic(c);
    benchmark::DoNotOptimize(dynamic);
  }
}
BENCHMARK(BM_MultiViewTestAllPoints)->Unit(benchmark::kMicrosecond);

void BM_Search(benchmark::State& state) {
  const Frame& f = frame();
  AntColonyParams params;
  params.strategy = state.range(0) ? SearchStrategy::exhaustive : SearchStrategy::ant_colony;
  DynamicPointSearch search(params);
  MultiViewTest test(f.camera, MultiViewParams{});
  test.set_frame(f.T_world_camera, f.references);
  const PointPredicate predicate = [&](int i) { return test.is_dynamic(f.candidates[i]); };
  const SearchResult* result = nullptr;
  for (auto _ : state) result = &search.run(f.points, f.depth.size(), predicate);
  state.counters["tested"] = result->tested_count;
  state.counters["dynamic"] = result->dynamic_count;
  state.counters["communities"] = result->communities;
  state.counters["rounds"] = result->band_rounds;
}
BENCHMARK(BM_Search)->Arg(0)->Arg(1)->ArgNames({"exhaustive"})->Unit(benchmark::kMicrosecond);

// The search's own bookkeeping (grid, path, hull bands): the multi-view verdicts are computed
// once beforehand, so the predicate is a table lookup.
void BM_SearchBookkeeping(benchmark::State& state) {
  const Frame& f = frame();
  AntColonyParams params;
  params.strategy = state.range(0) ? SearchStrategy::exhaustive : SearchStrategy::ant_colony;
  DynamicPointSearch search(params);
  MultiViewTest test(f.camera, MultiViewParams{});
  test.set_frame(f.T_world_camera, f.references);
  std::vector<std::uint8_t> verdicts;
  for (const CandidatePoint& c : f.candidates) verdicts.push_back(test.is_dynamic(c));
  const PointPredicate predicate = [&](int i) { return verdicts[i] != 0; };
  const SearchResult* result = nullptr;
  for (auto _ : state) result = &search.run(f.points, f.depth.size(), predicate);
  state.counters["tested"] = result->tested_count;
}
BENCHMARK(BM_SearchBookkeeping)
    ->Arg(0)
    ->Arg(1)
    ->ArgNames({"exhaustive"})
    ->Unit(benchmark::kMicrosecond);

void BM_RegionGrowing(benchmark::State& state) {
  const Frame& f = frame();
  MultiViewTest test(f.camera, MultiViewParams{});
  test.set_frame(f.T_world_camera, f.references);
  std::vector<Eigen::Vector2f> seeds, statics;
  std::vector<float> depths;
  for (size_t i = 0; i < f.candidates.size(); ++i) {
    if (test.is_dynamic(f.candidates[i])) {
      seeds.push_back(f.points[i]);
      depths.push_back(static_cast<float>(f.candidates[i].depth));
    } else {
      statics.push_back(f.points[i]);
    }
  }
  RegionGrowParams params;
  params.stride = static_cast<int>(state.range(0));
  // The focal length enables the metric growth radius, as in GeometryStage.
  DynamicRegionGrower grower(params, static_cast<float>(f.camera.fx));
  cv::Mat mask;
  for (auto _ : state) grower.grow(f.depth, seeds, depths, statics, mask);
  state.counters["seeds"] = static_cast<double>(seeds.size());
}
BENCHMARK(BM_RegionGrowing)->Arg(2)->Arg(4)->ArgNames({"stride"})->Unit(benchmark::kMicrosecond);

void BM_GeometryStage(benchmark::State& state) {
  const Frame& f = frame();
  GeometryParams params;
  params.search.strategy = state.range(0) ? SearchStrategy::exhaustive : SearchStrategy::ant_colony;
  GeometryStage stage(f.camera, params);
  GeometryFrameInput input;
  input.depth = f.depth;
  input.T_world_camera = f.T_world_camera;
  input.keypoints = f.keypoints;
  input.references = f.references;
  input.matched_previous = f.matched_previous;
  input.matched_current = f.matched_current;
  for (auto _ : state) benchmark::DoNotOptimize(stage.process(input));
}
BENCHMARK(BM_GeometryStage)
    ->Arg(0)
    ->Arg(1)
    ->ArgNames({"exhaustive"})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
