#include "pspslam/viewer/live_viewer.h"

#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>
#include <unordered_map>
#include <utility>

#include "pspslam/core/error.h"
#include "pspslam/core/interrupt.h"
#include "pspslam/eval/ate.h"
#include "pspslam/io/input_frame.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/occupancy/occupancy_grid.h"
#include "pspslam/semantic/overlay.h"
#include "pspslam/session/occupancy_run.h"

namespace pspslam {

// What the run loop copies for one shown frame: image headers (frames are loaded fresh and never
// written afterwards, so sharing their pixels is safe), the keypoints and the numbers.
struct LiveViewer::FrameSnapshot {
  size_t index = 0;
  Timestamp timestamp = 0.0;
  size_t total = 0;
  cv::Mat bgr, labels, regions;
  bool detail = false;
  std::vector<KeypointRecord> keypoints;
  std::vector<GeometryPicture::TestedPoint> tested;
  std::vector<cv::Point2f> path;
  TrackResult tracking;
  double extraction_ms = 0.0, tracking_ms = 0.0, local_ba_ms = 0.0;
  DynamicReport dynamic;
  std::vector<ShownPerson> people;
  MappingStats mapping;
  size_t processed = 0, lost = 0, relocalisations = 0, dropped = 0, masked = 0, tested_total = 0,
         dynamic_total = 0, culled = 0, without_mask = 0;
  Clock::time_point time;
};

// The map as the run loop saw it: positions only, no shared pointers kept past the copy.
struct LiveViewer::MapSnapshot {
  std::vector<float> positions;  // x, y, z per static map point
  std::vector<Pose> keyframes;
  std::vector<std::uint32_t> keyframe_maps;  // the atlas map of each keyframe
  std::vector<std::array<int, 2>> edges;     // covisibility, indices into keyframes
  std::vector<MapMerge> merges;              // the atlas's merges so far, in order
  Trajectory estimate;
};

namespace {

using nlohmann::json;

// The people of a frame with the pixel each one's centre projects to (none: no pose, no
// intrinsics, or behind the camera), so the page can write the ids on the frame.
std::vector<ShownPerson> shown_people(const FrameView& view) {
  std::vector<ShownPerson> shown;
  const std::optional<Pose>& pose = view.report.tracking.T_world_camera;
  for (const TrackedPerson& person : view.report.people.people) {
    ShownPerson& s = shown.emplace_back(ShownPerson{person, std::nullopt});
    if (!pose || !view.camera) continue;
    const Eigen::Vector3d in_camera = pose->inverse() * person.position;
    if (in_camera.z() > 0.05) s.pixel = view.camera->project(in_camera);
  }
  return shown;
}

json vector_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

double round2(double value) { return std::round(value * 100.0) / 100.0; }

// Covisibility edges drawn: the strong ones only, or the graph hides the map (ORB-SLAM2's viewer
// draws weight >= 100; synthetic and Bonn keyframes share fewer points, hence lower).
constexpr int kCovisibilityWeight = 30;

json pose_json(const Pose& pose) {
  const Eigen::Vector3d p = pose.translation();
  const Eigen::Quaterniond q(pose.rotation());
  return {{"p", {p.x(), p.y(), p.z()}}, {"q", {q.x(), q.y(), q.z(), q.w()}}};
}

double round1(double value) { return std::round(value * 10.0) / 10.0; }

std::shared_ptr<const std::string> share(std::string text) {
  return std::make_shared<const std::string>(std::move(text));
}

std::shared_ptr<const std::string> encode(const std::string& ext, const cv::Mat& image,
                                          const std::vector<int>& params = {}) {
  std::vector<uchar> bytes;
  cv::imencode(ext, image, bytes, params);
  return share(std::string(bytes.begin(), bytes.end()));
}

// Labels as a translucent BGRA picture for the page to lay over the frame: dynamic classes strong,
// static ones faint, background clear (colours of semantic/overlay.h, so the pictures of
// --save-overlays and the page agree).
cv::Mat label_picture(const cv::Mat& labels, cv::Size size, const OverlayClasses& classes) {
  cv::Mat small;
  cv::resize(labels, small, size, 0, 0, cv::INTER_NEAREST);
  std::array<cv::Vec4b, 256> lut{};
  for (int id = 1; id < 256; ++id) {
    const cv::Vec3b c = overlay_class_colour(id, classes.dynamic_ids, classes.names);
    const bool dynamic = std::find(classes.dynamic_ids.begin(), classes.dynamic_ids.end(), id) !=
                         classes.dynamic_ids.end();
    lut[id] = {c[0], c[1], c[2], static_cast<uchar>(dynamic ? 150 : 60)};
  }
  cv::Mat picture(small.size(), CV_8UC4);
  for (int v = 0; v < small.rows; ++v) {
    const uchar* in = small.ptr<uchar>(v);
    cv::Vec4b* out = picture.ptr<cv::Vec4b>(v);
    for (int u = 0; u < small.cols; ++u) out[u] = lut[in[u]];
  }
  return picture;
}

// Grown dynamic regions: a faint orange fill and a solid outline, so they read on top of the
// person labels they mostly agree with.
cv::Mat region_picture(const cv::Mat& regions, cv::Size size) {
  cv::Mat small;
  cv::resize(regions, small, size, 0, 0, cv::INTER_NEAREST);
  cv::Mat picture(small.size(), CV_8UC4, cv::Scalar::all(0));
  picture.setTo(cv::Scalar(0, 140, 255, 70), small);
  std::vector<std::vector<cv::Point>> outlines;
  cv::findContours(small, outlines, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  cv::drawContours(picture, outlines, -1, cv::Scalar(0, 140, 255, 255), 2);
  return picture;
}

}  // namespace

cv::Mat grid_picture(const OccupancyGrid& grid) {
  cv::Mat picture(grid.height, grid.width, CV_8UC4, cv::Scalar::all(0));
  for (int row = 0; row < grid.height; ++row) {
    cv::Vec4b* out = picture.ptr<cv::Vec4b>(grid.height - 1 - row);
    for (int column = 0; column < grid.width; ++column) {
      const std::int8_t cell = grid.at(column, row);
      if (cell == kGridFree) out[column] = {230, 230, 230, 90};     // BGRA
      if (cell == kGridOccupied) out[column] = {40, 40, 200, 230};  // dark red
    }
  }
  return picture;
}

nlohmann::json grid_json(const OccupancyGrid& grid, std::uint64_t version) {
  json pose = json::array();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) pose.push_back(grid.T_world_grid.matrix()(r, c));
  return {{"version", version},
          {"width", grid.width},
          {"height", grid.height},
          {"resolution", grid.resolution},
          {"origin", {grid.origin.x(), grid.origin.y()}},
          {"T_world_grid", std::move(pose)},
          {"cells",
           {{"unknown", grid.count(kGridUnknown)},
            {"free", grid.count(kGridFree)},
            {"occupied", grid.count(kGridOccupied)}}}};
}

nlohmann::json person_json(const ShownPerson& shown) {
  const TrackedPerson& p = shown.person;
  json pixel;
  if (shown.pixel) pixel = {round1(shown.pixel->x()), round1(shown.pixel->y())};
  return {{"id", p.id},
          {"p", vector_json(p.position)},
          {"v", vector_json(p.velocity)},
          {"extent", round2(p.extent_m)},
          {"seen", p.visible_pixels > 0},
          {"pixel", std::move(pixel)}};
}

LiveViewer::LiveViewer(LiveViewerOptions options)
    : options_(std::move(options)), server_(options_.web_root, "live.html") {
  paused_ = options_.start_paused && !options_.realtime;
  if (!options_.ground_truth.empty()) {
    try {
      ground_truth_ = read_tum_trajectory(options_.ground_truth);
    } catch (const Error& e) {
      spdlog::warn("viewer: ground truth not shown: {}", e.what());
    }
  }
  const auto shared_reply = [this](const std::shared_ptr<const std::string> LiveViewer::*member,
                                   const char* type) {
    return [this, member, type](const WebServer::Query&) {
      std::lock_guard lock(mutex_);
      const std::shared_ptr<const std::string>& body = this->*member;
      if (!body) return HttpReply{404, "text/plain", share("not yet\n")};
      return HttpReply{200, type, body};
    };
  };
  server_.get("/api/live/frame.jpg", shared_reply(&LiveViewer::jpeg_, "image/jpeg"));
  server_.get("/api/live/labels.png", shared_reply(&LiveViewer::labels_png_, "image/png"));
  server_.get("/api/live/regions.png", shared_reply(&LiveViewer::regions_png_, "image/png"));
  server_.get("/api/live/map", shared_reply(&LiveViewer::map_json_, "application/json"));
  server_.get("/api/live/grid", shared_reply(&LiveViewer::grid_json_, "application/json"));
  server_.get("/api/live/grid.png", shared_reply(&LiveViewer::grid_png_, "image/png"));
  server_.get("/api/live/info", [this](const WebServer::Query&) {
    return HttpReply{200, "application/json",
                     share(json{{"title", options_.title},
                                {"realtime", options_.realtime},
                                {"interval_ms", options_.interval.count()},
                                {"map_interval_ms", options_.map_interval.count()},
                                {"ground_truth", options_.ground_truth.string()},
                                {"occupancy", options_.occupancy}}
                               .dump())};
  });
  server_.get("/api/live/state", [this](const WebServer::Query&) {
    std::lock_guard lock(mutex_);
    return HttpReply{200, "application/json", share(event_json())};
  });
  server_.events("/api/live/events", [this](std::uint64_t& last) { return next_event(last); });
  server_.post("/api/pause",
               [this](const WebServer::Query&) { return control(&LiveViewer::pause); });
  server_.post("/api/resume",
               [this](const WebServer::Query&) { return control(&LiveViewer::resume); });
  server_.post("/api/step", [this](const WebServer::Query&) { return control(&LiveViewer::step); });
  url_ = server_.listen(options_.endpoint);
  encoder_ = std::thread([this] { encode_loop(); });
}

LiveViewer::~LiveViewer() {
  {
    std::lock_guard lock(mutex_);
    closing_ = true;
  }
  work_.notify_all();
  changed_.notify_all();
  // Event streams send what they have not sent yet, see closing_ and end (a page that stopped
  // reading gets a second), then the server's threads can be joined.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (server_.open_event_streams() > 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  server_.stop();
  encoder_.join();
}

RunObserver::Detail LiveViewer::wants_detail() {
  std::lock_guard lock(mutex_);
  detail_ = paused_ || Clock::now() - last_frame_snapshot_ >= options_.interval;
  return {detail_, detail_ && !options_.realtime};
}

void LiveViewer::frame_done(const FrameView& view) {
  const Clock::time_point now = Clock::now();
  std::unique_lock lock(mutex_);
  const bool detail = detail_;
  const bool show = detail || paused_;
  // The last frame of a sequence always sends the map, so the page ends on the atlas the frames
  // left (a new map or a merge just before the end would otherwise never be shown).
  const bool last_frame = view.frames_total > 0 && view.frame.index + 1 == view.frames_total;
  const bool map_due =
      last_frame || (show && (paused_ || now - last_map_snapshot_ >= options_.map_interval ||
                              view.mapping.keyframes_in_map != last_map_keyframes_ ||
                              view.mapping.map_merges.size() != last_map_merges_));
  lock.unlock();

  // The copies, outside the lock: the encoder may be busy with the snapshot before.
  std::unique_ptr<FrameSnapshot> frame = show ? snapshot_frame(view, detail, now) : nullptr;
  std::unique_ptr<MapSnapshot> map = map_due ? snapshot_map(view) : nullptr;

  lock.lock();
  if (frame) {
    pending_frame_ = std::move(frame);  // newest wins: an older one not yet encoded is dropped
    last_frame_snapshot_ = now;
  }
  if (view.occupancy) last_occupancy_ = view.occupancy;
  if (view.occupancy && !ended_ && now - last_grid_ >= options_.grid_interval) {
    pending_grid_ = view.occupancy;
    last_grid_ = now;
  }
  if (map) {
    pending_map_ = std::move(map);
    last_map_snapshot_ = now;
    last_map_keyframes_ = view.mapping.keyframes_in_map;
    last_map_merges_ = view.mapping.map_merges.size();
  }
  work_.notify_one();
  // A pause that came while this frame was processed without its keypoint fates holds after the
  // next frame, which records them (wants_detail() says so while paused): the held frame is
  // always shown whole.
  if (!paused_ || options_.realtime || !detail) return;
  hold(lock, view.frame.index);
}

std::unique_ptr<LiveViewer::FrameSnapshot> LiveViewer::snapshot_frame(const FrameView& view,
                                                                      bool detail,
                                                                      Clock::time_point now) {
  auto frame = std::make_unique<FrameSnapshot>();
  FrameSnapshot& s = *frame;
  s.index = view.frame.index;
  s.timestamp = view.frame.timestamp;
  s.total = view.frames_total;
  s.bgr = view.frame.bgr;
  s.labels = view.system.last_semantic_labels();
  s.detail = detail;
  s.keypoints = view.report.keypoints;
  if (const GeometryPicture* picture = view.system.last_geometry_picture()) {
    s.regions = picture->regions;  // already a copy of the stage's buffer
    s.tested = picture->tested;
    s.path = picture->path;
  }
  s.tracking = view.report.tracking;
  s.extraction_ms = view.report.extraction_ms;
  s.tracking_ms = view.report.tracking_ms;
  s.local_ba_ms =
      view.statistics.local_mapping_ms.empty() ? 0.0 : view.statistics.local_mapping_ms.back();
  s.dynamic = view.report.dynamic;
  s.people = shown_people(view);
  s.mapping = view.mapping;
  const RunStatistics& st = view.statistics;
  s.processed = st.processed();
  s.lost = st.lost();
  s.relocalisations = st.relocalisations();
  s.dropped = st.realtime_dropped();
  s.masked = st.masked_keypoints;
  s.tested_total = st.tested_points;
  s.dynamic_total = st.dynamic_points;
  s.culled = st.culled_points;
  s.without_mask = st.frames_without_mask;
  s.time = now;
  return frame;
}

std::unique_ptr<LiveViewer::MapSnapshot> LiveViewer::snapshot_map(const FrameView& view) {
  auto map = std::make_unique<MapSnapshot>();
  const Map& slam_map = view.system.map();
  for (const auto& point : slam_map.map_points()) {
    if (point->is_bad()) continue;
    const Eigen::Vector3d p = point->position();
    map->positions.insert(
        map->positions.end(),
        {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
  }
  std::unordered_map<std::uint64_t, int> index;
  const auto keyframes = slam_map.keyframes();
  for (const auto& keyframe : keyframes) {
    if (keyframe->is_bad()) continue;
    index[keyframe->id()] = static_cast<int>(map->keyframes.size());
    map->keyframes.push_back(keyframe->T_world_camera());
    map->keyframe_maps.push_back(keyframe->map_id());
  }
  for (const auto& keyframe : keyframes) {
    const auto from = index.find(keyframe->id());
    if (from == index.end()) continue;
    for (const auto& other : keyframe->covisibles_with_min_weight(kCovisibilityWeight)) {
      const auto to = index.find(other->id());
      if (to != index.end() && to->second > from->second)
        map->edges.push_back({from->second, to->second});
    }
  }
  map->merges = slam_map.merges();
  map->estimate = view.estimate;
  return map;
}

void LiveViewer::hold(std::unique_lock<std::mutex>& lock, size_t frame_index) {
  // Held between frames until resume or step; the poll lets Ctrl-C end a paused run.
  waiting_ = true;
  held_frame_ = frame_index;
  ++event_;
  changed_.notify_all();
  while (paused_ && steps_ == 0 && !closing_ && !interrupted())
    changed_.wait_for(lock, std::chrono::milliseconds(100));
  if (steps_ > 0) --steps_;
  waiting_ = false;
  ++event_;
  changed_.notify_all();
}

void LiveViewer::run_ended() {
  std::unique_lock lock(mutex_);
  ended_ = true;
  paused_ = false;
  pending_grid_ = nullptr;
  ++event_;
  changed_.notify_all();
  changed_.wait(lock, [this] { return !grid_busy_; });
  // The grid as the run left it, published here while the map still exists: a run (or its last
  // stretch) shorter than the refresh interval would otherwise leave the page an older grid.
  const OccupancyRun* occupancy = std::exchange(last_occupancy_, nullptr);
  lock.unlock();
  if (occupancy) publish_grid(*occupancy);
}

bool LiveViewer::pause() {
  std::lock_guard lock(mutex_);
  if (options_.realtime || ended_) return false;
  paused_ = true;
  ++event_;
  changed_.notify_all();
  return true;
}

bool LiveViewer::resume() {
  std::lock_guard lock(mutex_);
  if (options_.realtime || ended_) return false;
  paused_ = false;
  steps_ = 0;
  ++event_;
  changed_.notify_all();
  return true;
}

bool LiveViewer::step() {
  std::lock_guard lock(mutex_);
  if (options_.realtime || ended_) return false;
  // A step while running pauses; a step while held lets exactly one more frame through (a
  // second click before that frame is held waits for it: steps are not queued).
  if (paused_ && waiting_) steps_ = 1;
  paused_ = true;
  ++event_;
  changed_.notify_all();
  return true;
}

HttpReply LiveViewer::control(bool (LiveViewer::*action)()) {
  if ((this->*action)()) return {200, "application/json", share(R"({"ok":true})")};
  const std::string why = options_.realtime
                              ? "a --realtime run cannot be paused: its frames keep coming from "
                                "the source and would be dropped, not held"
                              : "the run is over";
  return {409, "application/json", share(json{{"ok", false}, {"error", why}}.dump())};
}

std::string LiveViewer::state_json() const {
  return json{{"paused", paused_},
              {"waiting", waiting_},
              {"held_frame", held_frame_},
              {"ended", ended_},
              {"realtime", options_.realtime},
              {"frame_version", frame_version_},
              {"map_version", map_version_},
              {"grid_version", grid_version_},
              {"pages", server_.open_event_streams()}}
      .dump();
}

std::optional<std::string> LiveViewer::next_event(std::uint64_t& last) {
  std::unique_lock lock(mutex_);
  if (!changed_.wait_for(lock, std::chrono::seconds(1), [&] { return closing_ || event_ != last; }))
    return std::string();  // keep-alive
  // The last change first, then the end of the stream: the run's end (state "ended") comes just
  // before the viewer closes, and a page that missed it would wait for a run that is over.
  if (event_ != last) {
    last = event_;
    return event_json();
  }
  return std::nullopt;
}

std::string LiveViewer::event_json() const {
  return R"({"event":)" + std::to_string(event_) + R"(,"state":)" + state_json() + R"(,"frame":)" +
         (frame_json_ ? *frame_json_ : std::string("null")) + "}";
}

void LiveViewer::encode_loop() {
  std::unique_lock lock(mutex_);
  while (true) {
    work_.wait(lock,
               [this] { return closing_ || pending_frame_ || pending_map_ || pending_grid_; });
    if (closing_) return;
    std::unique_ptr<FrameSnapshot> frame = std::move(pending_frame_);
    std::unique_ptr<MapSnapshot> map = std::move(pending_map_);
    const OccupancyRun* grid = std::exchange(pending_grid_, nullptr);
    grid_busy_ = grid != nullptr;
    lock.unlock();
    if (frame) publish_frame(*frame);
    if (map) publish_map(*map);
    if (grid) publish_grid(*grid);
    lock.lock();
    if (grid) {
      grid_busy_ = false;
      changed_.notify_all();
    }
  }
}

void LiveViewer::publish_frame(const FrameSnapshot& s) {
  const double scale = std::min(1.0, static_cast<double>(options_.image_width) / s.bgr.cols);
  const cv::Size size(static_cast<int>(std::lround(s.bgr.cols * scale)),
                      static_cast<int>(std::lround(s.bgr.rows * scale)));
  cv::Mat small;
  cv::resize(s.bgr, small, size, 0, 0, cv::INTER_AREA);
  auto jpeg = encode(".jpg", small, {cv::IMWRITE_JPEG_QUALITY, 80});
  auto labels = s.labels.empty() ? nullptr
                                 : encode(".png", label_picture(s.labels, size, options_.classes),
                                          {cv::IMWRITE_PNG_COMPRESSION, 1});
  auto regions = s.regions.empty() ? nullptr
                                   : encode(".png", region_picture(s.regions, size),
                                            {cv::IMWRITE_PNG_COMPRESSION, 1});

  update_fps(s);
  auto text = share(frame_json(s, labels != nullptr, regions != nullptr));

  std::lock_guard lock(mutex_);
  frame_json_ = std::move(text);
  jpeg_ = std::move(jpeg);
  labels_png_ = std::move(labels);
  regions_png_ = std::move(regions);
  ++frame_version_;
  ++event_;
  changed_.notify_all();
}

// fps over the snapshots: frames processed between two of them over the time between.
void LiveViewer::update_fps(const FrameSnapshot& s) {
  if (!fps_reference_ || s.processed < fps_reference_->first) {
    fps_reference_.emplace(s.processed, s.time);
  } else if (const double seconds =
                 std::chrono::duration<double>(s.time - fps_reference_->second).count();
             seconds >= 1.0) {
    fps_ = (s.processed - fps_reference_->first) / seconds;
    fps_reference_.emplace(s.processed, s.time);
  }
}

std::string LiveViewer::frame_json(const FrameSnapshot& s, bool labels, bool regions) const {
  std::array<int, 4> fates{};
  json keypoints = json::array();
  for (const KeypointRecord& k : s.keypoints) {
    keypoints.push_back({round1(k.position.x), round1(k.position.y), static_cast<int>(k.fate)});
    ++fates[static_cast<size_t>(k.fate)];
  }
  json tested = json::array();
  for (const auto& t : s.tested)
    tested.push_back({round1(t.position.x), round1(t.position.y), t.dynamic ? 1 : 0});
  json path = json::array();
  for (const cv::Point2f& node : s.path) path.push_back({round1(node.x), round1(node.y)});

  const DynamicReport& d = s.dynamic;
  json people = json::array();
  for (const ShownPerson& shown : s.people) people.push_back(person_json(shown));
  const json frame = {
      {"index", s.index},
      {"timestamp", s.timestamp},
      {"total", s.total},
      {"width", s.bgr.cols},
      {"height", s.bgr.rows},
      {"detail", s.detail},
      {"masked_recorded", s.detail && !options_.realtime},
      {"state", to_string(s.tracking.state)},
      {"method", to_string(s.tracking.method)},
      {"inliers", s.tracking.num_inliers},
      {"keyframe", s.tracking.keyframe_inserted},
      {"pose", s.tracking.T_world_camera ? pose_json(*s.tracking.T_world_camera) : json()},
      {"keypoints", std::move(keypoints)},
      {"fates", fates},
      {"tested", std::move(tested)},
      {"path", std::move(path)},
      {"people", std::move(people)},
      {"labels", labels},
      {"regions", regions},
      {"timing",
       {{"extraction", round1(s.extraction_ms)},
        {"flow", round1(d.flow_ms)},
        {"semantic_wait", round1(d.semantic_wait_ms)},
        {"semantic_inference", round1(d.semantic_inference_ms)},
        {"geometry", round1(d.geometry_ms)},
        {"search", round1(d.geometry_search_ms)},
        {"tracking", round1(s.tracking_ms)},
        {"local_ba", round1(s.local_ba_ms)}}},
      {"fps", round1(fps_)},
      {"mask_age", d.mask_age_frames},
      {"mask_warped", d.mask_warped},
      {"counters",
       {{"processed", s.processed},
        {"lost", s.lost},
        {"relocalisations", s.relocalisations},
        {"dropped_by_feed", s.dropped},
        {"keyframes", s.mapping.keyframes_in_map},
        {"map_points", s.mapping.map_points},
        {"masked_keypoints", s.masked},
        {"tested_points", s.tested_total},
        {"dynamic_points", s.dynamic_total},
        {"culled_map_points", s.culled},
        {"frames_without_mask", s.without_mask},
        {"loops_closed", s.mapping.loops_closed}}}};
  return frame.dump();
}

void LiveViewer::publish_map(const MapSnapshot& s) {
  json keyframes = json::array();
  for (const Pose& pose : s.keyframes) keyframes.push_back(pose_json(pose));
  json trajectory = json::array();
  for (const StampedPose& pose : s.estimate) {
    const Eigen::Vector3d p = pose.T_world_camera.translation();
    trajectory.push_back({p.x(), p.y(), p.z()});
  }
  json truth = json::array();
  double ate_rmse = -1.0;
  // The ground truth moved into the estimate's frame (the inverse of the ATE alignment), as
  // `pspslam view` does; too few poses yet is no error, just nothing to show.
  if (!ground_truth_.empty() && s.estimate.size() >= 10) {
    try {
      const AteResult ate = compute_ate(ground_truth_, s.estimate);
      for (const Eigen::Vector3d& g : ate.gt_all) {
        const Eigen::Vector3d p = ate.alignment.inverse_apply(g);
        truth.push_back({p.x(), p.y(), p.z()});
      }
      ate_rmse = ate.error.rmse;
    } catch (const Error&) {
    }
  }
  json merges = json::array();
  for (const MapMerge& merge : s.merges) {
    merges.push_back({{"from", merge.from},
                      {"into", merge.into},
                      {"current_keyframe", merge.current_keyframe},
                      {"matched_keyframe", merge.matched_keyframe}});
  }
  auto text = share(json{
      {"positions", s.positions},
      {"keyframes", std::move(keyframes)},
      {"keyframe_maps", s.keyframe_maps},
      {"edges", s.edges},
      {"merges", std::move(merges)},
      {"trajectory", std::move(trajectory)},
      {"truth", std::move(truth)},
      {"ate_rmse",
       ate_rmse}}.dump());
  std::lock_guard lock(mutex_);
  map_json_ = std::move(text);
  ++map_version_;
  ++event_;
  changed_.notify_all();
}

void LiveViewer::publish_grid(const OccupancyRun& occupancy) {
  OccupancyGrid grid;
  try {
    grid = occupancy.live_grid();
  } catch (const std::exception& e) {
    spdlog::debug("viewer: no occupancy grid yet: {}", e.what());
    return;
  }
  if (grid.width == 0 || grid.height == 0) return;
  auto png = encode(".png", grid_picture(grid), {cv::IMWRITE_PNG_COMPRESSION, 3});
  std::lock_guard lock(mutex_);
  grid_png_ = std::move(png);
  grid_json_ = share(grid_json(grid, ++grid_version_).dump());
  ++event_;
  changed_.notify_all();
}

}  // namespace pspslam
