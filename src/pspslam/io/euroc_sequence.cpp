#include "pspslam/io/euroc_sequence.h"

#include <Eigen/Geometry>
#include <cstdio>

#include "pspslam/core/error.h"
#include "pspslam/io/text_lines.h"

namespace pspslam {
namespace {

struct ListedImage {
  Timestamp timestamp = 0.0;
  std::string file;
};

// cam0/data.csv or cam1/data.csv: `timestamp_ns,filename` rows (header comment skipped).
std::vector<ListedImage> read_euroc_list(const std::filesystem::path& file,
                                         const std::string& folder) {
  if (!std::filesystem::exists(file)) throw Error(file.string() + ": not found");
  std::vector<ListedImage> list;
  for_each_data_line(file, "EuRoC image list", [&](const TextLine& line) {
    if (line.fields.size() != 2) {
      throw Error(line_prefix(file, line.line) + "expected 'timestamp [ns],filename', got " +
                  std::to_string(line.fields.size()) + " fields");
    }
    const double ns = parse_number(line.fields[0], file, line.line, "timestamp");
    list.push_back({ns * 1e-9, folder + "/data/" + std::string(line.fields[1])});
  });
  return list;
}

// state_groundtruth_estimate0/data.csv: timestamp, p_RS_R (3), q_RS (w x y z), then velocities
// and biases; the body pose T_world_body.
Trajectory read_euroc_ground_truth(const std::filesystem::path& file, const Pose& T_body_camera) {
  Trajectory trajectory;
  for_each_data_line(file, "EuRoC ground truth", [&](const TextLine& line) {
    if (line.fields.size() < 8) {
      throw Error(line_prefix(file, line.line) +
                  "expected 'timestamp, p x y z, q w x y z, ...', got " +
                  std::to_string(line.fields.size()) + " fields");
    }
    double v[8];
    for (size_t k = 0; k < 8; ++k) v[k] = parse_number(line.fields[k], file, line.line, "value");
    const Eigen::Quaterniond q(v[4], v[5], v[6], v[7]);
    if (std::abs(q.norm() - 1.0) > 1e-3) {
      throw Error(line_prefix(file, line.line) + "quaternion has norm " + std::to_string(q.norm()) +
                  ", expected a unit quaternion");
    }
    Pose T_world_body = Pose::Identity();
    T_world_body.linear() = q.normalized().toRotationMatrix();
    T_world_body.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    trajectory.push_back({v[0] * 1e-9, T_world_body * T_body_camera});
  });
  return trajectory;
}

std::filesystem::path mav_folder(const std::filesystem::path& dir) {
  return std::filesystem::exists(dir / "mav0" / "cam0") ? dir / "mav0" : dir;
}

}  // namespace

bool EurocSequence::has_right_camera(const std::filesystem::path& dir) {
  return std::filesystem::exists(mav_folder(dir) / "cam1" / "data.csv");
}

EurocSequence EurocSequence::open(const std::filesystem::path& dir,
                                  const SequenceOptions& options) {
  if (!std::filesystem::is_directory(dir)) {
    throw Error(dir.string() + ": sequence directory not found");
  }
  const std::filesystem::path mav = mav_folder(dir);
  if (!std::filesystem::exists(mav / "cam0" / "data.csv")) {
    throw Error(dir.string() +
                ": no mav0/cam0/data.csv (an EuRoC MAV sequence needs mav0/cam0, and mav0/cam1 "
                "for stereo, each with data.csv, data/ and sensor.yaml)");
  }
  const SensorType sensor =
      options.sensor.value_or(has_right_camera(dir) ? SensorType::stereo : SensorType::monocular);
  if (sensor == SensorType::rgbd) {
    throw Error(dir.string() + ": a EuRoC MAV sequence has no depth images");
  }
  EurocSequence sequence(mav, options, sensor);
  sequence.left_ = read_euroc_camera(mav / "cam0" / "sensor.yaml");
  // The camera load() delivers, in cam0's frame: x_camera = R x_cam0.
  Eigen::Matrix3d R_camera_cam0 = Eigen::Matrix3d::Identity();
  if (sequence.stereo()) {
    const EurocCamera right = read_euroc_camera(mav / "cam1" / "sensor.yaml");
    sequence.rectification_ =
        std::make_shared<const StereoRectification>(StereoRectification::compute(
            sequence.left_, right,
            (mav / "cam0" / "sensor.yaml").string() + " and " + "cam1/sensor.yaml"));
    R_camera_cam0 = sequence.rectification_->R_rect_left;
    sequence.list_pairs(mav);
  } else {
    sequence.undistortion_ =
        std::make_shared<const Undistortion>(Undistortion::compute(sequence.left_));
    sequence.list_left_images(mav);
  }
  if (sequence.frames_.empty()) {
    throw Error(dir.string() + ": no " + to_string(sensor) + " frame: " +
                (sequence.stereo()
                     ? std::to_string(sequence.listed_rgb_) + " cam0 and " +
                           std::to_string(sequence.listed_depth_) +
                           " cam1 images listed, none paired within 1 ms with both "
                           "files present"
                     : std::to_string(sequence.listed_rgb_) + " cam0 images listed, none present"));
  }
  sequence.ground_truth_file_ = std::filesystem::path("state_groundtruth_estimate0") / "data.csv";
  const std::filesystem::path ground_truth = mav / sequence.ground_truth_file_;
  if (std::filesystem::exists(ground_truth)) {
    Pose T_cam0_camera = Pose::Identity();
    T_cam0_camera.linear() = R_camera_cam0.transpose();
    sequence.ground_truth_ =
        read_euroc_ground_truth(ground_truth, sequence.left_.T_body_camera * T_cam0_camera);
  }
  return sequence;
}

void EurocSequence::list_pairs(const std::filesystem::path& mav) {
  const std::vector<ListedImage> cam0 = read_euroc_list(mav / "cam0" / "data.csv", "cam0");
  const std::vector<ListedImage> cam1 = read_euroc_list(mav / "cam1" / "data.csv", "cam1");
  listed_rgb_ = cam0.size();
  listed_depth_ = cam1.size();
  std::vector<Timestamp> t0, t1;
  std::vector<std::string> listed;
  for (const ListedImage& f : cam0) {
    t0.push_back(f.timestamp);
    listed.push_back(f.file);
  }
  for (const ListedImage& f : cam1) {
    t1.push_back(f.timestamp);
    listed.push_back(f.file);
  }
  // The two cameras are triggered together: their stamps agree to well under a millisecond.
  std::vector<FrameFiles> frames;
  for (const TimestampMatch& m : associate_timestamps(t0, t1, 1e-3)) {
    frames.push_back({cam0[m.first].timestamp, cam0[m.first].file, cam1[m.second].timestamp,
                      cam1[m.second].file});
  }
  keep_present_frames(std::move(frames), listed);
}

void EurocSequence::list_left_images(const std::filesystem::path& mav) {
  std::vector<FrameFiles> frames;
  std::vector<std::string> listed;
  for (const ListedImage& f : read_euroc_list(mav / "cam0" / "data.csv", "cam0")) {
    frames.push_back({f.timestamp, f.file, f.timestamp, std::string()});
    listed.push_back(f.file);
  }
  listed_rgb_ = frames.size();
  keep_present_frames(std::move(frames), listed);
}

void EurocSequence::to_camera_images(InputFrame& frame) const {
  cv::Mat left, right;
  if (rectification_) {
    rectification_->rectify(frame.bgr, frame.right, left, right);
    frame.right = right;
  } else {
    undistortion_->undistort(frame.bgr, left);
  }
  frame.bgr = left;
}

std::string EurocSequence::listing() const {
  char text[256];
  if (stereo()) {
    std::snprintf(text, sizeof(text),
                  "%zu colour and %zu right files listed, paired as the euroc layout lists them",
                  listed_rgb_, listed_depth_);
  } else {
    std::snprintf(text, sizeof(text), "%zu cam0 images listed in cam0/data.csv, cam0 alone",
                  listed_rgb_);
  }
  return text;
}

std::optional<LayoutCamera> EurocSequence::layout_camera() const {
  LayoutCamera camera;
  if (rectification_) {
    const StereoRectification& rect = *rectification_;
    camera = {rect.size, rect.fx, rect.fy, rect.cx, rect.cy, rect.baseline, left_.rate_hz};
  } else {
    const Undistortion& u = *undistortion_;
    camera = {u.size, u.fx, u.fy, u.cx, u.cy, 0.0, left_.rate_hz};
  }
  return camera;
}

}  // namespace pspslam
