// Speed of the synthetic sequence generator (not a test): rendering alone on one and on all
// threads, scene construction, and the full render + PNG writing pipeline of `pspslam synth`.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"

namespace {

pspslam::SynthOptions bench_options(int threads) {
  pspslam::SynthOptions options;
  options.frames = 300;
  options.bodies = 3;
  options.threads = threads;
  return options;
}

void BM_SynthSceneConstruction(benchmark::State& state) {
  for (auto _ : state) {
    pspslam::SyntheticScene scene(bench_options(1));
    benchmark::DoNotOptimize(&scene);
  }
}
BENCHMARK(BM_SynthSceneConstruction)->Unit(benchmark::kMillisecond);

// Renders frames 0, 7, 14, ... (people in and out of view), colour + exact and sensor depth.
// Second argument: 0 = --sensor ideal, 1 = --sensor kinect with every fault (a second render
// for the depth instant, a scene set-up per band of rows, blur, gain and distortion remaps).
void BM_SynthRender(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  pspslam::SynthOptions options = bench_options(threads);
  if (state.range(1) != 0) options.sensor = pspslam::SynthSensor::kKinect;
  const pspslam::SyntheticScene scene(options);
  pspslam::SynthFrame frame;
  size_t index = 0;
  for (auto _ : state) {
    scene.render(index, frame, threads);
    index = (index + 7) % scene.frame_count();
    benchmark::DoNotOptimize(frame.bgr.data);
  }
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SynthRender)
    ->Args({1, 0})
    ->Args({1, 1})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// What `pspslam synth --frames 60` does after building the scene: render + encode 3 PNGs/frame.
void BM_SynthWriteSequence(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  pspslam::SynthOptions options = bench_options(threads);
  options.frames = 60;
  const pspslam::SyntheticScene scene(options);
  const auto dir = std::filesystem::temp_directory_path() / "pspslam_bench_synth";
  for (auto _ : state) {
    pspslam::write_sequence(scene, dir);
  }
  std::filesystem::remove_all(dir);
  state.counters["frames/s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * options.frames), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SynthWriteSequence)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
