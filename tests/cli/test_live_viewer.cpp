// `pspslam run --viewer` end to end: a real browser (headless chromium driven by playwright-core,
// tests/cli/live_page.mjs) watches a synthetic run, pauses and steps it, and lists the maps of
// the atlas; path traversal and a request flood against a running run; Ctrl-C with an event
// stream open.
#include <gtest/gtest.h>
#include <signal.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pspslam/io/trajectory_io.h"
#include "support/test_support.h"

// Last: through <resolv.h> it defines a macro `_res`, which Eigen uses as a parameter name.
#include <httplib.h>

namespace pspslam {
namespace {

namespace fs = std::filesystem;

using testing::contains;
using testing::read_text;

// A synthetic sequence, by default with two moving bodies (`scene`: synth's options besides the
// frame count).
fs::path sequence(int frames, const std::string& scene = "--bodies 2 --seed 5") {
  const fs::path dir = testing::make_temp_dir("live_seq") / ("seq" + std::to_string(frames));
  std::string output;
  EXPECT_EQ(testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " synth -q --out " + dir.string() +
                                   " --frames " + std::to_string(frames) + " " + scene,
                               &output),
            0)
      << output;
  return dir;
}

// `pspslam run ... --viewer 127.0.0.1:0` in the background; the port is read from its output.
class LiveRun {
 public:
  LiveRun(const fs::path& seq, const std::string& flags)
      : dir_(testing::make_temp_dir("live_run")) {
    std::string pid;
    testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " run -q --sequence " + seq.string() +
                           " --out " + out().string() + " --viewer 127.0.0.1:0 " + flags + " > '" +
                           log_file().string() + "' 2>&1 & echo $!",
                       &pid);
    pid_ = std::stoi(pid);
    const std::string marker = "http://127.0.0.1:";
    for (int i = 0; i < 1200 && !contains(log(), marker); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const std::string text = log();
    if (const size_t at = text.find(marker); at != std::string::npos)
      port_ = std::stoi(text.substr(at + marker.size()));
  }
  ~LiveRun() {
    if (running()) kill(pid_, SIGKILL);
  }
  LiveRun(const LiveRun&) = delete;
  LiveRun& operator=(const LiveRun&) = delete;

  fs::path out() const { return dir_ / "out"; }
  fs::path log_file() const { return dir_ / "log"; }
  std::string log() const { return read_text(log_file()); }
  int port() const { return port_; }
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port_) + "/"; }
  bool running() const { return pid_ > 0 && kill(pid_, 0) == 0 && !contains(log(), "stats:"); }
  void signal(int number) const { kill(pid_, number); }
  // Waits for the process to end; false after `seconds`.
  bool wait(int seconds) const {
    for (int i = 0; i < seconds * 10; ++i) {
      if (kill(pid_, 0) != 0) return true;
      // The shell's child is not ours to reap; a zombie counts as ended once the log is final.
      if (contains(log(), "stats:") || contains(log(), "interrupted after")) {
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
        return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }

 private:
  fs::path dir_;
  int pid_ = 0;
  int port_ = 0;
};

nlohmann::json read_json(const fs::path& file) {
  std::ifstream stream(file);
  return nlohmann::json::parse(stream);
}

const fs::path kPlaywright = fs::path(PSPSLAM_SOURCE_DIR) / "web/node_modules/playwright-core";

// Why the browser tests cannot run here; empty when they can.
std::string browser_missing() {
  std::string found;
  if (testing::run_shell("command -v chromium && command -v node", &found) != 0)
    return "chromium or node is not installed (scripts/install-deps installs both)";
  if (!fs::is_regular_file(kPlaywright / "index.mjs"))
    return kPlaywright.string() + " missing (scripts/install-deps runs npm ci in web/)";
  return {};
}

// tests/cli/live_page.mjs on the page at `url` (`check`: what it does there): the JSON line it
// printed, or {"error": its output} when it printed none.
nlohmann::json watch_page(const std::string& url, const fs::path& screenshot,
                          const std::string& check) {
  std::string output;
  testing::run_shell("timeout 600 node " + fs::path(PSPSLAM_SOURCE_DIR).string() +
                         "/tests/cli/live_page.mjs " + kPlaywright.string() + " " + url + " " +
                         screenshot.string() + " " + check + " 2>&1",
                     &output);
  const size_t brace = output.rfind("\n{");
  if (output.find('{') == std::string::npos) return {{"error", output}};
  return nlohmann::json::parse(
      output.substr(brace == std::string::npos ? output.find('{') : brace));
}

TEST(CliLiveViewer, BrowserWatchesPausesAndStepsTheRun) {
  if (const std::string missing = browser_missing(); !missing.empty()) GTEST_SKIP() << missing;
  constexpr int kFrames = 200;
  LiveRun run(sequence(kFrames), "--viewer-paused --viewer-interval 100");
  ASSERT_GT(run.port(), 0) << run.log();
  const fs::path shot = testing::make_temp_dir("live_shot") / "live.png";
  const nlohmann::json seen = watch_page(run.url(), shot, "controls");
  ASSERT_FALSE(seen.contains("error")) << seen.dump() << "\n" << run.log();
  EXPECT_FALSE(seen.contains("page_error")) << seen.dump();
  // Held at the first frame, and it stays there.
  EXPECT_EQ(seen["start"], 0);
  EXPECT_EQ(seen["start_later"], 0);
  // One step: exactly one more frame, then held again.
  EXPECT_EQ(seen["step"], 1);
  EXPECT_EQ(seen["step_later"], 1);
  // Running, the map and the dynamic keypoints showed up.
  EXPECT_GT(seen["map_points"].get<int>(), 100);
  EXPECT_GE(seen["keyframes"].get<int>(), 2);
  // Local mapping links a new keyframe to the others a little after it is made: the page waits
  // for a map with covisibility edges before it pauses, so the edge toggle has something to hide.
  EXPECT_GT(seen["covisibility_edges"].get<int>(), 0);
  EXPECT_GT(seen["dynamic_seen"].get<int>(), 0);
  // The toggles (on held frames): keypoints and people's ids off leave the canvas empty (the ant
  // path is off by default), the ant path alone draws something, both back give the same picture;
  // the label overlay hides and the covisibility edges disappear from the 3D view and come back.
  EXPECT_GT(seen["marks_on"].get<int>(), 100);
  EXPECT_EQ(seen["marks_keypoints_off"], 0);
  EXPECT_GT(seen["marks_search_only"].get<int>(), 0);
  EXPECT_EQ(seen["marks_back"], seen["marks_on"]);
  EXPECT_EQ(seen["labels_shown"], "block");
  EXPECT_EQ(seen["labels_hidden"], "none");
  EXPECT_GT(seen["trajectory_on"].get<int>(), 0);
  EXPECT_LT(seen["trajectory_off"].get<int>(), seen["trajectory_on"].get<int>());
  EXPECT_EQ(seen["trajectory_back"], seen["trajectory_on"]);
  EXPECT_GT(seen["covis_on"].get<int>(), 0) << seen.dump();
  EXPECT_EQ(seen["covis_off"], 0);
  EXPECT_EQ(seen["covis_back"], seen["covis_on"]);
  // Follow camera: the orbit target stays without it and moves with the camera with it.
  EXPECT_TRUE(seen.value("target_kept_without_follow", false));
  EXPECT_TRUE(seen.value("target_moved_with_follow", false));
  EXPECT_EQ(seen["held_after_toggles"].get<int>(), seen["paused"].get<int>() + 2);  // two steps
  // Pause stops the frame counter; step moves it by one.
  EXPECT_EQ(seen["paused_step"].get<int>(), seen["held_after_toggles"].get<int>() + 1);
  EXPECT_GE(seen["paused"].get<int>(), 60);
  EXPECT_LT(seen["paused"].get<int>(), kFrames - 1);
  EXPECT_TRUE(seen.value("finished", false));

  ASSERT_TRUE(run.wait(120)) << run.log();
  EXPECT_EQ(read_tum_trajectory(run.out() / "trajectory.txt").size(), size_t{kFrames});

  ASSERT_TRUE(fs::is_regular_file(shot));
  const cv::Mat image = cv::imread(shot.string());
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 1400);
  cv::Scalar mean, deviation;
  cv::meanStdDev(image, mean, deviation);
  EXPECT_GT(deviation[0], 10.0);  // the frame, the panel and the map, not a blank page
}

// The maps the page lists when a run ends, against the run's stats.json: black frames lose
// tracking on a loop around the room; lost for half a second of the sequence with
// relocalisation failing, the tracker starts a second map when the frames come back, and loop
// closing (when on) merges it into the first once the camera is back in the first map's area.
// `merges`: how many the run makes (measured), so that neither case passes by turning into the
// other. Held at the start so the page sees the whole run.
void expect_page_lists_atlas(const fs::path& seq, const std::string& flags, int merges) {
  LiveRun run(seq, "--viewer-paused --dynamic off --blackout 40:40 --new-map-after 0.5 " + flags);
  ASSERT_GT(run.port(), 0) << run.log();
  const nlohmann::json seen =
      watch_page(run.url(), testing::make_temp_dir("live_shot") / "atlas.png", "atlas");
  ASSERT_FALSE(seen.contains("error")) << seen.dump() << "\n" << run.log();
  EXPECT_FALSE(seen.contains("page_error")) << seen.dump();
  ASSERT_TRUE(run.wait(120)) << run.log();

  const nlohmann::json atlas = read_json(run.out() / "stats.json")["atlas"];
  ASSERT_EQ(atlas["maps_tracked_in"], 2) << atlas.dump();
  ASSERT_EQ(atlas["merge_count"], merges) << atlas.dump();
  const nlohmann::json& maps = atlas["maps_at_end"];
  EXPECT_EQ(seen["maps"], maps.size()) << seen.dump();
  ASSERT_EQ(seen["maps_listed"].size(), maps.size()) << seen.dump();
  for (size_t i = 0; i < maps.size(); ++i) {
    const std::string listed = seen["maps_listed"][i];
    EXPECT_TRUE(listed.starts_with("map " + maps[i].dump() + " ")) << listed;
  }
  EXPECT_EQ(seen["merges"], atlas["merge_count"]) << seen.dump();
  ASSERT_EQ(seen["merges_listed"].size(), atlas["merges"].size()) << seen.dump();
  for (size_t i = 0; i < atlas["merges"].size(); ++i) {
    const nlohmann::json& merge = atlas["merges"][i];
    EXPECT_EQ(seen["merges_listed"][i].get<std::string>(),
              "map " + merge["from"].dump() + " merged into map " + merge["into"].dump() +
                  " at keyframe " + merge["current_keyframe"].dump());
  }
  // Each map's frusta in its colour: map 0's as in a single-map run, map 1's only while it is
  // a map of its own.
  EXPECT_GT(seen["map0_pixels"].get<int>(), 0) << seen.dump();
  if (maps.size() == 2) {
    EXPECT_GT(seen["map1_pixels"].get<int>(), 0) << seen.dump();
  }
}

TEST(CliLiveViewer, BrowserListsTheMapsOfTheAtlas) {
  if (const std::string missing = browser_missing(); !missing.empty()) GTEST_SKIP() << missing;
  const fs::path seq = sequence(120, "--bodies 0 --seed 2 --trajectory loop");
  {
    SCOPED_TRACE("loop closing off: the second map stays a map of its own");
    expect_page_lists_atlas(seq, "--loop-closing off", 0);
  }
  {
    SCOPED_TRACE("loop closing on: the second map merges into the first before the end");
    expect_page_lists_atlas(seq, "", 1);
  }
}

// The ids people.csv holds (column "id" of its header).
std::set<int> csv_ids(const fs::path& file) {
  std::ifstream stream(file);
  std::string line;
  std::getline(stream, line);
  std::vector<std::string> header;
  for (std::stringstream cells(line); std::getline(cells, line, ',');) header.push_back(line);
  const auto column = std::find(header.begin(), header.end(), "id") - header.begin();
  std::set<int> ids;
  while (std::getline(stream, line)) {
    std::stringstream cells(line);
    for (long i = 0; std::getline(cells, line, ','); ++i)
      if (i == column) ids.insert(std::stoi(line));
  }
  return ids;
}

// People from the sequence's own person masks: the page gets them with their ids, draws a box
// per person in the 3D scene and writes the ids on the frame; without --occupancy the grid's
// toggle is off and its tooltip names the flag.
TEST(CliLiveViewer, BrowserShowsThePeople) {
  if (const std::string missing = browser_missing(); !missing.empty()) GTEST_SKIP() << missing;
  const fs::path seq = sequence(90);
  LiveRun run(seq, "--viewer-paused --dynamic semantic --loop-closing off --semantic-masks " +
                       (seq / "mask").string());
  ASSERT_GT(run.port(), 0) << run.log();
  const nlohmann::json seen =
      watch_page(run.url(), testing::make_temp_dir("live_shot") / "people.png", "people");
  ASSERT_FALSE(seen.contains("error")) << seen.dump() << "\n" << run.log();
  EXPECT_FALSE(seen.contains("page_error")) << seen.dump();
  ASSERT_TRUE(run.wait(120)) << run.log();

  EXPECT_GT(seen["people_seen"].get<int>(), 0) << seen.dump();
  EXPECT_GT(seen["people_labels_seen"].get<int>(), 0) << seen.dump();
  // Held on a frame with people: the scene holds a box for each one the page counts.
  EXPECT_GT(seen["people_now"].get<int>(), 0) << seen.dump();
  EXPECT_EQ(seen["people_scene"], seen["people_now"]) << seen.dump();
  const std::set<int> written = csv_ids(run.out() / "people.csv");
  ASSERT_FALSE(written.empty()) << run.log();
  for (const int id : seen["people_ids"].get<std::vector<int>>())
    EXPECT_TRUE(written.contains(id)) << id << " is not in people.csv; " << seen.dump();
  EXPECT_TRUE(seen["occupancy_disabled"].get<bool>()) << seen.dump();
  EXPECT_TRUE(contains(seen["occupancy_tooltip"].get<std::string>(), "--occupancy")) << seen.dump();
}

// --occupancy: the toggle is offered, and the grid layer loads with free and occupied cells.
TEST(CliLiveViewer, BrowserShowsTheOccupancyGrid) {
  if (const std::string missing = browser_missing(); !missing.empty()) GTEST_SKIP() << missing;
  const fs::path seq = sequence(90);
  LiveRun run(seq, "--viewer-paused --dynamic off --loop-closing off --occupancy");
  ASSERT_GT(run.port(), 0) << run.log();
  const nlohmann::json seen =
      watch_page(run.url(), testing::make_temp_dir("live_shot") / "occupancy.png", "occupancy");
  ASSERT_FALSE(seen.contains("error")) << seen.dump() << "\n" << run.log();
  EXPECT_FALSE(seen.contains("page_error")) << seen.dump();
  ASSERT_TRUE(run.wait(120)) << run.log();
  EXPECT_FALSE(seen["occupancy_disabled"].get<bool>()) << seen.dump();
  EXPECT_GT(seen["grid_free"].get<int>(), 0) << seen.dump();
  EXPECT_GT(seen["grid_occupied"].get<int>(), 0) << seen.dump();
  EXPECT_EQ(seen["grid_meshes"], 1) << seen.dump();
}

TEST(CliLiveViewer, TraversalRefusedAndFloodDoesNotStallTracking) {
  constexpr int kFrames = 150;
  const fs::path seq = sequence(kFrames);
  const auto start = std::chrono::steady_clock::now();
  LiveRun run(seq, "");
  ASSERT_GT(run.port(), 0) << run.log();
  httplib::Client client("127.0.0.1", run.port());
  client.set_url_encode(false);  // sent byte for byte
  for (const std::string path :
       {"/../../etc/passwd", "/%2e%2e%2f%2e%2e%2fetc%2fpasswd", "/..%2f..%2f..%2fetc/passwd",
        "/%2E%2E/%2E%2E/etc/passwd", "/%252e%252e%252f%252e%252e%252fetc%252fpasswd",
        "/vendor/three/%2e%2e/%2e%2e/%2e%2e/%2e%2e/etc/passwd", "/..\\..\\etc\\passwd",
        "/api/live/../../../etc/passwd", "/%2e%2e/CMakeLists.txt"}) {
    const auto response = client.Get(path.c_str());
    ASSERT_TRUE(response) << path;
    EXPECT_TRUE(response->status == 404 || response->status == 400)
        << path << ": " << response->status;
    EXPECT_FALSE(contains(response->body, "root:")) << path;
  }
  // 1,000 requests from four connections while the run goes.
  std::atomic<int> answered{0};
  std::vector<std::thread> flood;
  for (int t = 0; t < 4; ++t) {
    flood.emplace_back([&, t] {
      httplib::Client c("127.0.0.1", run.port());
      const char* paths[] = {"/api/live/state", "/api/live/frame.jpg", "/", "/api/live/map"};
      for (int i = 0; i < 250; ++i) {
        if (c.Get(paths[(i + t) % 4])) ++answered;
      }
    });
  }
  for (std::thread& thread : flood) thread.join();
  EXPECT_EQ(answered.load(), 1000);
  EXPECT_TRUE(run.running()) << "the run ended before the flood did: the test proves nothing";
  ASSERT_TRUE(run.wait(600)) << run.log();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Generous: ~15 s on an idle 2-core machine; a stalled tracker would not finish.
  EXPECT_LT(seconds, 400.0);
  const nlohmann::json stats = read_json(run.out() / "stats.json");
  EXPECT_EQ(stats["frames"], kFrames);
  EXPECT_EQ(stats["lost_frames"], 0);
  EXPECT_EQ(read_tum_trajectory(run.out() / "trajectory.txt").size(), size_t{kFrames});
}

// Polls /api/live/state until the run loop is held after frame `index`.
bool wait_held(httplib::Client& client, int index) {
  for (int i = 0; i < 1200; ++i) {
    if (const auto response = client.Get("/api/live/state"); response && response->status == 200) {
      const nlohmann::json state = nlohmann::json::parse(response->body)["state"];
      if (state["waiting"] == true && state["held_frame"] == index) return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

TEST(CliLiveViewer, InterruptStopsServerWithEventStreamOpen) {
  LiveRun run(sequence(60), "--viewer-paused");
  ASSERT_GT(run.port(), 0) << run.log();
  httplib::Client client("127.0.0.1", run.port());
  // Three steps from the held first frame, each one frame.
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(wait_held(client, i)) << run.log();
    const auto response = client.Post("/api/step");
    ASSERT_TRUE(response);
    EXPECT_EQ(response->status, 200);
  }
  ASSERT_TRUE(wait_held(client, 3)) << run.log();
  // An open event stream must not keep the server from stopping.
  std::atomic<int> events{0};
  std::thread stream([&] {
    httplib::Client c("127.0.0.1", run.port());
    c.set_read_timeout(120, 0);
    c.Get("/api/live/events", [&](const char*, size_t) {
      ++events;
      return true;
    });
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  run.signal(SIGINT);
  const bool ended = run.wait(120);
  stream.join();
  ASSERT_TRUE(ended) << run.log();
  EXPECT_GT(events.load(), 0);
  EXPECT_TRUE(contains(run.log(), "interrupted after")) << run.log();
  const Trajectory trajectory = read_tum_trajectory(run.out() / "trajectory.txt");
  // Frames 0-3 were processed; the interrupt came while the loop was held after frame 3.
  EXPECT_EQ(trajectory.size(), 4u);
  EXPECT_TRUE(fs::is_regular_file(run.out() / "stats.json"));
}

TEST(CliLiveViewer, RealtimeRefusesPause) {
  LiveRun run(sequence(60), "--realtime");
  ASSERT_GT(run.port(), 0) << run.log();
  httplib::Client client("127.0.0.1", run.port());
  const auto response = client.Post("/api/pause");
  ASSERT_TRUE(response);
  EXPECT_EQ(response->status, 409);
  EXPECT_TRUE(contains(response->body, "--realtime")) << response->body;
  ASSERT_TRUE(run.wait(300)) << run.log();
}

}  // namespace
}  // namespace pspslam
