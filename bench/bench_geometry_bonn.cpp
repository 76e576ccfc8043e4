// Geometry module on the real bonn_crowd_dev clip (../shared): (1) the compensated homography of
// every consecutive frame pair (ORB matches, eq. 10-11): inlier transfer RMS before (RANSAC only)
// and after the Levenberg-Marquardt refinement; (2) the per-frame cost of the geometry stage with
// the ant-colony search and with the exhaustive baseline, run on the same frames in the same
// process. The mocap frame of groundtruth.txt is not the camera frame, so reference poses come
// from PnP (RANSAC) of ORB matches against each reference's depth: relative poses, as the
// tracker would provide them. No ground-truth masks exist here; frames 0-215 are a static room,
// so dynamic flags there are false positives.
//
// With --poses FILE (a TUM trajectory of this clip, e.g. `pspslam run`'s trajectory.txt) the
// camera poses come from that file instead, and each frame gets a pool of `pool-size` earlier
// frames at multiples of 5 (keyframe-like: consecutive frames share them), from which the stage
// picks 5 by coverage (reference_selection.h). Much faster than the PnP harness.
//
//   bench_geometry_bonn [--frames N] [--shared DIR] [--poses FILE] [--pool-size N] [--repeats N]
//                       [--node-spacing PX] [--dump FILE] [--system-inputs 0|1]
//   --system-inputs 1 (default): the stage gets what System gives it: the previous -> current
//   homography computed beforehand (System's flow step) and no keypoint depths (read lazily by
//   the stage, only for the points it needs); the stage time is then System's geometry step.
//   0: the stage gets the ORB matches (estimates H itself, "module" time) and the depths.
//   --dump FILE: per-frame CSV of the last pass (CPU ms per part and counts of both strategies).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "pspslam/config/config.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/feature/orb_extractor.h"
#include "pspslam/geometry/geometry_stage.h"
#include "pspslam/io/rgbd_sequence.h"
#include "pspslam/io/trajectory_io.h"

namespace {

using namespace pspslam;
namespace fs = std::filesystem;

struct Entry {
  double t;
  std::string file;
};

std::vector<Entry> read_list(const fs::path& file) {
  std::vector<Entry> out;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    Entry e;
    s >> e.t >> e.file;
    out.push_back(e);
  }
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

struct Frame {
  double timestamp = 0.0;
  std::optional<Pose> T_world_camera;      // from --poses
  cv::Mat depth;                           // undistorted, metres
  std::vector<Eigen::Vector2d> keypoints;  // undistorted pixels with a depth reading
  std::vector<float> depths;
  cv::Mat descriptors;  // rows of the keypoints above
};

}  // namespace

int main(int argc, char** argv) {
  int max_frames = 400;
  int pool_size = 12;
  int repeats = 5;            // timed passes over the frames (the inputs are prepared once)
  float node_spacing = 0.0f;  // > 0: overrides the ant colony's node spacing (comparisons)
  fs::path shared = shared_dir();
  fs::path poses_file;
  fs::path dump_file;
  bool system_inputs = true;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--frames") max_frames = std::stoi(argv[i + 1]);
    if (key == "--shared") shared = argv[i + 1];
    if (key == "--poses") poses_file = argv[i + 1];
    if (key == "--pool-size") pool_size = std::stoi(argv[i + 1]);
    if (key == "--repeats") repeats = std::stoi(argv[i + 1]);
    if (key == "--node-spacing") node_spacing = std::stof(argv[i + 1]);
    if (key == "--dump") dump_file = argv[i + 1];
    if (key == "--system-inputs") system_inputs = std::stoi(argv[i + 1]) != 0;
  }
  Trajectory poses;
  if (!poses_file.empty()) poses = read_tum_trajectory(poses_file);
  const fs::path dir = shared / "data" / "bonn_crowd_dev";
  const SystemConfig config = load_config(source_dir() / "config" / "bonn.yaml");
  const PinholeCamera& camera = config.camera.pinhole;
  PinholeCamera ideal = camera;
  ideal.distortion = {};

  // Associate rgb and depth by nearest timestamp; skip missing depth files (known quirk).
  const std::vector<Entry> rgb = read_list(dir / "rgb.txt");
  const std::vector<Entry> depth_list = read_list(dir / "depth.txt");
  cv::Mat map_x, map_y;
  cv::initUndistortRectifyMap(camera.K(), camera.distortion_coeffs(), cv::Mat(), camera.K(),
                              cv::Size(camera.width, camera.height), CV_32FC1, map_x, map_y);
  OrbExtractor orb(config.orb);
  std::vector<Frame> frames;
  std::vector<int> frame_index;
  for (size_t i = 0; i < rgb.size() && static_cast<int>(frames.size()) < max_frames; ++i) {
    const auto nearest =
        std::min_element(depth_list.begin(), depth_list.end(), [&](const Entry& a, const Entry& b) {
          return std::abs(a.t - rgb[i].t) < std::abs(b.t - rgb[i].t);
        });
    if (std::abs(nearest->t - rgb[i].t) > 0.02 || !fs::exists(dir / nearest->file)) continue;
    const cv::Mat bgr = cv::imread((dir / rgb[i].file).string());
    Frame f;
    f.timestamp = rgb[i].t;
    if (!poses.empty()) {
      const auto pose =
          std::min_element(poses.begin(), poses.end(), [&](const auto& a, const auto& b) {
            return std::abs(a.timestamp - rgb[i].t) < std::abs(b.timestamp - rgb[i].t);
          });
      if (std::abs(pose->timestamp - rgb[i].t) < 0.005) f.T_world_camera = pose->T_world_camera;
    }
    // As System reads it: metres, with the config's depth registration shift.
    const cv::Mat metres =
        read_depth_image(dir / nearest->file, config.camera.depth_factor,
                         config.camera.depth_shift_x, config.camera.depth_shift_y);
    // Nearest remap: never blends depths across an object edge.
    cv::remap(metres, f.depth, map_x, map_y, cv::INTER_NEAREST);
    cv::Mat gray;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    OrbFeatures features;
    orb.extract(gray, cv::Mat(), features);
    std::vector<cv::Point2f> points;
    for (const cv::KeyPoint& k : features.keypoints) points.push_back(k.pt);
    camera.undistort_points(points);
    for (size_t k = 0; k < points.size(); ++k) {
      const int u = int(points[k].x + 0.5f), v = int(points[k].y + 0.5f);
      if (u < 0 || v < 0 || u >= f.depth.cols || v >= f.depth.rows) continue;
      const float d = f.depth.at<float>(v, u);
      if (!(d > 0.0f)) continue;
      f.keypoints.emplace_back(points[k].x, points[k].y);
      f.depths.push_back(d);
      f.descriptors.push_back(features.descriptors.row(static_cast<int>(k)));
    }
    frames.push_back(std::move(f));
    frame_index.push_back(static_cast<int>(i));
  }
  std::printf("bonn_crowd_dev: %zu frames with depth, %.0f ORB candidates with depth per frame\n",
              frames.size(), [&] {
                double s = 0;
                for (const Frame& f : frames) s += f.keypoints.size();
                return s / std::max<size_t>(1, frames.size());
              }());

  cv::BFMatcher matcher(cv::NORM_HAMMING, true);  // cross-checked matches
  const auto match = [&](const Frame& a, const Frame& b) {
    std::vector<cv::DMatch> m;
    if (!a.descriptors.empty() && !b.descriptors.empty())
      matcher.match(a.descriptors, b.descriptors, m);
    std::vector<cv::DMatch> good;
    for (const cv::DMatch& d : m)
      if (d.distance < 50) good.push_back(d);
    return good;
  };

  // (1) Compensated homography on consecutive pairs.
  std::vector<double> improvement, relative, before_all, after_all, h_cpu, lm_iterations;
  int lower = 0, pairs = 0;
  for (size_t i = 1; i < frames.size(); ++i) {
    const std::vector<cv::DMatch> m = match(frames[i - 1], frames[i]);
    std::vector<Eigen::Vector2d> x, y;
    for (const cv::DMatch& d : m) {
      x.push_back(frames[i - 1].keypoints[d.queryIdx]);
      y.push_back(frames[i].keypoints[d.trainIdx]);
    }
    timespec t0{}, t1{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
    const CompensatedHomography h = estimate_compensated_homography(x, y, HomographyParams{});
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
    if (!h.valid) continue;
    ++pairs;
    h_cpu.push_back((t1.tv_sec - t0.tv_sec) * 1e3 + (t1.tv_nsec - t0.tv_nsec) * 1e-6);
    lm_iterations.push_back(h.lm_iterations);
    lower += h.rms_after_px < h.rms_before_px;
    improvement.push_back(h.rms_before_px - h.rms_after_px);
    relative.push_back((h.rms_before_px - h.rms_after_px) / h.rms_before_px);
    before_all.push_back(h.rms_before_px);
    after_all.push_back(h.rms_after_px);
  }
  std::printf("\nhomography, %d consecutive pairs: refined RMS lower on %.3f of pairs\n", pairs,
              double(lower) / std::max(1, pairs));
  std::printf("  RMS before (RANSAC only) median %.3f px, after LM median %.3f px\n",
              median(before_all), median(after_all));
  std::printf("  improvement (px)  p5 %.4f  median %.4f  p95 %.4f\n", percentile(improvement, 0.05),
              median(improvement), percentile(improvement, 0.95));
  std::printf("  improvement (rel) p5 %.4f  median %.4f  p95 %.4f\n", percentile(relative, 0.05),
              median(relative), percentile(relative, 0.95));
  std::printf("  cpu per pair median %.3f ms; LM iterations median %.0f, p95 %.0f\n", median(h_cpu),
              median(lm_iterations), percentile(lm_iterations, 0.95));

  // (2) Stage cost, ant colony vs exhaustive, same frames, same process.
  // Inputs first (references, matches to the previous frame), so that the timed passes below
  // contain only the stage calls.
  struct StageFrame {
    size_t index = 0;
    Pose T_world_current = Pose::Identity();
    std::vector<DepthView> references;
    std::vector<Eigen::Vector2d> x, y;
    std::optional<Eigen::Matrix3d> H_previous_to_current;  // --system-inputs: from the matches
  };
  std::vector<StageFrame> stage_frames;
  for (size_t i = 50; i < frames.size(); ++i) {
    std::vector<DepthView> references;
    Pose T_world_current = Pose::Identity();
    if (!poses.empty()) {
      if (!frames[i].T_world_camera) continue;
      T_world_current = *frames[i].T_world_camera;
      // Keyframe-like pool: frames at multiples of 5 before this one (newest first), so
      // consecutive frames share their pool as they would share keyframes.
      const int newest = (static_cast<int>(i) - 1) / 5 * 5;
      for (int r = 0; r < pool_size && newest - 5 * r >= 0; ++r) {
        const Frame& ref = frames[newest - 5 * r];
        if (ref.T_world_camera) references.push_back({*ref.T_world_camera, ref.depth});
      }
    }
    for (int r = 1; r <= 5 && poses.empty(); ++r) {
      const Frame& ref = frames[i - 10 * r];
      const std::vector<cv::DMatch> m = match(frames[i], ref);
      std::vector<cv::Point3f> object;
      std::vector<cv::Point2f> image;
      for (const cv::DMatch& d : m) {
        const Eigen::Vector3d p =
            ideal.unproject(ref.keypoints[d.trainIdx], ref.depths[d.trainIdx]);
        object.emplace_back(p.x(), p.y(), p.z());
        image.emplace_back(frames[i].keypoints[d.queryIdx].x(),
                           frames[i].keypoints[d.queryIdx].y());
      }
      if (object.size() < 20) continue;
      cv::Mat rvec, tvec;
      std::vector<int> inliers;
      if (!cv::solvePnPRansac(object, image, ideal.K(), cv::Mat(), rvec, tvec, false, 200, 2.0,
                              0.999, inliers) ||
          inliers.size() < 20)
        continue;
      cv::Mat R;
      cv::Rodrigues(rvec, R);
      Pose T_current_ref = Pose::Identity();
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) T_current_ref.linear()(a, b) = R.at<double>(a, b);
        T_current_ref.translation()(a) = tvec.at<double>(a);
      }
      // World = current camera: the reference pose in it is T_current_ref.
      references.push_back({T_current_ref, ref.depth});
    }
    const std::vector<cv::DMatch> m = match(frames[i - 1], frames[i]);
    std::vector<Eigen::Vector2d> x, y;
    for (const cv::DMatch& d : m) {
      x.push_back(frames[i - 1].keypoints[d.queryIdx]);
      y.push_back(frames[i].keypoints[d.trainIdx]);
    }
    std::optional<Eigen::Matrix3d> H;
    if (system_inputs && x.size() >= 4) {
      const CompensatedHomography h = estimate_compensated_homography(x, y, HomographyParams{});
      if (h.valid) H = h.H;
    }
    stage_frames.push_back(
        {i, T_world_current, std::move(references), std::move(x), std::move(y), H});
  }
  // Each pass runs both strategies on every frame with fresh stages; the strategy that runs
  // first on a frame finds the reference depth images out of cache, so the order alternates
  // frame by frame (and pass by pass): neither strategy gets the other's warm cache for free.
  // Ratios are of per-pass medians; the reported ratio is their median over the passes.
  GeometryParams ant_params, exhaustive_params;
  exhaustive_params.search.strategy = SearchStrategy::exhaustive;
  if (node_spacing > 0.0f) ant_params.search.node_spacing_px = node_spacing;
  std::vector<double> ant_cpu, ex_cpu, ant_wall, ex_wall, ant_search, ex_search, tested_share;
  std::vector<double> ant_no_h, ex_no_h, selection, ant_region, ex_region, last_band_share;
  std::vector<double> pass_module_ratio, pass_search_ratio, pass_no_h_ratio;
  // The per-frame times are bimodal (static room frames: few dynamic points; crowd frames: half
  // the points on people), so a median can sit between the modes and jump between passes. The
  // ratio of totals (time over all frames) and the medians within each part are reported too.
  std::vector<double> pass_search_total_ratio, pass_no_h_total_ratio, pass_crowd_search_ratio,
      pass_static_search_ratio, pass_crowd_no_h_ratio;
  const auto sum = [](const std::vector<double>& v) {
    double total = 0.0;
    for (double x : v) total += x;
    return total;
  };
  const auto part_ratio = [&](const std::vector<double>& ant_v, const std::vector<double>& ex_v,
                              bool crowd) {
    std::vector<double> a, e;
    for (size_t k = 0; k < stage_frames.size(); ++k) {
      const int index = frame_index[stage_frames[k].index];
      if (crowd ? index >= 220 : index < 215) {
        a.push_back(ant_v[k]);
        e.push_back(ex_v[k]);
      }
    }
    return median(a) / median(e);
  };
  long static_flags = 0, static_points = 0, crowd_flags = 0, crowd_points = 0, kept = 0, found = 0;
  // "Kept" also on the final verdicts (tested dynamic or in the grown mask: what SLAM uses), over
  // all frames and over the crowd frames only: the exhaustive's dynamic verdicts in the
  // person-free frames are false positives, keeping them is no merit.
  long kept_final = 0, found_final = 0, crowd_kept_final = 0, crowd_found_final = 0;
  for (int pass = 0; pass < std::max(1, repeats); ++pass) {
    GeometryStage ant(ideal, ant_params), exhaustive(ideal, exhaustive_params);
    for (std::vector<double>* v :
         {&ant_cpu, &ex_cpu, &ant_wall, &ex_wall, &ant_search, &ex_search, &tested_share, &ant_no_h,
          &ex_no_h, &selection, &ant_region, &ex_region, &last_band_share})
      v->clear();
    static_flags = static_points = crowd_flags = crowd_points = kept = found = 0;
    kept_final = found_final = crowd_kept_final = crowd_found_final = 0;
    cv::Mat previous_mask;
    const bool last_pass = pass + 1 == std::max(1, repeats);
    std::ofstream dump;
    if (last_pass && !dump_file.empty()) {
      dump.open(dump_file);
      dump << "frame,points,strategy,total,homography,selection,search,region,tested,"
              "tested_dynamic,dynamic,mask_pixels,last_band_tests\n";
    }
    for (size_t k = 0; k < stage_frames.size(); ++k) {
      const StageFrame& sf = stage_frames[k];
      const size_t i = sf.index;
      GeometryFrameInput input;
      input.depth = frames[i].depth;
      input.T_world_camera = sf.T_world_current;
      input.keypoints = frames[i].keypoints;
      if (!system_inputs) input.keypoint_depths = frames[i].depths;
      input.references = sf.references;
      if (system_inputs) {
        input.H_previous_to_current = sf.H_previous_to_current;
      } else {
        input.matched_previous = sf.x;
        input.matched_current = sf.y;
      }
      input.previous_dynamic_mask = previous_mask;
      GeometryFrameResult e, a;
      if ((k + static_cast<size_t>(pass)) % 2 == 0) {
        e = exhaustive.process(input);
        a = ant.process(input);
      } else {
        a = ant.process(input);
        e = exhaustive.process(input);
      }
      previous_mask = a.dynamic_mask;
      if (dump.is_open()) {
        for (const auto& [name, r] :
             {std::pair<const char*, const GeometryFrameResult*>{"ant", &a}, {"exhaustive", &e}}) {
          const GeometryTiming& t = r->timing;
          dump << frame_index[i] << ',' << frames[i].keypoints.size() << ',' << name << ','
               << t.total_cpu_ms << ',' << t.homography_cpu_ms << ',' << t.selection_cpu_ms << ','
               << t.search_cpu_ms << ',' << t.region_cpu_ms << ',' << r->tested_count << ','
               << r->tested_dynamic_count << ',' << r->dynamic_count << ','
               << cv::countNonZero(r->dynamic_mask) << ',' << r->last_band_tests << '\n';
        }
      }
      ex_cpu.push_back(e.timing.total_cpu_ms);
      ant_cpu.push_back(a.timing.total_cpu_ms);
      ex_wall.push_back(e.timing.total_ms);
      ant_wall.push_back(a.timing.total_ms);
      ex_search.push_back(e.timing.search_cpu_ms);
      ant_no_h.push_back(a.timing.total_cpu_ms - a.timing.homography_cpu_ms);
      ex_no_h.push_back(e.timing.total_cpu_ms - e.timing.homography_cpu_ms);
      selection.push_back(a.timing.selection_cpu_ms);
      ant_region.push_back(a.timing.region_cpu_ms);
      ex_region.push_back(e.timing.region_cpu_ms);
      ant_search.push_back(a.timing.search_cpu_ms);
      tested_share.push_back(double(a.tested_count) /
                             std::max<size_t>(1, frames[i].keypoints.size()));
      last_band_share.push_back(double(a.last_band_tests) /
                                std::max<size_t>(1, frames[i].keypoints.size()));
      for (size_t q = 0; q < frames[i].keypoints.size(); ++q) {
        found += e.keypoint_tested_dynamic[q];
        kept += e.keypoint_tested_dynamic[q] && a.keypoint_tested_dynamic[q];
        const long both = e.keypoint_dynamic[q] && a.keypoint_dynamic[q];
        found_final += e.keypoint_dynamic[q];
        kept_final += both;
        if (frame_index[i] >= 220) {
          crowd_found_final += e.keypoint_dynamic[q];
          crowd_kept_final += both;
        }
      }
      if (frame_index[i] < 215) {
        static_flags += a.dynamic_count;
        static_points += static_cast<long>(frames[i].keypoints.size());
      } else if (frame_index[i] >= 220) {
        crowd_flags += a.dynamic_count;
        crowd_points += static_cast<long>(frames[i].keypoints.size());
      }
    }
    pass_module_ratio.push_back(median(ant_cpu) / median(ex_cpu));
    pass_search_ratio.push_back(median(ant_search) / median(ex_search));
    pass_no_h_ratio.push_back(median(ant_no_h) / median(ex_no_h));
    pass_search_total_ratio.push_back(sum(ant_search) / sum(ex_search));
    pass_no_h_total_ratio.push_back(sum(ant_no_h) / sum(ex_no_h));
    pass_crowd_search_ratio.push_back(part_ratio(ant_search, ex_search, true));
    pass_static_search_ratio.push_back(part_ratio(ant_search, ex_search, false));
    pass_crowd_no_h_ratio.push_back(part_ratio(ant_no_h, ex_no_h, true));
    std::printf(
        "  pass %d: totals over frames: search %.3f, without H %.3f; medians over crowd frames "
        ">=220: search %.3f, without H %.3f; static frames <215: search %.3f\n",
        pass, pass_search_total_ratio.back(), pass_no_h_total_ratio.back(),
        pass_crowd_search_ratio.back(), pass_crowd_no_h_ratio.back(),
        pass_static_search_ratio.back());
    std::printf("  pass %d: ratio ant/exhaustive module %.3f, search %.3f, without H %.3f\n", pass,
                pass_module_ratio.back(), pass_search_ratio.back(), pass_no_h_ratio.back());
  }
  std::printf("  median over %d passes: ratio module %.3f, search %.3f, without H %.3f\n",
              std::max(1, repeats), median(pass_module_ratio), median(pass_search_ratio),
              median(pass_no_h_ratio));
  std::printf(
      "  median over %d passes: totals search %.3f, without H %.3f; crowd frames search %.3f, "
      "without H %.3f; static frames search %.3f\n",
      std::max(1, repeats), median(pass_search_total_ratio), median(pass_no_h_total_ratio),
      median(pass_crowd_search_ratio), median(pass_crowd_no_h_ratio),
      median(pass_static_search_ratio));
  if (poses.empty())
    std::printf("\ngeometry stage over %zu frames (5 PnP references each, 10 frames apart):\n",
                ant_cpu.size());
  else
    std::printf("\ngeometry stage over %zu frames (poses %s, 5 of a pool of %d frames 5 apart):\n",
                ant_cpu.size(), poses_file.c_str(), pool_size);
  std::printf(system_inputs
                  ? "  inputs as System gives them: H from its flow step, keypoint depths read by "
                    "the stage (module = System's geometry step)\n"
                  : "  inputs: ORB matches (the stage estimates H) and keypoint depths\n");
  std::printf("  %-11s module cpu median %.3f ms (wall %.3f ms), search cpu median %.3f ms\n",
              "ant_colony", median(ant_cpu), median(ant_wall), median(ant_search));
  std::printf("  %-11s module cpu median %.3f ms (wall %.3f ms), search cpu median %.3f ms\n",
              "exhaustive", median(ex_cpu), median(ex_wall), median(ex_search));
  std::printf(
      "  last pass: ratio ant/exhaustive of medians: module %.3f, search %.3f; ant tests %.3f of "
      "points "
      "(median); keeps %.3f of the exhaustive test's detections (%ld of %ld), %.3f of its final "
      "dynamic verdicts (%ld of %ld), in the crowd frames >=220 %.3f (%ld of %ld)\n",
      median(ant_cpu) / median(ex_cpu), median(ant_search) / median(ex_search),
      median(tested_share), double(kept) / std::max(1L, found), kept, found,
      double(kept_final) / std::max(1L, found_final), kept_final, found_final,
      double(crowd_kept_final) / std::max(1L, crowd_found_final), crowd_kept_final,
      crowd_found_final);
  std::printf(
      "  without the homography (System computes H in its flow step): ant %.3f ms, exhaustive "
      "%.3f ms, ratio %.3f; reference selection %.3f ms, region growing ant %.3f / exhaustive "
      "%.3f ms (cpu medians)\n",
      median(ant_no_h), median(ex_no_h), median(ant_no_h) / median(ex_no_h), median(selection),
      median(ant_region), median(ex_region));
  {
    std::vector<double> crowd_tested, static_tested, crowd_last_band;
    for (size_t k = 0; k < stage_frames.size(); ++k) {
      const int index = frame_index[stage_frames[k].index];
      if (index >= 220) crowd_tested.push_back(tested_share[k]);
      if (index >= 220) crowd_last_band.push_back(last_band_share[k]);
      if (index < 215) static_tested.push_back(tested_share[k]);
    }
    std::printf(
        "  ant colony tested share (median): static frames <215 %.3f, crowd frames >=220 %.3f, "
        "of which in the last (empty) band rounds %.3f\n",
        median(static_tested), median(crowd_tested), median(crowd_last_band));
  }
  std::printf(
      "  dynamic share of keypoints (ant colony, final flags): static room frames <215 "
      "%.4f, crowd frames >=220 %.4f\n",
      double(static_flags) / std::max(1L, static_points),
      double(crowd_flags) / std::max(1L, crowd_points));
  return 0;
}
