#include "pspslam/synth/sequence_writer.h"

#include <Eigen/Geometry>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <fstream>
#include <functional>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>
#include <vector>

#include "pspslam/config/config.h"
#include "pspslam/core/error.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/synth/people_truth.h"

namespace pspslam {
namespace {

namespace fs = std::filesystem;

void write_png(const fs::path& file, const cv::Mat& image) {
  // Fastest zlib level with run-length matching: faster than the default strategy and the files
  // come out slightly smaller (noisy depth and textures have few long matches). PNG encoding is
  // most of the cost of writing a sequence.
  static const std::vector<int> kParams = {cv::IMWRITE_PNG_COMPRESSION, 1, cv::IMWRITE_PNG_STRATEGY,
                                           cv::IMWRITE_PNG_STRATEGY_RLE};
  bool ok = false;
  try {
    ok = cv::imwrite(file.string(), image, kParams);
  } catch (const cv::Exception& e) {
    throw Error("synth: cannot write " + file.string() + ": " + e.what());
  }
  if (!ok) throw Error("synth: cannot write " + file.string());
}

std::ofstream open_text(const fs::path& file) {
  std::ofstream out(file);
  if (!out) throw Error("synth: cannot open " + file.string() + " for writing");
  return out;
}

void close_text(std::ofstream& out, const fs::path& file) {
  out.close();
  if (!out) throw Error("synth: failed writing " + file.string());
}

// " --sensor kinect --no-fault ..." for a kinect sequence; "" for the ideal one, whose files
// keep the bytes they had before the kinect sensor existed.
std::string kinect_flags(const SynthOptions& options) {
  if (options.sensor != SynthSensor::kKinect) return "";
  std::string flags = " --sensor kinect";
  for (const std::string& name : synth::KinectFaults::names()) {
    if (!options.faults.is_on(name)) flags += " --no-fault " + name;
  }
  return flags;
}

std::string stereo_flags(const SynthOptions& options) {
  if (!(options.stereo_baseline > 0.0)) return "";
  char text[64];
  std::snprintf(text, sizeof(text), " --stereo %g", options.stereo_baseline);
  const char* layout = options.layout == SynthOptions::Layout::kitti   ? " --layout kitti"
                       : options.layout == SynthOptions::Layout::euroc ? " --layout euroc"
                                                                       : "";
  return std::string(text) + layout;
}

std::string describe(const SynthOptions& options) {
  return "pspslam synth --frames " + std::to_string(options.frames) + " --bodies " +
         std::to_string(options.bodies) + " --seed " + std::to_string(options.seed) +
         " --trajectory " + to_string(options.trajectory) + " --depth-noise " +
         (options.depth_noise ? "on" : "off") + " --carried-objects " +
         std::to_string(options.carried_objects) + kinect_flags(options) + stereo_flags(options);
}

// The stamp of frame i's depth image: its capture instant, as a Kinect driver stamps each stream
// (the Bonn recordings' depth stamps sit -17..+17 ms from their colour stamps, and the colour and
// depth edges of bonn_crowd_dev shift with that difference times the image motion:
// tools/calibration/depth_sync_check.py). Equal to the colour stamp unless kinect sync-offset.
Timestamp depth_timestamp(const SyntheticScene& scene, size_t i) {
  return scene.timestamp(i) + scene.depth_time_offset(i);
}

// `stamp_of(i)`: the timestamp listed (and naming the file) for frame i.
void write_frame_list(const fs::path& dir, const std::string& list_name, const std::string& folder,
                      const std::string& what, const SyntheticScene& scene,
                      const std::function<Timestamp(size_t)>& stamp_of) {
  const fs::path file = dir / list_name;
  std::ofstream out = open_text(file);
  out << "# " << what << "\n# file: '" << describe(scene.options()) << "'\n# timestamp filename\n";
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    const std::string ts = format_timestamp(stamp_of(i));
    out << ts << " " << folder << "/" << ts << ".png\n";
  }
  close_text(out, file);
}

void write_ground_truth(const fs::path& dir, const SyntheticScene& scene) {
  const fs::path file = dir / "groundtruth.txt";
  std::ofstream out = open_text(file);
  const bool marker = !scene.T_body_camera().isApprox(Pose::Identity(), 0.0);
  out << (marker ? "# ground truth trajectory (motion-capture marker body-to-world, exact; "
                   "body_to_camera.txt moves it onto the camera)\n# file: '"
                 : "# ground truth trajectory (camera-to-world, exact)\n# file: '")
      << describe(scene.options()) << "'\n# timestamp tx ty tz qx qy qz qw\n";
  char line[256];
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    const Pose pose = scene.ground_truth_pose(i);
    Eigen::Quaterniond q(pose.linear());
    if (q.w() < 0) q.coeffs() = -q.coeffs();  // one canonical sign: byte-identical files
    const Eigen::Vector3d t = pose.translation();
    std::snprintf(line, sizeof(line), "%s %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n",
                  format_timestamp(scene.timestamp(i)).c_str(), t.x(), t.y(), t.z(), q.x(), q.y(),
                  q.z(), q.w());
    out << line;
  }
  close_text(out, file);
}

// T_body_camera as `pspslam eval --gt-body-to-camera` reads it (tx ty tz qx qy qz qw).
void write_body_to_camera(const fs::path& dir, const SyntheticScene& scene) {
  const fs::path file = dir / "body_to_camera.txt";
  std::ofstream out = open_text(file);
  const Pose T = scene.T_body_camera();
  Eigen::Quaterniond q(T.linear());
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  char line[256];
  std::snprintf(line, sizeof(line), "%.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", T.translation().x(),
                T.translation().y(), T.translation().z(), q.x(), q.y(), q.z(), q.w());
  out << "# T_body_camera: camera points into the marker body of groundtruth.txt\n"
      << "# use: pspslam eval --gt groundtruth.txt --gt-body-to-camera body_to_camera.txt\n"
      << "# tx ty tz qx qy qz qw\n"
      << line;
  close_text(out, file);
}

void write_info(const fs::path& dir, const SyntheticScene& scene) {
  const SynthOptions& o = scene.options();
  const fs::path file = dir / "info.yaml";
  std::ofstream out = open_text(file);
  out << "# Synthetic dynamic RGB-D sequence written by `" << describe(o) << "`\n"
      << "generator: pspslam synth\n"
      << "seed: " << o.seed << "\n"
      << "frames: " << o.frames << "\n"
      << "bodies: " << o.bodies << "\n"
      << "carried_objects: " << o.carried_objects << "\n"
      << "trajectory: " << to_string(o.trajectory) << "\n"
      << "depth_noise: " << (o.depth_noise ? "on" : "off") << "\n";
  if (o.sensor == SynthSensor::kKinect) {
    out << "sensor: kinect\n"
        << "faults: " << o.faults.describe() << "\n";
  }
  out << "labels:  # mask/*.png values; label != 0 is the ground-truth dynamic mask\n"
      << "  static: " << int{kSynthLabelStatic} << "\n"
      << "  person: " << int{kSynthLabelPerson} << "\n"
      << "  carried_object: " << int{kSynthLabelCarried} << "\n";
  close_text(out, file);
}

void write_readme(const fs::path& dir, const SyntheticScene& scene) {
  const fs::path file = dir / "README.txt";
  std::ofstream out = open_text(file);
  out << "Synthetic dynamic RGB-D sequence (pspslam synth)\n"
      << "Command: " << describe(scene.options()) << "\n\n"
      << "A closed 7 x 6 x 2.8 m textured room with furniture along the walls, seen by a\n"
      << "hand-held 640x480 RGB-D camera at 30 Hz (fx = fy = 525, cx = 319.5, cy = 239.5, "
      << (scene.system_config().camera.pinhole.has_distortion() ? "distortion in config.yaml"
                                                                : "no\ndistortion")
      << "), while people walk around; one may carry a box.\n\n"
      << "rgb/<ts>.png     colour (8-bit BGR)\n"
      << "depth/<ts>.png   depth, 16-bit, 5000 units per metre, 0 = no reading\n"
      << "mask/<ts>.png    ground-truth labels: 0 static, 15 person, 100 carried object;\n"
      << "                 label != 0 is the ground-truth dynamic mask\n"
      << "rgb.txt, depth.txt, mask.txt   TUM lists: timestamp path\n"
      << "groundtruth.txt  timestamp tx ty tz qx qy qz qw, camera-to-world, exact\n"
      << "config.yaml      camera config for 'pspslam run --sequence <this folder>'\n"
      << "info.yaml        generator parameters\n"
      << "people.txt       every walking person at every frame: timestamp id, torso centre and\n"
      << "                 velocity (world), pixels showing her (pspslam run scores its tracks)\n";
  if (scene.options().sensor == SynthSensor::kKinect) {
    out << "\nSensor: kinect, faults " << scene.options().faults.describe() << ":\n"
        << "depth noise 1.425e-3 z^2 m quantised to 1/8 px of disparity, holes (projector\n"
        << "shadow, dark and grazing surfaces), depth captured up to +-16 ms off colour (its\n"
        << "stamp in depth.txt and its file name are that instant, as a Kinect driver's), a 30 ms\n"
        << "rolling shutter, motion blur, exposure changes, lens distortion (config.yaml), the\n"
        << "Bonn clip's hand-held speeds, and ground truth of a marker body:\n"
        << "body_to_camera.txt  T_body_camera for 'pspslam eval --gt-body-to-camera'\n";
  }
  close_text(out, file);
}

// KITTI odometry files: times.txt, calib.txt (P0 left, P1 right at the baseline; P2, P3 copies
// of them since the synthetic rig has no colour cameras of its own), poses.txt (3x4 row-major
// camera-to-world per frame).
void write_kitti_files(const fs::path& dir, const SyntheticScene& scene) {
  {
    const fs::path file = dir / "times.txt";
    std::ofstream out = open_text(file);
    // The synthetic timestamps as they are (KITTI's start at 0): the same stamps as the TUM
    // layout, so both layouts' trajectories compare with one ground truth.
    for (size_t i = 0; i < scene.frame_count(); ++i)
      out << format_timestamp(scene.timestamp(i)) << "\n";
    close_text(out, file);
  }
  {
    const fs::path file = dir / "calib.txt";
    std::ofstream out = open_text(file);
    const PinholeCamera& c = scene.camera();
    const double bf = c.fx * scene.options().stereo_baseline;
    char line[512];
    for (int k = 0; k < 4; ++k) {
      const double tx = k % 2 == 1 ? -bf : 0.0;
      std::snprintf(line, sizeof(line),
                    "P%d: %.12e 0.000000000000e+00 %.12e %.12e 0.000000000000e+00 %.12e %.12e "
                    "0.000000000000e+00 0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 "
                    "0.000000000000e+00\n",
                    k, c.fx, c.cx, tx, c.fy, c.cy);
      out << line;
    }
    close_text(out, file);
  }
  write_kitti_trajectory(dir / "poses.txt", scene.ground_truth());
}

std::string euroc_stamp(Timestamp t) {
  return std::to_string(static_cast<long long>(std::llround(t * 1e9)));
}

// EuRoC MAV files: cam0 and cam1 (data.csv, sensor.yaml: the synthetic intrinsics, no
// distortion, cam0 at the body origin and cam1 at (baseline, 0, 0), so rectification is the
// identity) and the body's ground truth (= cam0's pose).
void write_euroc_files(const fs::path& dir, const SyntheticScene& scene) {
  const PinholeCamera& c = scene.camera();
  for (int cam = 0; cam < 2; ++cam) {
    const fs::path folder = dir / "mav0" / ("cam" + std::to_string(cam));
    {
      const fs::path file = folder / "data.csv";
      std::ofstream out = open_text(file);
      out << "#timestamp [ns],filename\n";
      for (size_t i = 0; i < scene.frame_count(); ++i) {
        const std::string stamp = euroc_stamp(scene.timestamp(i));
        out << stamp << "," << stamp << ".png\n";
      }
      close_text(out, file);
    }
    const fs::path file = folder / "sensor.yaml";
    std::ofstream out = open_text(file);
    char text[1024];
    std::snprintf(text, sizeof(text),
                  "%%YAML:1.0\nsensor_type: camera\ncomment: pspslam synth cam%d\nT_BS:\n"
                  "  cols: 4\n  rows: 4\n  data: [1.0, 0.0, 0.0, %.9f, 0.0, 1.0, 0.0, 0.0,\n"
                  "         0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]\nrate_hz: 30\n"
                  "resolution: [%d, %d]\ncamera_model: pinhole\n"
                  "intrinsics: [%.9f, %.9f, %.9f, %.9f]\n"
                  "distortion_model: radial-tangential\n"
                  "distortion_coefficients: [0.0, 0.0, 0.0, 0.0]\n",
                  cam, cam == 1 ? scene.options().stereo_baseline : 0.0, c.width, c.height, c.fx,
                  c.fy, c.cx, c.cy);
    out << text;
    close_text(out, file);
  }
  const fs::path file = dir / "mav0/state_groundtruth_estimate0/data.csv";
  std::ofstream out = open_text(file);
  out << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
         "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad "
         "s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m "
         "s^-2], b_a_RS_S_z [m s^-2]\n";
  char line[512];
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    const Pose pose = scene.ground_truth_pose(i);
    Eigen::Quaterniond q(pose.linear());
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    const Eigen::Vector3d t = pose.translation();
    std::snprintf(line, sizeof(line), "%s,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,0,0,0,0,0,0,0,0,0\n",
                  euroc_stamp(scene.timestamp(i)).c_str(), t.x(), t.y(), t.z(), q.w(), q.x(), q.y(),
                  q.z());
    out << line;
  }
  close_text(out, file);
}

}  // namespace

std::string format_timestamp(Timestamp timestamp) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.6f", timestamp);
  return text;
}

void write_sequence(const SynthOptions& options, const fs::path& dir,
                    const SynthProgress& progress) {
  const SyntheticScene scene(options);
  write_sequence(scene, dir, progress);
}

namespace {

void create_layout_folders(const SyntheticScene& scene, const fs::path& dir) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) {
    throw Error("synth: --out " + dir.string() + " exists and is not a directory");
  }
  std::vector<const char*> folders = {"rgb", "depth", "mask"};
  if (scene.options().stereo_baseline > 0.0) folders.push_back("right");
  if (scene.options().layout == SynthOptions::Layout::kitti) folders = {"image_0", "image_1"};
  if (scene.options().layout == SynthOptions::Layout::euroc)
    folders = {"mav0/cam0/data", "mav0/cam1/data", "mav0/state_groundtruth_estimate0"};
  for (const char* sub : folders) {
    fs::create_directories(dir / sub, ec);
    if (ec) throw Error("synth: cannot create " + (dir / sub).string() + ": " + ec.message());
  }
}

// A worker's images, kept from frame to frame.
struct FrameImages {
  SynthFrame frame;
  cv::Mat depth_u16, right, gray;
};

// Every frame's people (people.txt), filled by the workers, one slot per frame.
using PeopleOfFrames = std::vector<std::vector<PersonTruth>>;

// Renders frame i and writes its images in the sequence's layout.
void write_frame(const SyntheticScene& scene, size_t i, const fs::path& dir, FrameImages& images,
                 PeopleOfFrames& people) {
  const bool stereo = scene.options().stereo_baseline > 0.0;
  SynthFrame& frame = images.frame;
  scene.render(i, frame, 1);
  people[i] = people_truth(scene, frame);
  if (stereo) {
    scene.render_right(i, images.right, 1);
    cv::cvtColor(images.right, images.right, cv::COLOR_BGR2GRAY);
  }
  if (scene.options().layout == SynthOptions::Layout::euroc) {
    // EuRoC's cameras are grey too; file names are the nanosecond stamps.
    const std::string name = euroc_stamp(scene.timestamp(i)) + ".png";
    cv::cvtColor(frame.bgr, images.gray, cv::COLOR_BGR2GRAY);
    write_png(dir / "mav0/cam0/data" / name, images.gray);
    write_png(dir / "mav0/cam1/data" / name, images.right);
  } else if (scene.options().layout == SynthOptions::Layout::kitti) {
    // KITTI's odometry pair is grey: the left is the colour image's grey conversion, which
    // is what the TUM-layout run extracts from, so both layouts track the same pixels.
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", i);
    cv::cvtColor(frame.bgr, images.gray, cv::COLOR_BGR2GRAY);
    write_png(dir / "image_0" / name, images.gray);
    write_png(dir / "image_1" / name, images.right);
  } else {
    const std::string name = format_timestamp(frame.timestamp) + ".png";
    write_png(dir / "rgb" / name, frame.bgr);
    frame.depth_sensor.convertTo(images.depth_u16, CV_16U, 5000.0);
    write_png(dir / "depth" / (format_timestamp(depth_timestamp(scene, i)) + ".png"),
              images.depth_u16);
    write_png(dir / "mask" / name, frame.labels);
    if (stereo) write_png(dir / "right" / name, images.right);
  }
}

// Whole frames per worker (render single-threaded + encode): PNG encoding dominates and
// parallelises only across frames. The first error stops the workers and is rethrown.
void write_frames(const SyntheticScene& scene, const fs::path& dir, const SynthProgress& progress,
                  PeopleOfFrames& people) {
  const size_t frames = scene.frame_count();
  const int requested = scene.options().threads;
  const size_t workers = std::max<size_t>(
      1,
      std::min<size_t>(frames, requested > 0 ? static_cast<size_t>(requested)
                                             : std::max(1u, std::thread::hardware_concurrency())));
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;
  std::condition_variable frame_done;
  size_t done = 0;
  std::exception_ptr first_error;

  const auto worker = [&] {
    FrameImages images;
    for (size_t i = next++; i < frames && !failed; i = next++) {
      try {
        write_frame(scene, i, dir, images, people);
      } catch (...) {
        std::lock_guard lock(mutex);
        if (!first_error) first_error = std::current_exception();
        failed = true;
      }
      {
        std::lock_guard lock(mutex);
        ++done;
      }
      frame_done.notify_one();
    }
  };
  std::vector<std::thread> pool;
  for (size_t w = 0; w < workers; ++w) pool.emplace_back(worker);
  {
    std::unique_lock lock(mutex);
    size_t reported = 0;
    while (reported < frames && !failed) {
      frame_done.wait(lock, [&] { return done > reported || failed; });
      reported = done;
      if (progress && !failed) {
        lock.unlock();
        progress(reported);
        lock.lock();
      }
    }
  }
  for (std::thread& thread : pool) thread.join();
  if (first_error) std::rethrow_exception(first_error);
}

// The TUM layout's frame lists, configs and notes.
void write_tum_files(const fs::path& dir, const SyntheticScene& scene) {
  const auto colour_stamp = [&](size_t i) { return scene.timestamp(i); };
  write_frame_list(dir, "rgb.txt", "rgb", "color images", scene, colour_stamp);
  write_frame_list(dir, "depth.txt", "depth",
                   "depth maps (16-bit PNG, 5000 per metre, 0 = no reading)", scene,
                   [&](size_t i) { return depth_timestamp(scene, i); });
  write_frame_list(dir, "mask.txt", "mask",
                   "ground-truth labels (0 static, 15 person, 100 carried object)", scene,
                   colour_stamp);
  if (scene.options().stereo_baseline > 0.0) {
    write_frame_list(dir, "right.txt", "right",
                     "rectified right images (8-bit grey) of the stereo pair", scene, colour_stamp);
    save_config(dir / "config_rgbd.yaml", scene.rgbd_system_config());
  }
  save_config(dir / "config.yaml", scene.system_config());
  if (scene.options().sensor == SynthSensor::kKinect) write_body_to_camera(dir, scene);
  write_info(dir, scene);
  write_readme(dir, scene);
}

}  // namespace

void write_sequence(const SyntheticScene& scene, const fs::path& dir,
                    const SynthProgress& progress) {
  create_layout_folders(scene, dir);
  PeopleOfFrames people(scene.frame_count());
  write_frames(scene, dir, progress, people);
  if (scene.body_count() > 0) {
    std::vector<PersonTruth> rows;
    for (const std::vector<PersonTruth>& frame : people)
      rows.insert(rows.end(), frame.begin(), frame.end());
    write_people_truth(dir / "people.txt", rows);
  }
  write_ground_truth(dir, scene);
  if (scene.options().layout == SynthOptions::Layout::euroc) {
    write_euroc_files(dir, scene);
    write_info(dir, scene);
    return;
  }
  if (scene.options().layout == SynthOptions::Layout::kitti) {
    // The camera comes from calib.txt; config.yaml would not be read in this layout.
    write_kitti_files(dir, scene);
    write_info(dir, scene);
    return;
  }
  write_tum_files(dir, scene);
}

}  // namespace pspslam
