#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "pspslam/core/error.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/session/frame_log.h"
#include "pspslam/session/occupancy_run.h"
#include "pspslam/session/run_option_table.h"
#include "pspslam/session/run_options.h"
#include "pspslam/session/run_settings.h"
#include "pspslam/session/run_statistics.h"
#include "pspslam/session/start_watch.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

TEST(RunStatistics, TimingSummaryIsMedianMeanAndP95) {
  std::vector<double> values;
  for (int i = 20; i >= 1; --i) values.push_back(i);  // 1..20, unsorted
  const TimingSummary t = summarize(values);
  EXPECT_EQ(t.count, 20u);
  EXPECT_DOUBLE_EQ(t.mean, 10.5);
  EXPECT_DOUBLE_EQ(t.median, 11.0);  // upper median, as the run report always printed
  EXPECT_DOUBLE_EQ(t.p95, 20.0);     // index floor(0.95 * 20) = 19
  EXPECT_EQ(summarize({}).count, 0u);
}

TEST(RunStatistics, LatencySummaryIsMedianP99AndMax) {
  std::vector<double> values;
  for (int i = 200; i >= 1; --i) values.push_back(i);  // 1..200, unsorted
  const LatencySummary l = summarize_latency(values);
  EXPECT_EQ(l.count, 200u);
  EXPECT_DOUBLE_EQ(l.median, 101.0);
  EXPECT_DOUBLE_EQ(l.p99, 199.0);  // index floor(0.99 * 200) = 198
  EXPECT_DOUBLE_EQ(l.max, 200.0);
  const LatencySummary one = summarize_latency({33.0});
  EXPECT_DOUBLE_EQ(one.p99, 33.0);
  EXPECT_EQ(summarize_latency({}).count, 0u);
}

FrameReport frame(bool tracked, TrackingMethod method = TrackingMethod::kMotionModel) {
  FrameReport report;
  report.tracking.state = tracked ? TrackingState::kOk : TrackingState::kLost;
  report.tracking.method = method;
  if (tracked) report.tracking.T_world_camera = Pose::Identity();
  report.dynamic.mask_age_frames = 0;
  report.dynamic.semantic_inference_ms = 50.0;
  report.dynamic.masked_keypoints = 7;
  return report;
}

TEST(RunStatistics, CountsLostFramesRelocalisationsAndTheReturnAfterABlackout) {
  RunStatistics stats(DynamicMode::full, FrameRange{2, 3});  // frames 2, 3, 4 black
  stats.add_frame(0, frame(true), {.wall_ms = 12.0, .cpu_ms = 11.0});
  stats.add_frame(1, frame(true));
  for (size_t i = 2; i < 6; ++i) stats.add_frame(i, frame(false));
  stats.add_frame(6, frame(true, TrackingMethod::kRelocalisation));
  stats.add_frame(7, frame(true));
  EXPECT_EQ(stats.processed(), 8u);
  EXPECT_EQ(stats.lost(), 4u);
  EXPECT_EQ(stats.relocalisations(), 1u);
  ASSERT_TRUE(stats.first_pose_after_blackout());
  EXPECT_EQ(*stats.first_pose_after_blackout(), 6u);
  EXPECT_EQ(stats.first_method_after_blackout(), to_string(TrackingMethod::kRelocalisation));
  EXPECT_EQ(stats.local_mapping_ms.size(), 1u);  // only frames that finished a local BA
  EXPECT_EQ(stats.masked_keypoints, 56u);
  EXPECT_EQ(stats.semantic_ms.size(), 1u);  // the same mask inference is counted once
  EXPECT_EQ(stats.frames_without_mask, 0u);
}

TEST(RunStatistics, FindsTheLongestLostStretchAfterTheMapStarted) {
  RunStatistics stats(DynamicMode::full, std::nullopt);
  FrameReport before_map;  // not initialised: not a lost stretch
  stats.add_frame(0, before_map);
  stats.add_frame(1, frame(true, TrackingMethod::kInitialization));
  stats.add_frame(2, frame(false));
  stats.add_frame(3, frame(false));
  stats.add_frame(4, frame(true));
  EXPECT_EQ(stats.lost_stretches(), 1u);
  ASSERT_TRUE(stats.longest_lost_stretch());
  EXPECT_EQ(stats.longest_lost_stretch()->first_frame, 2u);
  EXPECT_EQ(stats.longest_lost_stretch()->frames, 2u);
  EXPECT_EQ(stats.longest_lost_stretch()->end, RunStatistics::LostStretch::End::tracked_again);
  for (size_t i = 5; i < 8; ++i) stats.add_frame(i, frame(false));
  EXPECT_EQ(stats.lost_stretches(), 2u);
  EXPECT_EQ(stats.longest_lost_stretch()->first_frame, 5u);
  EXPECT_EQ(stats.longest_lost_stretch()->last_frame, 7u);
  EXPECT_EQ(stats.longest_lost_stretch()->frames, 3u);
  EXPECT_EQ(stats.longest_lost_stretch()->end, RunStatistics::LostStretch::End::still_lost);
  stats.add_frame(8, before_map);  // a monocular map started again
  EXPECT_EQ(stats.longest_lost_stretch()->end, RunStatistics::LostStretch::End::map_restarted);
  EXPECT_EQ(stats.lost_stretches(), 2u);

  RunStatistics never_lost(DynamicMode::full, std::nullopt);
  never_lost.add_frame(0, frame(true, TrackingMethod::kInitialization));
  EXPECT_EQ(never_lost.lost_stretches(), 0u);
  EXPECT_FALSE(never_lost.longest_lost_stretch());
}

// A monocular map that starts at frame 3 places frames 1 and 2 (frame 0 was too early to be
// kept): they count as posed, and the latest start's count is reported.
TEST(RunStatistics, FramesPlacedByTheMapStartCountAsPosed) {
  RunStatistics stats(DynamicMode::full, std::nullopt);
  FrameReport before_map;
  for (size_t i = 0; i < 3; ++i) stats.add_frame(i, before_map);
  EXPECT_EQ(stats.lost(), 3u);
  FrameReport start = frame(true, TrackingMethod::kInitialization);
  start.tracking.earlier_frames = {{1.0, Pose::Identity()}, {2.0, Pose::Identity()}};
  stats.add_frame(3, start);
  stats.add_frame(4, frame(true));
  EXPECT_EQ(stats.processed(), 5u);
  EXPECT_EQ(stats.lost(), 1u);
  EXPECT_EQ(stats.placed_before_initialisation(), 2u);
  EXPECT_EQ(stats.tracked_since_initialisation(), 2u);
  ASSERT_TRUE(stats.initialised_at());
  EXPECT_EQ(*stats.initialised_at(), 3u);
  // A restart moves every pose of the map it drops, the placed ones too, back to "without pose".
  FrameReport restart = frame(false);
  restart.tracking.restart_due = true;
  stats.add_frame(5, restart);
  EXPECT_EQ(stats.lost(), 6u);
}

// The frames placed by the map's start leave lost_frames.txt and enter trajectory.txt ahead of
// the frame that started it; a later restart lists every pose of the dropped map as restarted.
TEST(FrameLog, EarlierFramesMoveFromLostFramesToTheTrajectoryInTimeOrder) {
  const auto dir = testing::make_temp_dir("frame_log_earlier");
  FrameLog log(dir);
  const MappingStats mapping;
  FrameReport before_map;
  for (size_t i = 0; i < 4; ++i)
    log.write(i, 10.0 + 0.5 * static_cast<double>(i), before_map, 0.0, mapping, std::nullopt);
  Pose placed = Pose::Identity();
  placed.translation() = Eigen::Vector3d(0.1, 0.0, 0.0);
  log.write_earlier({{11.0, Pose::Identity()}, {11.5, placed}});
  FrameReport start = frame(true, TrackingMethod::kInitialization);
  start.tracking.T_world_camera->translation() = Eigen::Vector3d(0.2, 0.0, 0.0);
  log.write(4, 12.0, start, 0.0, mapping, std::nullopt);
  EXPECT_EQ(log.poses(), 3u);

  const Trajectory trajectory = read_tum_trajectory(dir / "trajectory.txt");
  ASSERT_EQ(trajectory.size(), 3u);
  EXPECT_DOUBLE_EQ(trajectory[0].timestamp, 11.0);
  EXPECT_DOUBLE_EQ(trajectory[1].timestamp, 11.5);
  EXPECT_NEAR(trajectory[1].T_world_camera.translation().x(), 0.1, 1e-9);
  EXPECT_DOUBLE_EQ(trajectory[2].timestamp, 12.0);
  EXPECT_EQ(testing::read_text(dir / "lost_frames.txt"),
            "# frames without a pose (tracking not initialised or lost): index timestamp state\n"
            "0 10.000000 not_initialized\n"
            "1 10.500000 not_initialized\n");

  log.forget_poses();
  EXPECT_EQ(log.poses(), 0u);
  EXPECT_EQ(testing::read_text(dir / "lost_frames.txt"),
            "# frames without a pose (tracking not initialised or lost): index timestamp state\n"
            "0 10.000000 not_initialized\n"
            "1 10.500000 not_initialized\n"
            "2 11.000000 restarted\n"
            "3 11.500000 restarted\n"
            "4 12.000000 restarted\n");
}

TEST(StartWatch, WarnsOnceAfterTheGivenFramesAndSaysWhy) {
  StartWatch watch(3);
  TrackResult waiting;
  waiting.keypoints_with_depth = 40;
  waiting.keypoints_with_depth_needed = 500;
  EXPECT_FALSE(watch.update(waiting));
  EXPECT_FALSE(watch.update(waiting));
  EXPECT_TRUE(watch.update(waiting));
  EXPECT_FALSE(watch.update(waiting));
  EXPECT_TRUE(watch.never_started());
  EXPECT_EQ(watch.reason(),
            "no map after 4 frames: the best frame had 40 keypoints with a depth reading, 500 "
            "are needed to start one (are the depth images listed in depth.txt empty?)");
  TrackResult started;
  started.state = TrackingState::kOk;
  watch.update(started);
  EXPECT_FALSE(watch.never_started());
}

TEST(RunOutputs, PathsAreCheckedAndCreatedNamingTheFlag) {
  const auto dir = testing::make_temp_dir("session_outputs");
  std::ofstream(dir / "plain") << "x";
  RunOutputs outputs;
  outputs.folder = dir / "out" / "deep";
  outputs.export_dense = dir / "clouds" / "dense.ply";
  prepare_run_outputs(outputs);
  EXPECT_TRUE(std::filesystem::is_directory(dir / "out" / "deep"));
  EXPECT_TRUE(std::filesystem::is_directory(dir / "clouds"));
  outputs.export_map = dir / "plain" / "map.ply";
  try {
    prepare_run_outputs(outputs);
    FAIL() << "an output under a regular file was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--export-map '", 0), 0u) << e.what();
  }
}

TEST(RunSettings, LiveRunsYieldTheCoreAndCapLocalBa) {
  RunSettings settings;
  settings.mode = "off";
  const SystemOptions offline = system_options(settings);
  EXPECT_EQ(offline.background_thread_nice, 0);
  EXPECT_EQ(offline.local_ba_keyframes, 0);
  EXPECT_EQ(offline.back_end_wait, BackEndWait::whole_back_end);
  settings.realtime = true;
  const SystemOptions realtime = system_options(settings);
  EXPECT_EQ(realtime.background_thread_nice, kLiveBackgroundNice);
  EXPECT_EQ(realtime.local_ba_keyframes, kLiveLocalBaKeyframes);
  EXPECT_EQ(realtime.back_end_wait, BackEndWait::none);
  EXPECT_TRUE(realtime.dynamic.realtime);
  settings.realtime = false;
  settings.live_camera = true;
  settings.background_nice = 3;
  const SystemOptions camera = system_options(settings);
  EXPECT_EQ(camera.background_thread_nice, 3);
  EXPECT_EQ(camera.local_ba_keyframes, kLiveLocalBaKeyframes);
  EXPECT_FALSE(camera.dynamic.realtime);
}

TEST(RunSettings, ALiveSourceWaitsForLocalMappingOnlyAndEveryRunGetsTheLiveMaskPolicies) {
  RunSettings settings;
  settings.mode = "off";
  const SystemOptions offline = system_options(settings);
  // Acting in live runs only, so the same for every run, whichever front end made it.
  EXPECT_TRUE(offline.dynamic.cull_with_late_masks);
  EXPECT_TRUE(offline.tracker.judged_points_first);
  EXPECT_TRUE(offline.dynamic.tighten_geometry);
  EXPECT_FALSE(offline.dynamic.keep_pace);
  EXPECT_EQ(offline.dynamic.stale_masks, StaleMaskPolicy::homography);
  settings.live_camera = true;
  EXPECT_EQ(system_options(settings).back_end_wait, BackEndWait::local_mapping);
  settings.realtime = true;
  EXPECT_EQ(system_options(settings).back_end_wait, BackEndWait::none);
  settings.late_mask_culling = "off";
  settings.semantic_delay_ms = "random:10:20";
  settings.semantic_delay_seed = 7;
  const SystemOptions changed = system_options(settings);
  EXPECT_FALSE(changed.dynamic.cull_with_late_masks);
  EXPECT_EQ(changed.dynamic.semantic.injected_delay, (SemanticDelay{10, 20, 7}));
}

// The occupancy map's options come from the table, so `pspslam run` and Python build one map.
TEST(RunOptionTable, OccupancyOptionsReachTheMap) {
  EXPECT_FALSE(occupancy_run_options(RunSettings{}).enabled);
  RunSettings settings;
  for (const auto& [keyword, words] : {std::pair<std::string, std::string>{"occupancy", ""},
                                       {"occupancy_resolution", "0.1"},
                                       {"occupancy_max_range", "3"},
                                       {"occupancy_masks", "off"},
                                       {"occupancy_clearing", "off"}}) {
    const RunOption& option = *find_run_option_by_keyword(keyword);
    option.set(settings, parse_run_text(option, {words}));
  }
  const OccupancyRunOptions options = occupancy_run_options(settings);
  EXPECT_TRUE(options.enabled);
  EXPECT_DOUBLE_EQ(options.map.resolution_m, 0.1);
  EXPECT_DOUBLE_EQ(options.map.max_range_m, 3.0);
  EXPECT_FALSE(options.map.use_masks);
  EXPECT_FALSE(options.map.clearing);
  settings.occupancy_max_range = 0.05;
  EXPECT_THROW(check_run_settings(settings, SettingNames{}), Error);
}

TEST(RunOptionTable, FlagsAndKeywordsAreUniqueAndBadValuesAreToldOnce) {
  std::set<std::string> flags;
  std::set<std::string> keywords;
  for (const RunOption& option : run_option_table()) {
    if (!option.flag.empty()) {
      EXPECT_TRUE(flags.insert(option.flag).second) << option.flag;
    }
    EXPECT_TRUE(keywords.insert(option.keyword).second) << option.keyword;
  }
  const RunOption& margin = *find_run_option_by_flag("--mask-margin");
  EXPECT_EQ(margin.keyword, "mask_margin");
  EXPECT_EQ(run_text_problem(margin, {"101"}), "must be an integer in [0, 100], got '101'");
  EXPECT_EQ(run_text_problem(margin, {"2.5"}), "must be an integer in [0, 100], got '2.5'");
  EXPECT_EQ(run_value_problem(margin, 101LL, {"101"}), "must be an integer in [0, 100], got '101'");
  EXPECT_EQ(run_text_problem(margin, {"100"}), "");
  const RunOption& ratio = *find_run_option_by_keyword("keyframe_ratio");
  EXPECT_EQ(run_text_problem(ratio, {"0"}), "must be a number in [0.01, 1], got '0'");
  const RunOption& loops = *find_run_option_by_keyword("loop_closing");
  EXPECT_EQ(run_text_problem(loops, {"maybe"}), "must be one of on | off | auto, got 'maybe'");
  const RunOption& prior = *find_run_option_by_flag("--motion-prior");
  EXPECT_EQ(run_value_problem(prior, std::pair(1.0, 5000.0), {"1.0", "5000.0"}),
            "must be a number in [0.001, 1000], got '5000.0'");
  RunSettings settings;
  prior.set(settings, parse_run_text(prior, {"2", "0.5"}));
  EXPECT_EQ(settings.motion_prior, std::pair(2.0, 0.5));
  settings.localization = true;
  try {
    check_run_settings(settings, SettingNames{.keywords = true});
    FAIL() << "localization without a map was accepted";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "localization: needs load_map (a map to localise in)");
  }
}

TEST(RunSettings, LoopClosingAutoNeedsTheVocabularyAndNeverRunsInLocalisation) {
  RunSettings settings;
  settings.mode = "off";
  settings.vocabulary = "/nonexistent/vocabulary.pspvoc";
  EXPECT_FALSE(system_options(settings).place.loop_closing);
  settings.loop_closing = "on";
  EXPECT_TRUE(system_options(settings).place.loop_closing);
  settings.load_map = "map.bin";
  settings.localization = true;
  const SystemOptions localisation = system_options(settings);
  EXPECT_TRUE(localisation.localization_only);
  EXPECT_FALSE(localisation.place.loop_closing);
}

// The message of the Error `call` throws; empty when it throws none.
template <typename Call>
std::string error_of(Call call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

TEST(RunSettings, AutoFallsBackToGeometryButANamedModeNeedsItsModel) {
  const std::filesystem::path missing = "/nonexistent/model.yaml";
  RunSettings settings;
  EXPECT_EQ(choose_mode(settings, missing), DynamicMode::geometry);
  settings.model = missing;
  EXPECT_THROW(choose_mode(settings, missing), Error);
  settings.model.reset();
  settings.mode = "full";
  const std::string cli = error_of([&] { choose_mode(settings, missing); });
  EXPECT_EQ(cli.rfind("--dynamic full: segmentation model not usable: ", 0), 0u) << cli;
  const SettingNames keywords{
      .mode = "mode", .semantic_masks = "semantic_masks", .explain_model = false};
  const std::string python = error_of([&] { choose_mode(settings, missing, keywords); });
  EXPECT_EQ(python.rfind("mode full: ", 0), 0u) << python;
  EXPECT_EQ(python.find("get it"), std::string::npos) << python;
}

TEST(RunSettings, MasksFromFilesNeedAModeThatUsesThem) {
  const std::filesystem::path missing = "/nonexistent/model.yaml";
  RunSettings settings;
  settings.semantic_masks = "masks";
  settings.mode = "semantic";
  EXPECT_EQ(choose_mode(settings, missing), DynamicMode::semantic);
  settings.mode = "geometry";
  EXPECT_EQ(error_of([&] { choose_mode(settings, missing); }),
            "--semantic-masks replaces the network's masks, but --dynamic geometry uses none "
            "(use semantic, full or exhaustive)");
}

}  // namespace
}  // namespace pspslam
