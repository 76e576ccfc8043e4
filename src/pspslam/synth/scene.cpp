#include "pspslam/synth/scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <thread>
#include <vector>

#include "pspslam/core/error.h"
#include "pspslam/synth/kinect.h"
#include "pspslam/synth/motion.h"
#include "pspslam/synth/sensor.h"
#include "pspslam/synth/texture.h"

namespace pspslam {
namespace {

constexpr double kFps = 30.0;
constexpr double kFirstTimestamp = 1000000.0;
constexpr float kStaticTexelsPerMetre = 256.0f;
constexpr float kBodyTexelsPerMetre = 200.0f;
constexpr float kNearPlane_m = 0.02f;  // equals the clip plane of the screen rectangles
constexpr int kRowsPerChunk = 8;

// What a box looks like; its pose is given separately (fixed for furniture, animated for bodies).
struct BoxSurface {
  Eigen::Vector3d half_extents;
  bool seen_from_inside = false;  // the room: we see the far side of its faces
  uint8_t label = kSynthLabelStatic;
  std::array<int, 6> face_textures{};  // face = 2 * axis + (positive side ? 1 : 0)
};

// A box as seen from one camera pose, ready for ray casting pixel rays (x_n, y_n, 1).
struct FrameBox {
  const BoxSurface* surface = nullptr;
  Eigen::Matrix3f R_box_camera;
  Eigen::Vector3f camera_in_box;
  Eigen::Vector3f half;
  std::array<float, 6> face_light{};   // lighting of each face (1 when baked into the texture)
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // screen rectangle that can contain the box (end exclusive)
  uint16_t first_surface_id = 0;
};

struct Furniture {
  Eigen::Vector3d centre;
  Eigen::Vector3d half;
  double yaw = 0.0;
};

// Furniture along the walls, leaving the middle free for the camera and the walking people.
const std::vector<Furniture>& furniture_layout() {
  static const std::vector<Furniture> layout = {
      {{1.5, 0.25, 0.45}, {0.6, 0.25, 0.45}},          // cabinet
      {{6.78, 2.0, 0.95}, {0.22, 0.5, 0.95}},          // tall shelf
      {{4.5, 5.6, 0.38}, {0.7, 0.4, 0.38}},            // desk
      {{4.2, 5.65, 0.86}, {0.15, 0.15, 0.1}, 0.3},     // box on the desk
      {{0.4, 3.2, 0.22}, {0.4, 0.9, 0.22}},            // sofa seat
      {{0.1, 3.2, 0.5}, {0.1, 0.9, 0.5}},              // sofa back
      {{6.55, 0.45, 0.3}, {0.3, 0.3, 0.3}, 0.2},       // crate
      {{6.55, 0.45, 0.72}, {0.18, 0.18, 0.12}, -0.3},  // small crate on it
      {{0.3, 0.3, 1.4}, {0.2, 0.2, 1.4}},              // corner column
      {{3.0, 5.985, 1.6}, {0.6, 0.015, 0.4}},          // picture
      {{3.4, 0.015, 1.0}, {0.45, 0.015, 1.0}},         // door
      {{6.985, 4.3, 1.5}, {0.015, 0.7, 0.5}},          // whiteboard
      {{1.6, 5.75, 0.35}, {0.5, 0.25, 0.35}},          // low cabinet
      {{6.6, 5.6, 0.4}, {0.2, 0.2, 0.4}},              // planter
  };
  return layout;
}

cv::Vec3b bgr(int b, int g, int r) {
  return cv::Vec3b(static_cast<uchar>(b), static_cast<uchar>(g), static_cast<uchar>(r));
}

// Recipes of one person's clothes, skin and carried box; softer than the static surfaces.
struct BodyLook {
  synth::TextureRecipe shirt, trousers, skin, carried_box;
};

BodyLook body_look(uint64_t body_seed) {
  cv::RNG rng(body_seed);
  BodyLook look;
  const cv::Vec3b shirt(static_cast<uchar>(rng.uniform(30, 220)),
                        static_cast<uchar>(rng.uniform(30, 220)),
                        static_cast<uchar>(rng.uniform(30, 220)));
  look.shirt = {shirt, shirt * 0.55, 0.5, 8.0, 20.0, 2.0, 1.0, 0.7};
  const int trousers = rng.uniform(25, 90);
  look.trousers = {bgr(trousers + 25, trousers, trousers - 10),
                   bgr(trousers / 2 + 10, trousers / 2, trousers / 3),
                   0.4,
                   4.0,
                   6.0,
                   0.0,
                   0.0,
                   0.2};
  const int tone = rng.uniform(0, 3);
  const cv::Vec3b skins[] = {bgr(150, 180, 225), bgr(95, 135, 185), bgr(50, 80, 120)};
  look.skin = {skins[tone], skins[tone] * 0.7, 0.3, 10.0, 0.0, 0.0, 0.0, 0.1};
  // Cardboard with tape and printing: well textured, so trackers do see features on it.
  look.carried_box = {bgr(45, 95, 140), bgr(110, 170, 215), 0.6, 10.0, 25.0, 10.0, 40.0, 0.3};
  return look;
}

// View-independent lighting: a diffuse term from the face's world normal plus two ceiling
// lamps that fall off with distance. Static surfaces have it baked into their textures;
// moving boxes get it per face and frame (evaluated at the face centre).
constexpr float kLampA[3] = {2.3f, 3.0f, 2.6f};
constexpr float kLampB[3] = {4.9f, 3.0f, 2.6f};

float light_at(const Eigen::Vector3d& world_point, const Eigen::Vector3d& world_normal) {
  static constexpr double kSun[3] = {0.25197631533948484, 0.41996052556580804,
                                     0.83992105113161610};  // (0.3, 0.5, 1) normalised
  const double sun =
      world_normal.x() * kSun[0] + world_normal.y() * kSun[1] + world_normal.z() * kSun[2];
  const auto lamp = [&](const float* at) {
    const double dx = world_point.x() - at[0], dy = world_point.y() - at[1],
                 dz = world_point.z() - at[2];
    return 0.35 / (1.0 + (dx * dx + dy * dy + dz * dz) / 3.0);
  };
  return static_cast<float>(0.6 + 0.3 * std::max(0.0, sun) + lamp(kLampA) + lamp(kLampB));
}

// Outward normal of a face in box coordinates (inward for the room, seen from inside).
Eigen::Vector3d face_normal(int face, bool seen_from_inside) {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  normal[face / 2] = (face % 2 ? 1.0 : -1.0) * (seen_from_inside ? -1.0 : 1.0);
  return normal;
}

// Runs fn(row_begin, row_end) over chunks of rows on `threads` threads. Every pixel's result
// depends only on its own inputs, so the split never changes the output.
template <typename Fn>
void parallel_rows(int height, int threads, const Fn& fn) {
  std::atomic<int> next_chunk{0};
  const int chunks = (height + kRowsPerChunk - 1) / kRowsPerChunk;
  const auto worker = [&] {
    for (int chunk = next_chunk++; chunk < chunks; chunk = next_chunk++) {
      fn(chunk * kRowsPerChunk, std::min(height, (chunk + 1) * kRowsPerChunk));
    }
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool) thread.join();
}

// Kinect hand-held motion: scales of the ideal path (0.8 x rotation, 0.38 x translation, 2 x hand
// shake) chosen so that the median frame-to-frame rotation and translation rates match the Bonn
// crowd recording's ground truth (12.7 deg/s and 0.085 m/s over its 404 poses); the test pins the
// match.
synth::MotionProfile motion_profile(const SynthOptions& options) {
  if (options.sensor != SynthSensor::kKinect || !options.faults.handheld_motion) return {};
  return {0.8, 0.38, 2.0};
}

int resolve_threads(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace

SynthTrajectory parse_synth_trajectory(const std::string& name) {
  if (name == "handheld") return SynthTrajectory::kHandheld;
  if (name == "loop") return SynthTrajectory::kLoop;
  throw Error("synth: flag --trajectory expects 'handheld' or 'loop', got '" + name + "'");
}

std::string to_string(SynthTrajectory trajectory) {
  return trajectory == SynthTrajectory::kLoop ? "loop" : "handheld";
}

SynthSensor parse_synth_sensor(const std::string& name) {
  if (name == "ideal") return SynthSensor::kIdeal;
  if (name == "kinect") return SynthSensor::kKinect;
  throw Error("synth: flag --sensor expects 'ideal' or 'kinect', got '" + name + "'");
}

std::string to_string(SynthSensor sensor) {
  return sensor == SynthSensor::kKinect ? "kinect" : "ideal";
}

void SynthOptions::validate() const {
  if (frames < 1) throw Error("synth: flag --frames must be >= 1, got " + std::to_string(frames));
  if (bodies < 0 || bodies > kMaxBodies) {
    throw Error("synth: flag --bodies must be in [0, " + std::to_string(kMaxBodies) + "], got " +
                std::to_string(bodies));
  }
  if (carried_objects < 0) {
    throw Error("synth: flag --carried-objects must be >= 0, got " +
                std::to_string(carried_objects));
  }
  if (threads < 0)
    throw Error("synth: flag --threads must be >= 0, got " + std::to_string(threads));
  if (!(stand_seconds >= 0.0 && stand_seconds <= 3600.0)) {
    throw Error("synth: flag --stand-seconds must be in [0, 3600], got " +
                std::to_string(stand_seconds));
  }
  if (!(loop_turns > 0.0 && loop_turns <= 1000.0))
    throw Error("synth: flag --loop-turns must be in (0, 1000], got " + std::to_string(loop_turns));
  if (!(stereo_baseline >= 0.0 && stereo_baseline <= 2.0))
    throw Error("synth: flag --stereo must be a baseline in metres in (0, 2], got " +
                std::to_string(stereo_baseline));
  if (stereo_baseline > 0.0 && sensor == SynthSensor::kKinect)
    throw Error("synth: flag --stereo renders the ideal sensor only (not --sensor kinect)");
  if (layout != Layout::tum && stereo_baseline <= 0.0)
    throw Error("synth: flag --layout kitti|euroc needs --stereo BASELINE_M (stereo layouts)");
}

CameraConfig synthetic_camera_config() {
  CameraConfig config;
  config.name = "synthetic";
  config.pinhole = PinholeCamera{};
  config.pinhole.width = 640;
  config.pinhole.height = 480;
  config.pinhole.fx = 525.0;
  config.pinhole.fy = 525.0;
  config.pinhole.cx = 319.5;
  config.pinhole.cy = 239.5;
  config.pinhole.distortion = {};
  config.fps = kFps;
  config.depth_factor = 5000.0;
  config.depth_threshold = 4.0;
  // The rendered depth is registered and synchronised with colour, its noise is the Kinect v1
  // model (sensor.h): trust it as such (optimize/depth_noise_model.h).
  config.depth_noise = CameraConfig::DepthNoise::kinect_v1;
  return config;
}

SystemConfig synthetic_system_config() {
  SystemConfig config;
  config.camera = synthetic_camera_config();
  return config;
}

struct SyntheticScene::Impl {
  explicit Impl(const SynthOptions& opts);
  void render(size_t index, SynthFrame& frame, int threads) const;
  void render_kinect(size_t index, SynthFrame& frame, int threads) const;
  void render_right(size_t index, cv::Mat& bgr, int threads) const;
  // Every box posed at scene time t (seconds) as seen from T_world_camera.
  void prepare_boxes(double t, const Pose& T_world_camera, std::vector<FrameBox>& boxes) const;
  // Ray casts and shades rows [row_begin, row_end) into the (allocated) images.
  void draw_rows(const std::vector<FrameBox>& boxes, int row_begin, int row_end, cv::Mat& bgr,
                 cv::Mat& depth, cv::Mat& labels, cv::Mat& surface_ids,
                 cv::Mat& incidence_cos) const;
  bool kinect(bool synth::KinectFaults::*fault) const {
    return options.sensor == SynthSensor::kKinect && options.faults.*fault;
  }

  SynthOptions options;
  PinholeCamera camera;
  synth::RoomLayout room;
  synth::CameraPath camera_path;
  synth::DepthSensorModel sensor;
  synth::KinectDepthModel kinect_sensor;
  std::optional<synth::DistortionMaps> distortion;  // kinect distortion fault only
  Pose T_body_camera = Pose::Identity();            // kinect marker fault only
  std::vector<synth::MipTexture> textures;
  // Static boxes first (room, then furniture) so their surface ids do not depend on --bodies.
  std::vector<BoxSurface> static_boxes;
  std::vector<Pose> static_poses;
  std::vector<synth::WalkingBody> bodies;
  std::vector<std::vector<BoxSurface>> body_boxes;  // per body, in WalkingBody::parts() order
  std::vector<int> person_of_box;  // per box of prepare_boxes(): its body, -1 static or carried
  std::vector<float> column_xn, row_yn;  // normalised ray coordinates of pixel centres
  std::vector<float> ray_length;         // |(x_n, y_n, 1)| per pixel, row-major

 private:
  // `static_pose`: the pose of a box that never moves, whose lighting is baked into its
  // textures; nullptr for moving boxes (lit per frame).
  BoxSurface make_box(const Eigen::Vector3d& half, bool inside, uint8_t label,
                      const synth::TextureRecipe* recipe, float texels_per_metre, uint64_t seed,
                      const Pose* static_pose);
};

SyntheticScene::Impl::Impl(const SynthOptions& opts)
    : options(opts),
      camera(synthetic_camera_config().pinhole),
      camera_path(opts.trajectory == SynthTrajectory::kLoop, opts.seed,
                  static_cast<double>(std::max<size_t>(opts.frames, 2) - 1) / kFps, room,
                  opts.loop_turns, motion_profile(opts)),
      sensor(opts.seed),
      kinect_sensor(opts.seed, camera.fx) {
  options.validate();
  options.carried_objects = std::min(options.carried_objects, options.bodies);
  if (kinect(&synth::KinectFaults::distortion)) {
    distortion.emplace(camera.width, camera.height, camera.fx, camera.fy, camera.cx, camera.cy,
                       synth::kKinectDistortion);
  }
  if (kinect(&synth::KinectFaults::marker)) {
    // A marker body beside and above the lens, slightly tilted, as a rig is glued together.
    T_body_camera.linear() =
        Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.3, 0.8, 0.5).normalized()).toRotationMatrix();
    T_body_camera.translation() = Eigen::Vector3d(0.045, 0.065, -0.03);
  }

  // Static scene: every face gets its own recipe and texture.
  const uint64_t static_seed = synth::mix_hash(opts.seed, 0x57A71Cu);
  static_poses.push_back(Pose(Eigen::Translation3d(room.size / 2.0)));
  static_boxes.push_back(make_box(room.size / 2.0, true, kSynthLabelStatic, nullptr,
                                  kStaticTexelsPerMetre, synth::mix_hash(static_seed, 0),
                                  &static_poses.back()));
  for (size_t i = 0; i < furniture_layout().size(); ++i) {
    const Furniture& item = furniture_layout()[i];
    Pose pose = Pose::Identity();
    pose.linear() = Eigen::AngleAxisd(item.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pose.translation() = item.centre;
    static_poses.push_back(pose);
    static_boxes.push_back(make_box(item.half, false, kSynthLabelStatic, nullptr,
                                    kStaticTexelsPerMetre, synth::mix_hash(static_seed, i + 1),
                                    &static_poses.back()));
  }

  for (int b = 0; b < options.bodies; ++b) {
    // Hand-held: people walk laps in front of where the camera mostly looks; loop: round the
    // whole room, since the loop camera looks in every direction.
    const std::optional<double> sector = opts.trajectory == SynthTrajectory::kHandheld
                                             ? std::optional<double>(camera_path.mean_heading())
                                             : std::nullopt;
    bodies.emplace_back(b, opts.seed, b < options.carried_objects, room, sector,
                        options.stand_seconds);
    const uint64_t body_seed = synth::mix_hash(opts.seed, 0xB0D7u, static_cast<uint64_t>(b));
    const BodyLook look = body_look(body_seed);
    std::vector<synth::BodyPartPose> rest;
    bodies.back().pose_parts(0.0, rest);
    std::vector<BoxSurface> boxes;
    for (size_t p = 0; p < bodies.back().parts().size(); ++p) {
      const synth::BodyPart part = bodies.back().parts()[p];
      const synth::TextureRecipe* recipe = &look.shirt;
      uint8_t label = kSynthLabelPerson;
      if (part == synth::BodyPart::kHead) recipe = &look.skin;
      if (part == synth::BodyPart::kLeftLeg || part == synth::BodyPart::kRightLeg) {
        recipe = &look.trousers;
      }
      if (part == synth::BodyPart::kCarriedBox) {
        recipe = &look.carried_box;
        label = kSynthLabelCarried;
      }
      boxes.push_back(make_box(rest[p].half_extents, false, label, recipe, kBodyTexelsPerMetre,
                               synth::mix_hash(body_seed, p), nullptr));
    }
    body_boxes.push_back(std::move(boxes));
  }
  person_of_box.assign(static_boxes.size(), -1);
  for (size_t b = 0; b < body_boxes.size(); ++b) {
    for (const BoxSurface& box : body_boxes[b])
      person_of_box.push_back(box.label == kSynthLabelPerson ? static_cast<int>(b) : -1);
  }

  for (int x = 0; x < camera.width; ++x) {
    column_xn.push_back(static_cast<float>((x - camera.cx) / camera.fx));
  }
  for (int y = 0; y < camera.height; ++y) {
    row_yn.push_back(static_cast<float>((y - camera.cy) / camera.fy));
  }
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      ray_length.push_back(
          std::sqrt(column_xn[static_cast<size_t>(x)] * column_xn[static_cast<size_t>(x)] +
                    row_yn[static_cast<size_t>(y)] * row_yn[static_cast<size_t>(y)] + 1.0f));
    }
  }
}

BoxSurface SyntheticScene::Impl::make_box(const Eigen::Vector3d& half, bool inside, uint8_t label,
                                          const synth::TextureRecipe* recipe,
                                          float texels_per_metre, uint64_t seed,
                                          const Pose* static_pose) {
  BoxSurface box;
  box.half_extents = half;
  box.seen_from_inside = inside;
  box.label = label;
  for (int face = 0; face < 6; ++face) {
    const int axis = face / 2;
    const double width_m = 2.0 * half[(axis + 1) % 3];
    const double height_m = 2.0 * half[(axis + 2) % 3];
    const uint64_t face_seed = synth::mix_hash(seed, static_cast<uint64_t>(face));
    const synth::TextureRecipe face_recipe =
        recipe ? *recipe : synth::static_surface_recipe(face_seed);
    cv::Mat image =
        synth::make_texture_image(face_recipe, width_m, height_m, texels_per_metre, face_seed);
    if (static_pose) {
      // Lighting varies slowly: evaluate it every kLightStep texels and interpolate, which
      // keeps scene construction (paid by every test that renders frames) short.
      constexpr int kLightStep = 8;
      const Eigen::Vector3d normal = static_pose->linear() * face_normal(face, inside);
      const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
      const int grid_w = image.cols / kLightStep + 2, grid_h = image.rows / kLightStep + 2;
      cv::Mat coarse(grid_h, grid_w, CV_32F);
      Eigen::Vector3d local;
      local[axis] = (face % 2 ? 1.0 : -1.0) * half[axis];
      for (int j = 0; j < grid_h; ++j) {
        local[v_axis] = (j * kLightStep + 0.5) / texels_per_metre - half[v_axis];
        for (int i = 0; i < grid_w; ++i) {
          local[u_axis] = (i * kLightStep + 0.5) / texels_per_metre - half[u_axis];
          coarse.at<float>(j, i) = light_at(*static_pose * local, normal);
        }
      }
      for (int j = 0; j < image.rows; ++j) {
        auto* row = image.ptr<cv::Vec3b>(j);
        const int j0 = j / kLightStep;
        const float fj = static_cast<float>(j % kLightStep) / kLightStep;
        const float* top = coarse.ptr<float>(j0);
        const float* bottom = coarse.ptr<float>(j0 + 1);
        for (int i = 0; i < image.cols; ++i) {
          const int i0 = i / kLightStep;
          const float fi = static_cast<float>(i % kLightStep) / kLightStep;
          const float upper = top[i0] + (top[i0 + 1] - top[i0]) * fi;
          const float lower = bottom[i0] + (bottom[i0 + 1] - bottom[i0]) * fi;
          const float shade = upper + (lower - upper) * fj;
          for (int c = 0; c < 3; ++c) row[i][c] = cv::saturate_cast<uchar>(row[i][c] * shade);
        }
      }
    }
    box.face_textures[static_cast<size_t>(face)] = static_cast<int>(textures.size());
    textures.emplace_back(std::move(image), texels_per_metre);
  }
  return box;
}

void SyntheticScene::Impl::prepare_boxes(double t, const Pose& T_world_camera,
                                         std::vector<FrameBox>& boxes) const {
  const Pose T_camera_world = T_world_camera.inverse();
  // Gather this frame's boxes with their poses.
  std::vector<std::pair<const BoxSurface*, Pose>> posed;
  for (size_t i = 0; i < static_boxes.size(); ++i)
    posed.emplace_back(&static_boxes[i], static_poses[i]);
  std::vector<synth::BodyPartPose> parts;
  for (size_t b = 0; b < bodies.size(); ++b) {
    bodies[b].pose_parts(t, parts);
    for (size_t p = 0; p < parts.size(); ++p)
      posed.emplace_back(&body_boxes[b][p], parts[p].T_world_part);
  }

  boxes.resize(posed.size());
  for (size_t i = 0; i < posed.size(); ++i) {
    const auto& [surface, T_world_box] = posed[i];
    FrameBox& box = boxes[i];
    box.surface = surface;
    const Pose T_camera_box = T_camera_world * T_world_box;
    const Pose T_box_camera = T_camera_box.inverse();
    box.R_box_camera = T_box_camera.linear().cast<float>();
    box.camera_in_box = T_box_camera.translation().cast<float>();
    box.half = surface->half_extents.cast<float>();
    box.first_surface_id = static_cast<uint16_t>(1 + i * 6);
    const bool is_static = i < static_boxes.size();
    for (int face = 0; face < 6; ++face) {
      const Eigen::Vector3d normal = face_normal(face, surface->seen_from_inside);
      const Eigen::Vector3d centre =
          normal.cwiseAbs().cwiseProduct(surface->half_extents).cwiseProduct(normal);
      box.face_light[static_cast<size_t>(face)] =
          is_static ? 1.0f : light_at(T_world_box * centre, T_world_box.linear() * normal);
    }
    // Screen rectangle of the box clipped to the near plane (corners in front of it plus
    // points where edges cross it); boxes wholly behind the camera get an empty rectangle.
    box.x0 = 0, box.y0 = 0, box.x1 = camera.width, box.y1 = camera.height;
    if (!surface->seen_from_inside) {
      constexpr double kClipZ = 0.02;
      std::array<Eigen::Vector3d, 8> corners;
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d local((corner & 1 ? 1 : -1) * surface->half_extents.x(),
                                    (corner & 2 ? 1 : -1) * surface->half_extents.y(),
                                    (corner & 4 ? 1 : -1) * surface->half_extents.z());
        corners[static_cast<size_t>(corner)] = T_camera_box * local;
      }
      double u_min = 1e9, u_max = -1e9, v_min = 1e9, v_max = -1e9;
      const auto extend = [&](const Eigen::Vector3d& p) {
        const Eigen::Vector2d uv = camera.project(p);
        u_min = std::min(u_min, uv.x()), u_max = std::max(u_max, uv.x());
        v_min = std::min(v_min, uv.y()), v_max = std::max(v_max, uv.y());
      };
      for (int a = 0; a < 8; ++a) {
        const Eigen::Vector3d& pa = corners[static_cast<size_t>(a)];
        if (pa.z() >= kClipZ) extend(pa);
        for (int bit = 1; bit < 8; bit <<= 1) {  // the 3 edges from corner a to a larger index
          if (a & bit) continue;
          const Eigen::Vector3d& pb = corners[static_cast<size_t>(a | bit)];
          if ((pa.z() < kClipZ) != (pb.z() < kClipZ)) {
            extend(pa + (pb - pa) * ((kClipZ - pa.z()) / (pb.z() - pa.z())));
          }
        }
      }
      if (u_min > u_max) {
        box.x1 = box.x0;  // nothing in front of the camera
      } else {
        box.x0 = static_cast<int>(std::clamp(std::floor(u_min) - 1.0, 0.0, double(camera.width)));
        box.x1 = static_cast<int>(std::clamp(std::ceil(u_max) + 2.0, 0.0, double(camera.width)));
        box.y0 = static_cast<int>(std::clamp(std::floor(v_min) - 1.0, 0.0, double(camera.height)));
        box.y1 = static_cast<int>(std::clamp(std::ceil(v_max) + 2.0, 0.0, double(camera.height)));
      }
    }
  }
}

void SyntheticScene::Impl::draw_rows(const std::vector<FrameBox>& boxes, int row_begin, int row_end,
                                     cv::Mat& bgr, cv::Mat& depth, cv::Mat& labels,
                                     cv::Mat& surface_ids, cv::Mat& incidence_cos) const {
  const int width = camera.width;
  const float focal = static_cast<float>(camera.fx);
  // Pass 1: nearest hit per pixel (z-buffer over exact ray-box intersections).
  for (int y = row_begin; y < row_end; ++y) {
    std::fill_n(depth.ptr<float>(y), width, std::numeric_limits<float>::infinity());
    std::fill_n(surface_ids.ptr<uint16_t>(y), width, uint16_t{0});
  }
  for (const FrameBox& box : boxes) {
    const int y_begin = std::max(row_begin, box.y0), y_end = std::min(row_end, box.y1);
    const Eigen::Vector3f& o = box.camera_in_box;
    const Eigen::Vector3f& h = box.half;
    const bool inside = box.surface->seen_from_inside;
    for (int y = y_begin; y < y_end; ++y) {
      float* depth_row = depth.ptr<float>(y);
      uint16_t* id_row = surface_ids.ptr<uint16_t>(y);
      const Eigen::Vector3f row_part =
          box.R_box_camera.col(1) * row_yn[y] + box.R_box_camera.col(2);
      for (int x = box.x0; x < box.x1; ++x) {
        const Eigen::Vector3f d = box.R_box_camera.col(0) * column_xn[x] + row_part;
        float t_enter = kNearPlane_m, t_exit = depth_row[x];
        int enter_axis = -1, exit_axis = -1;
        bool hit = true;
        for (int a = 0; a < 3; ++a) {
          const float inv = 1.0f / d[a];
          float t0 = (-h[a] - o[a]) * inv, t1 = (h[a] - o[a]) * inv;
          if (t0 > t1) std::swap(t0, t1);
          if (t0 > t_enter) t_enter = t0, enter_axis = a;
          if (t1 < t_exit || (inside && exit_axis < 0)) t_exit = t1, exit_axis = a;
          if (!inside && t_enter > t_exit) {
            hit = false;
            break;
          }
        }
        if (inside) {
          // Seen from within: the visible face is where the ray leaves the box.
          if (exit_axis < 0 || !(t_exit < depth_row[x])) continue;
          depth_row[x] = t_exit;
          id_row[x] = static_cast<uint16_t>(box.first_surface_id + 2 * exit_axis +
                                            (d[exit_axis] > 0 ? 1 : 0));
        } else if (hit && enter_axis >= 0) {
          depth_row[x] = t_enter;
          id_row[x] = static_cast<uint16_t>(box.first_surface_id + 2 * enter_axis +
                                            (d[enter_axis] > 0 ? 0 : 1));
        }
      }
    }
  }

  // Pass 2: shade the visible surface of every pixel from its own surface coordinates.
  for (int y = row_begin; y < row_end; ++y) {
    float* depth_row = depth.ptr<float>(y);
    const uint16_t* id_row = surface_ids.ptr<uint16_t>(y);
    auto* colour_row = bgr.ptr<cv::Vec3b>(y);
    uint8_t* label_row = labels.ptr<uint8_t>(y);
    float* cos_row = incidence_cos.ptr<float>(y);
    for (int x = 0; x < width; ++x) {
      if (id_row[x] == 0) {  // cannot happen inside the closed room; kept safe anyway
        depth_row[x] = 0.0f;
        colour_row[x] = cv::Vec3b(0, 0, 0);
        label_row[x] = kSynthLabelStatic;
        cos_row[x] = 0.0f;
        continue;
      }
      const int box_index = (id_row[x] - 1) / 6, face = (id_row[x] - 1) % 6, axis = face / 2;
      const FrameBox& box = boxes[static_cast<size_t>(box_index)];
      const float z = depth_row[x];
      const float xn = column_xn[x], yn = row_yn[y];
      const Eigen::Vector3f d = box.R_box_camera * Eigen::Vector3f(xn, yn, 1.0f);
      const Eigen::Vector3f p = box.camera_in_box + z * d;
      const float s = p[(axis + 1) % 3] + box.half[(axis + 1) % 3];
      const float r = p[(axis + 2) % 3] + box.half[(axis + 2) % 3];
      // Mip level from the pixel's footprint on the surface: range / focal, stretched by
      // 1 / sqrt(cos) (a compromise between blur and aliasing on oblique surfaces).
      const float length = ray_length[static_cast<size_t>(y * width + x)];
      const float cosine = std::abs(d[axis]) / length;
      const synth::MipTexture& texture =
          textures[static_cast<size_t>(box.surface->face_textures[static_cast<size_t>(face)])];
      const float lod =
          synth::MipTexture::approx_log2(z * length * texture.texels_per_metre() / focal) -
          0.5f * synth::MipTexture::approx_log2(std::max(cosine, 0.05f));
      const cv::Vec3f albedo = texture.sample_lod(s, r, lod);
      const float shade = box.face_light[static_cast<size_t>(face)];
      colour_row[x] = cv::Vec3b(cv::saturate_cast<uchar>(albedo[0] * shade),
                                cv::saturate_cast<uchar>(albedo[1] * shade),
                                cv::saturate_cast<uchar>(albedo[2] * shade));
      label_row[x] = box.surface->label;
      cos_row[x] = cosine;
    }
  }
}

void SyntheticScene::Impl::render(size_t index, SynthFrame& frame, int threads) const {
  if (options.sensor == SynthSensor::kKinect) {
    render_kinect(index, frame, threads);
    return;
  }
  const double t = static_cast<double>(index) / kFps;
  frame.index = index;
  frame.timestamp = kFirstTimestamp + t;
  frame.T_world_camera = camera_path.T_world_camera(t);
  std::vector<FrameBox> boxes;
  prepare_boxes(t, frame.T_world_camera, boxes);

  const int width = camera.width, height = camera.height;
  frame.bgr.create(height, width, CV_8UC3);
  frame.depth.create(height, width, CV_32F);
  frame.labels.create(height, width, CV_8U);
  frame.surface_ids.create(height, width, CV_16U);
  cv::Mat incidence_cos(height, width, CV_32F);
  parallel_rows(height, threads, [&](int row_begin, int row_end) {
    draw_rows(boxes, row_begin, row_end, frame.bgr, frame.depth, frame.labels, frame.surface_ids,
              incidence_cos);
  });

  if (options.depth_noise) {
    sensor.apply(frame.depth, incidence_cos, index, frame.depth_sensor);
  } else {
    frame.depth_sensor.create(height, width, CV_32F);
    for (int y = 0; y < height; ++y) {
      const float* exact = frame.depth.ptr<float>(y);
      float* out = frame.depth_sensor.ptr<float>(y);
      for (int x = 0; x < width; ++x) out[x] = synth::quantise_depth(exact[x], 5000.0);
    }
  }
}

void SyntheticScene::Impl::render_right(size_t index, cv::Mat& bgr, int threads) const {
  const double t = static_cast<double>(index) / kFps;
  const Pose T_world_right =
      camera_path.T_world_camera(t) * Eigen::Translation3d(options.stereo_baseline, 0.0, 0.0);
  std::vector<FrameBox> boxes;
  prepare_boxes(t, T_world_right, boxes);
  const int width = camera.width, height = camera.height;
  bgr.create(height, width, CV_8UC3);
  cv::Mat depth(height, width, CV_32F), labels(height, width, CV_8U);
  cv::Mat surface_ids(height, width, CV_16U), incidence_cos(height, width, CV_32F);
  parallel_rows(height, threads, [&](int row_begin, int row_end) {
    draw_rows(boxes, row_begin, row_end, bgr, depth, labels, surface_ids, incidence_cos);
  });
}

void SyntheticScene::Impl::render_kinect(size_t index, SynthFrame& frame, int threads) const {
  const synth::KinectFaults& faults = options.faults;
  const double t = static_cast<double>(index) / kFps;
  frame.index = index;
  frame.timestamp = kFirstTimestamp + t;
  frame.T_world_camera = camera_path.T_world_camera(t);
  const int width = camera.width, height = camera.height;
  frame.bgr.create(height, width, CV_8UC3);
  frame.depth.create(height, width, CV_32F);
  frame.labels.create(height, width, CV_8U);
  frame.surface_ids.create(height, width, CV_16U);
  cv::Mat incidence_cos(height, width, CV_32F);

  // Colour (with its labels): a rolling shutter reads each band of kRowsPerChunk rows at its
  // own instant, the middle row at the frame's timestamp. A band is 0.5 ms: under 0.1 px of
  // motion at hand-held speeds, so the staircase is invisible.
  if (faults.rolling_shutter) {
    parallel_rows(height, threads, [&](int row_begin, int row_end) {
      std::vector<FrameBox> band;
      const double row_time =
          t + synth::kKinectReadout_s * (0.5 * (row_begin + row_end) / height - 0.5);
      prepare_boxes(row_time, camera_path.T_world_camera(row_time), band);
      draw_rows(band, row_begin, row_end, frame.bgr, frame.depth, frame.labels, frame.surface_ids,
                incidence_cos);
    });
  } else {
    std::vector<FrameBox> boxes;
    prepare_boxes(t, frame.T_world_camera, boxes);
    parallel_rows(height, threads, [&](int row_begin, int row_end) {
      draw_rows(boxes, row_begin, row_end, frame.bgr, frame.depth, frame.labels, frame.surface_ids,
                incidence_cos);
    });
  }

  // Depth: a global-shutter IR camera at t + offset. Its own render only when that differs
  // from what the colour pass saw; the colour of the depth pass says which surfaces are dark.
  const double depth_offset =
      faults.sync_offset ? synth::kinect_sync_offset(options.seed, index) : 0.0;
  cv::Mat depth_bgr = frame.bgr;
  if (faults.rolling_shutter || depth_offset != 0.0) {
    const double depth_time = t + depth_offset;
    std::vector<FrameBox> boxes;
    prepare_boxes(depth_time, camera_path.T_world_camera(depth_time), boxes);
    depth_bgr = cv::Mat(height, width, CV_8UC3);
    cv::Mat depth_labels(height, width, CV_8U), depth_ids(height, width, CV_16U);
    parallel_rows(height, threads, [&](int row_begin, int row_end) {
      draw_rows(boxes, row_begin, row_end, depth_bgr, frame.depth, depth_labels, depth_ids,
                incidence_cos);
    });
  }
  synth::KinectDepthModel::Switches switches;
  switches.noise = switches.quantisation = faults.depth_noise;
  switches.holes = faults.holes;
  kinect_sensor.apply(frame.depth, incidence_cos, depth_bgr, index, switches, frame.depth_sensor);
  for (int y = 0; y < height; ++y) {  // onto the PNG grid: depth_sensor is what the file holds
    float* row = frame.depth_sensor.ptr<float>(y);
    for (int x = 0; x < width; ++x) row[x] = synth::quantise_depth(row[x], 5000.0);
  }

  if (faults.motion_blur) {
    // Angular velocity in the camera frame from the path around t (central difference).
    constexpr double kStep_s = 0.002;
    const Eigen::Matrix3d R0 = camera_path.T_world_camera(t - kStep_s).linear();
    const Eigen::Matrix3d R1 = camera_path.T_world_camera(t + kStep_s).linear();
    const Eigen::AngleAxisd turn(R0.transpose() * R1);
    synth::kinect_motion_blur(frame.bgr, turn.axis() * (turn.angle() / (2.0 * kStep_s)), camera.fx,
                              synth::kKinectExposure_s);
  }
  if (faults.exposure) {
    frame.bgr.convertTo(frame.bgr, -1, synth::kinect_exposure_gain(options.seed, t));
  }
  if (distortion) {
    // Registered depth lives in the distorted colour image (map/frame.cpp reads depth before
    // undistorting keypoints), so every image goes through the same lens.
    const auto bend = [&](cv::Mat& image, int interpolation) {
      cv::Mat bent;
      cv::remap(image, bent, distortion->map_x, distortion->map_y, interpolation,
                cv::BORDER_REPLICATE);
      image = bent;
    };
    bend(frame.bgr, cv::INTER_LINEAR);
    bend(frame.labels, cv::INTER_NEAREST);
    bend(frame.surface_ids, cv::INTER_NEAREST);
    bend(frame.depth, cv::INTER_NEAREST);
    bend(frame.depth_sensor, cv::INTER_NEAREST);
  }
}

SyntheticScene::SyntheticScene(const SynthOptions& options)
    : impl_(std::make_unique<const Impl>(options)) {}
SyntheticScene::~SyntheticScene() = default;
SyntheticScene::SyntheticScene(SyntheticScene&&) noexcept = default;
SyntheticScene& SyntheticScene::operator=(SyntheticScene&&) noexcept = default;

SynthFrame SyntheticScene::render(size_t index) const {
  SynthFrame frame;
  render(index, frame, impl_->options.threads);
  return frame;
}

void SyntheticScene::render(size_t index, SynthFrame& frame, int threads) const {
  if (index >= impl_->options.frames) {
    throw Error("synth: frame index " + std::to_string(index) + " is past the sequence end (" +
                std::to_string(impl_->options.frames) + " frames)");
  }
  impl_->render(index, frame, resolve_threads(threads));
}

void SyntheticScene::render_right(size_t index, cv::Mat& bgr, int threads) const {
  if (!(impl_->options.stereo_baseline > 0.0)) {
    throw Error("synth: render_right needs a stereo baseline (--stereo)");
  }
  if (index >= impl_->options.frames) {
    throw Error("synth: frame index " + std::to_string(index) + " is past the sequence end (" +
                std::to_string(impl_->options.frames) + " frames)");
  }
  impl_->render_right(index, bgr, resolve_threads(threads));
}

const PinholeCamera& SyntheticScene::camera() const { return impl_->camera; }
const SynthOptions& SyntheticScene::options() const { return impl_->options; }
size_t SyntheticScene::frame_count() const { return impl_->options.frames; }

Timestamp SyntheticScene::timestamp(size_t index) const {
  return kFirstTimestamp + static_cast<double>(index) / kFps;
}

Pose SyntheticScene::camera_pose(size_t index) const {
  return impl_->camera_path.T_world_camera(static_cast<double>(index) / kFps);
}

Pose SyntheticScene::camera_pose_at(double seconds) const {
  return impl_->camera_path.T_world_camera(seconds);
}

double SyntheticScene::depth_time_offset(size_t index) const {
  return impl_->kinect(&synth::KinectFaults::sync_offset)
             ? synth::kinect_sync_offset(impl_->options.seed, index)
             : 0.0;
}

Pose SyntheticScene::T_body_camera() const { return impl_->T_body_camera; }

int SyntheticScene::body_count() const { return static_cast<int>(impl_->bodies.size()); }

Eigen::Vector3d SyntheticScene::body_centre_at(int body, double seconds) const {
  std::vector<synth::BodyPartPose> parts;
  impl_->bodies.at(static_cast<size_t>(body)).pose_parts(seconds, parts);
  return parts.front().T_world_part.translation();  // the torso comes first
}

int SyntheticScene::person_of_surface(uint16_t surface_id) const {
  if (surface_id == 0) return -1;
  const size_t box = (surface_id - 1u) / 6u;
  return box < impl_->person_of_box.size() ? impl_->person_of_box[box] : -1;
}

Pose SyntheticScene::ground_truth_pose(size_t index) const {
  return camera_pose(index) * impl_->T_body_camera.inverse();
}

SystemConfig SyntheticScene::rgbd_system_config() const {
  SystemConfig config = synthetic_system_config();
  if (impl_->distortion) config.camera.pinhole.distortion = synth::kKinectDistortion;
  // The sensor's readout, as a user would take it from the camera's data sheet.
  if (impl_->kinect(&synth::KinectFaults::rolling_shutter))
    config.camera.rolling_shutter_readout_s = synth::kKinectReadout_s;
  return config;
}

SystemConfig SyntheticScene::system_config() const {
  SystemConfig config = rgbd_system_config();
  const double baseline = impl_->options.stereo_baseline;
  if (baseline > 0.0) {
    config.camera.name = "synthetic_stereo";
    config.camera.type = SensorType::stereo;
    config.camera.baseline = baseline;
    config.camera.depth_threshold = 40.0 * baseline;
  }
  return config;
}

std::vector<SynthBox> SyntheticScene::static_boxes() const {
  std::vector<SynthBox> boxes;
  for (size_t i = 0; i < impl_->static_boxes.size(); ++i)
    boxes.push_back({impl_->static_poses[i], impl_->static_boxes[i].half_extents});
  return boxes;
}

std::vector<SynthBox> SyntheticScene::body_boxes_at(double seconds) const {
  std::vector<SynthBox> boxes;
  std::vector<synth::BodyPartPose> parts;
  for (const synth::WalkingBody& body : impl_->bodies) {
    body.pose_parts(seconds, parts);
    for (const synth::BodyPartPose& part : parts)
      boxes.push_back({part.T_world_part, part.half_extents});
  }
  return boxes;
}

Trajectory SyntheticScene::ground_truth() const {
  Trajectory trajectory;
  for (size_t i = 0; i < frame_count(); ++i) trajectory.push_back({timestamp(i), camera_pose(i)});
  return trajectory;
}

}  // namespace pspslam
