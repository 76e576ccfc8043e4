// `pspslam view` end to end: a short synthetic run is served, its API is read with cpp-httplib's
// client, path traversal is refused, and a headless chromium renders the page.
#include <gtest/gtest.h>
#include <signal.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>

#include "pspslam/io/point_cloud_ply.h"
#include "pspslam/io/trajectory_io.h"
#include "support/test_support.h"

// Last: through <resolv.h> it defines a macro `_res`, which Eigen uses as a parameter name.
#include <httplib.h>

namespace pspslam {
namespace {

namespace fs = std::filesystem;

using testing::contains;
using testing::read_text;

// One short run for all tests: synth + run --export-map into RUN_DIR/map.ply.
const fs::path& run_dir() {
  static const fs::path dir = [] {
    const fs::path root = testing::make_temp_dir("view_run");
    std::string output;
    const std::string cli = PSPSLAM_CLI_PATH;
    EXPECT_EQ(testing::run_shell(cli + " synth -q --out " + (root / "seq").string() +
                                     " --frames 30 --bodies 1 --seed 2",
                                 &output),
              0)
        << output;
    EXPECT_EQ(testing::run_shell(cli + " run -q --sequence " + (root / "seq").string() + " --out " +
                                     (root / "run").string() + " --export-map " +
                                     (root / "run" / "map.ply").string(),
                                 &output),
              0)
        << output;
    return root / "run";
  }();
  return dir;
}

// A `pspslam view` in the background, on a free port; SIGINT in the destructor, as Ctrl-C.
class Viewer {
 public:
  explicit Viewer(const std::string& arguments) : log_(testing::make_temp_dir("view_log") / "log") {
    std::string pid;
    testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " view " + arguments + " > '" +
                           log_.string() + "' 2>&1 & echo $!",
                       &pid);
    pid_ = std::stoi(pid);
    // Generous: the machine may be busy with other tests.
    const std::string marker = "viewer: http://";
    for (int i = 0; i < 600 && !contains(log(), marker); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    const std::string text = log();
    const size_t at = text.find(marker);
    if (at == std::string::npos) return;
    const size_t colon = text.find(':', at + marker.size());
    port_ = std::stoi(text.substr(colon + 1));
  }
  ~Viewer() { stop(); }
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  int port() const { return port_; }
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port_) + "/"; }
  std::string log() const { return read_text(log_); }

  // True once the server said it stopped after SIGINT.
  bool stop() {
    if (pid_ <= 0) return false;
    kill(pid_, SIGINT);
    pid_ = 0;
    for (int i = 0; i < 300; ++i) {
      if (contains(log(), "viewer stopped")) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }

 private:
  fs::path log_;
  int pid_ = 0;
  int port_ = 0;
};

TEST(CliView, ServesTheRunAndStopsOnInterrupt) {
  Viewer viewer(run_dir().string() + " --viewer 0");
  ASSERT_GT(viewer.port(), 0) << viewer.log();
  httplib::Client client("127.0.0.1", viewer.port());
  client.set_read_timeout(60, 0);

  const auto trajectory = client.Get("/api/trajectory");
  ASSERT_TRUE(trajectory) << viewer.log();
  ASSERT_EQ(trajectory->status, 200);
  const nlohmann::json poses = nlohmann::json::parse(trajectory->body);
  EXPECT_EQ(poses["online"].size(), read_tum_trajectory(run_dir() / "trajectory.txt").size());
  EXPECT_EQ(poses["refined"].size(),
            read_tum_trajectory(run_dir() / "trajectory_refined.txt").size());
  EXPECT_EQ(poses["keyframes"].size(), read_tum_trajectory(run_dir() / "keyframes.txt").size());
  EXPECT_EQ(poses["online"].size(), 30u);

  const auto map = client.Get("/api/map");
  ASSERT_TRUE(map);
  EXPECT_EQ(nlohmann::json::parse(map->body)["positions"].size(),
            3 * read_point_cloud_ply(run_dir() / "map.ply").size());
  const auto stats = client.Get("/api/stats");
  ASSERT_TRUE(stats);
  EXPECT_EQ(nlohmann::json::parse(stats->body)["frames"], 30);
  // The sequence named in stats.json has a groundtruth.txt: aligned, one position per pose.
  const auto truth = client.Get("/api/groundtruth");
  ASSERT_TRUE(truth);
  const nlohmann::json truth_json = nlohmann::json::parse(truth->body);
  EXPECT_EQ(truth_json["positions"].size(), 30u);
  EXPECT_LT(truth_json["ate_rmse"].get<double>(), 0.05);

  const auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_TRUE(contains(page->body, "viewer.js"));
  const auto three = client.Get("/vendor/three/build/three.module.js");
  ASSERT_TRUE(three);
  EXPECT_EQ(three->status, 200);
  EXPECT_EQ(three->get_header_value("Content-Type"), "text/javascript; charset=utf-8");

  EXPECT_TRUE(viewer.stop()) << viewer.log();
}

TEST(CliView, PathTraversalIsRefused) {
  Viewer viewer(run_dir().string() + " --viewer 127.0.0.1:0");
  ASSERT_GT(viewer.port(), 0) << viewer.log();
  httplib::Client client("127.0.0.1", viewer.port());
  // Sent byte for byte: no client-side encoding or normalisation.
  client.set_url_encode(false);
  for (const std::string path :
       {"/../../etc/passwd", "/%2e%2e%2f%2e%2e%2fetc%2fpasswd", "/..%2f..%2f..%2fetc/passwd",
        "/%2E%2E/%2E%2E/etc/passwd", "/vendor/three/../../../../../../etc/passwd",
        "/vendor/three/%2e%2e/%2e%2e/%2e%2e/%2e%2e/etc/passwd", "/%252e%252e/etc/passwd",
        "/..\\..\\etc\\passwd", "//etc/passwd", "/api/../../etc/passwd"}) {
    const auto response = client.Get(path.c_str());
    ASSERT_TRUE(response) << path;
    EXPECT_TRUE(response->status == 404 || response->status == 400)
        << path << ": " << response->status;
    EXPECT_FALSE(contains(response->body, "root:")) << path;
  }
  // Files of the repository next to web/ are outside the asset folder too.
  const auto outside = client.Get("/../CMakeLists.txt");
  ASSERT_TRUE(outside);
  EXPECT_EQ(outside->status, 404);
}

TEST(CliView, BadArgumentsAndNonLoopbackWarning) {
  std::string output;
  const std::string cli = PSPSLAM_CLI_PATH;
  EXPECT_EQ(testing::run_shell(cli + " view /nonexistent_run_dir", &output), 2);
  EXPECT_TRUE(contains(output, "not a run folder")) << output;
  EXPECT_EQ(testing::run_shell(cli + " view " + run_dir().string() + " --viewer 70000", &output),
            2);
  EXPECT_TRUE(contains(output, "[HOST:]PORT")) << output;
  EXPECT_EQ(testing::run_shell(cli + " view " + run_dir().string() + " --viewer host:", &output),
            2);
  Viewer open(run_dir().string() + " --viewer 0.0.0.0:0");
  ASSERT_GT(open.port(), 0) << open.log();
  EXPECT_TRUE(contains(open.log(), "warning: the viewer listens on 0.0.0.0")) << open.log();
}

// A real browser: the page must fetch the API and fill the panel, and the 3D view must draw.
TEST(CliView, HeadlessChromiumRendersTheCounters) {
  std::string found;
  if (testing::run_shell("command -v chromium", &found) != 0) {
    GTEST_SKIP() << "chromium is not installed (scripts/install-deps installs it)";
  }
  Viewer viewer(run_dir().string() + " --viewer 0");
  ASSERT_GT(viewer.port(), 0) << viewer.log();
  const fs::path dir = testing::make_temp_dir("view_browser");
  // Own profile per run (parallel tests), no proxy (the server is local), software WebGL.
  const std::string chromium =
      "timeout 300 chromium --headless --disable-gpu --no-sandbox --no-proxy-server "
      "--enable-unsafe-swiftshader --user-data-dir='" +
      (dir / "profile").string() + "' --virtual-time-budget=30000 --window-size=1000,700 ";
  std::string dom;
  testing::run_shell(chromium + "--dump-dom " + viewer.url() + " 2>/dev/null", &dom);
  EXPECT_TRUE(contains(dom, "data-ready=\"true\"")) << dom;
  EXPECT_TRUE(contains(dom, "<td id=\"frames\">30</td>")) << dom;
  EXPECT_TRUE(contains(dom, "<td id=\"lost\">0</td>")) << dom;
  EXPECT_TRUE(contains(dom, "<canvas")) << dom;

  const fs::path shot = dir / "shot.png";
  std::string output;
  testing::run_shell(chromium + "--screenshot='" + shot.string() + "' " + viewer.url(), &output);
  ASSERT_TRUE(fs::is_regular_file(shot)) << output;
  const cv::Mat image = cv::imread(shot.string());
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 1000);
  // Not a blank page: the dark 3D view, the lighter panel, its text and the map's points.
  cv::Scalar mean, deviation;
  cv::meanStdDev(image, mean, deviation);
  EXPECT_GT(deviation[0], 5.0);
  EXPECT_GT(fs::file_size(shot), 10000u);
}

}  // namespace
}  // namespace pspslam
