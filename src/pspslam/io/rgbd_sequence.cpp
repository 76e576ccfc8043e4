#include "pspslam/io/rgbd_sequence.h"

#include <Eigen/Geometry>
#include <array>
#include <cstdio>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <ostream>
#include <system_error>
#include <unordered_map>

#include "pspslam/core/error.h"
#include "pspslam/io/text_lines.h"
#include "pspslam/io/trajectory_io.h"

namespace pspslam {
namespace {

struct ListedFile {
  Timestamp timestamp = 0.0;
  std::string file;
};

// Reads rgb.txt / depth.txt: `timestamp filename` per line.
std::vector<ListedFile> read_file_list(const std::filesystem::path& file) {
  std::vector<ListedFile> list;
  std::unordered_map<double, size_t> line_of_timestamp;
  for_each_data_line(file, "file list", [&](const TextLine& line) {
    if (line.fields.size() != 2) {
      throw Error(line_prefix(file, line.line) + "expected 'timestamp filename', got " +
                  std::to_string(line.fields.size()) + " fields");
    }
    const double t = parse_number(line.fields[0], file, line.line, "timestamp");
    const auto [it, inserted] = line_of_timestamp.emplace(t, line.line);
    if (!inserted) {
      throw Error(line_prefix(file, line.line) + "timestamp " + std::string(line.fields[0]) +
                  " repeats line " + std::to_string(it->second));
    }
    list.push_back({t, std::string(line.fields[1])});
  });
  return list;
}

std::vector<FrameFiles> read_associations(const std::filesystem::path& file) {
  std::vector<FrameFiles> frames;
  for_each_data_line(file, "association file", [&](const TextLine& line) {
    if (line.fields.size() != 4) {
      throw Error(line_prefix(file, line.line) +
                  "expected 't_rgb rgb_file t_depth depth_file', got " +
                  std::to_string(line.fields.size()) + " fields");
    }
    FrameFiles frame;
    frame.rgb_timestamp = parse_number(line.fields[0], file, line.line, "rgb timestamp");
    frame.rgb_file = std::string(line.fields[1]);
    frame.depth_timestamp = parse_number(line.fields[2], file, line.line, "depth timestamp");
    frame.depth_file = std::string(line.fields[3]);
    frames.push_back(std::move(frame));
  });
  return frames;
}

std::string describe_type(const cv::Mat& image) {
  std::string depth;
  switch (image.depth()) {
    case CV_8U:
      depth = "8-bit";
      break;
    case CV_8S:
      depth = "8-bit signed";
      break;
    case CV_16U:
      depth = "16-bit";
      break;
    case CV_16S:
      depth = "16-bit signed";
      break;
    case CV_32F:
      depth = "32-bit float";
      break;
    default:
      depth = "type " + std::to_string(image.depth());
      break;
  }
  const int channels = image.channels();
  return depth + ", " + std::to_string(channels) + (channels == 1 ? " channel" : " channels");
}

}  // namespace

cv::Mat read_depth_image(const std::filesystem::path& file, double depth_factor, int shift_x,
                         int shift_y) {
  const cv::Mat raw = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  if (raw.empty()) {
    throw Error(file.string() + ": cannot read depth image (missing, empty or not an image)");
  }
  if (raw.type() != CV_16UC1) {
    throw Error(file.string() + ": depth image must be 16-bit single-channel (got " +
                describe_type(raw) + ")");
  }
  return depth_to_metres(raw, depth_factor, shift_x, shift_y);
}

cv::Mat depth_to_metres(const cv::Mat& raw, double depth_factor, int shift_x, int shift_y) {
  cv::Mat metres;
  if (shift_x == 0 && shift_y == 0) {
    raw.convertTo(metres, CV_32F, 1.0 / depth_factor);
    return metres;
  }
  // One conversion of the overlapping rectangle into place; the strip shifted in stays 0.
  metres = cv::Mat::zeros(raw.size(), CV_32F);
  const cv::Rect image(0, 0, raw.cols, raw.rows);
  const cv::Rect source = image & (image + cv::Point(shift_x, shift_y));
  if (!source.empty()) {
    cv::Mat target = metres(source - cv::Point(shift_x, shift_y));
    raw(source).convertTo(target, CV_32F, 1.0 / depth_factor);
  }
  return metres;
}

cv::Mat read_color_image(const std::filesystem::path& file) {
  cv::Mat bgr = cv::imread(file.string(), cv::IMREAD_COLOR);
  if (bgr.empty()) {
    throw Error(file.string() + ": cannot read colour image (missing, empty or not an image)");
  }
  return bgr;
}

RgbdSequence RgbdSequence::open(const std::filesystem::path& dir, const SequenceOptions& options) {
  if (!std::filesystem::is_directory(dir)) {
    throw Error(dir.string() + ": sequence directory not found");
  }
  if (!(options.depth_factor > 0.0)) {
    throw Error(dir.string() + ": depth factor must be > 0");
  }
  RgbdSequence sequence;
  sequence.dir_ = dir;
  sequence.options_ = options;

  std::vector<FrameFiles> associated;
  std::vector<std::string> listed_files;  // every listed file, in listing order
  const std::filesystem::path associations = dir / "associations.txt";
  if (options.colour_only && std::filesystem::exists(dir / "rgb.txt")) {
    for (const ListedFile& f : read_file_list(dir / "rgb.txt")) {
      associated.push_back({f.timestamp, f.file, f.timestamp, std::string()});
      listed_files.push_back(f.file);
    }
    sequence.listed_rgb_ = associated.size();
  } else if (!options.stereo && std::filesystem::exists(associations)) {
    associated = read_associations(associations);
    sequence.used_associations_file_ = true;
    sequence.listed_rgb_ = sequence.listed_depth_ = associated.size();
    for (const FrameFiles& f : associated) {
      listed_files.push_back(f.rgb_file);
      listed_files.push_back(f.depth_file);
    }
  } else {
    const std::filesystem::path rgb_list = dir / "rgb.txt";
    const std::filesystem::path depth_list = dir / (options.stereo ? "right.txt" : "depth.txt");
    for (const auto& list : {rgb_list, depth_list}) {
      if (!std::filesystem::exists(list)) {
        throw Error(dir.string() + ": no " + list.filename().string() +
                    (options.stereo
                         ? " (a stereo sequence in TUM layout needs rgb.txt and right.txt)"
                         : " (a TUM RGB-D sequence needs rgb.txt and depth.txt, or "
                           "associations.txt)"));
      }
    }
    const std::vector<ListedFile> rgb = read_file_list(rgb_list);
    const std::vector<ListedFile> depth = read_file_list(depth_list);
    sequence.listed_rgb_ = rgb.size();
    sequence.listed_depth_ = depth.size();
    std::vector<Timestamp> rgb_times, depth_times;
    for (const ListedFile& f : rgb) {
      rgb_times.push_back(f.timestamp);
      listed_files.push_back(f.file);
    }
    for (const ListedFile& f : depth) {
      depth_times.push_back(f.timestamp);
      listed_files.push_back(f.file);
    }
    // Associate on the lists as associate.py does, so the pairs are those of the published
    // association files; a missing file then drops its frame below.
    for (const TimestampMatch& m :
         associate_timestamps(rgb_times, depth_times, options.max_difference)) {
      associated.push_back({rgb[m.first].timestamp, rgb[m.first].file, depth[m.second].timestamp,
                            depth[m.second].file});
    }
  }

  sequence.keep_present_frames(std::move(associated), listed_files);
  if (sequence.frames_.empty()) {
    if (options.colour_only) {
      throw Error(dir.string() + ": no colour frame: " + std::to_string(sequence.listed_rgb_) +
                  " colour files listed, none present");
    }
    throw Error(dir.string() + ": no " + (options.stereo ? "stereo" : "RGB-D") +
                " frame: " + std::to_string(sequence.listed_rgb_) + " colour and " +
                std::to_string(sequence.listed_depth_) + (options.stereo ? " right" : " depth") +
                " files listed, none associated within " + std::to_string(options.max_difference) +
                " s with both files present");
  }

  const std::filesystem::path ground_truth = dir / "groundtruth.txt";
  if (std::filesystem::exists(ground_truth)) {
    sequence.ground_truth_ = read_tum_trajectory(ground_truth);
  }
  return sequence;
}

void RgbdSequence::keep_present_frames(std::vector<FrameFiles> associated,
                                       const std::vector<std::string>& listed_files) {
  RgbdSequence& sequence = *this;
  const std::filesystem::path& dir = dir_;
  const SequenceOptions& options = options_;
  // A listed name the file system cannot even look up (too long, say) is a missing file, not an
  // exception (found by fuzz/fuzz_sequence_lists).
  const auto present = [&](const std::string& file) {
    std::error_code ec;
    return std::filesystem::exists(dir / file, ec) && !ec;
  };
  std::string first_missing;
  for (const std::string& file : listed_files) {
    if (present(file)) continue;
    if (sequence.missing_files_++ == 0) first_missing = file;
  }
  for (FrameFiles& frame : associated) {
    if (sequence.missing_files_ > 0 && (!present(frame.rgb_file) || !present(frame.depth_file))) {
      ++sequence.skipped_frames_;
      continue;
    }
    sequence.frames_.push_back(std::move(frame));
  }
  if (sequence.missing_files_ > 0) {
    sequence.warning_ = dir.string() + ": " + std::to_string(sequence.missing_files_) +
                        " listed files are missing; skipped " +
                        std::to_string(sequence.skipped_frames_) +
                        " frames (first: " + first_missing + ")";
    if (options.warnings != nullptr) *options.warnings << "warning: " << sequence.warning_ << "\n";
  }
}

std::string to_string(SequenceLayout layout) {
  switch (layout) {
    case SequenceLayout::kitti:
      return "kitti";
    case SequenceLayout::euroc:
      return "euroc";
    case SequenceLayout::tum:
      break;
  }
  return "tum";
}

namespace {

// cam0/data.csv or cam1/data.csv: `timestamp_ns,filename` rows (header comment skipped).
std::vector<ListedFile> read_euroc_list(const std::filesystem::path& file,
                                        const std::string& folder) {
  if (!std::filesystem::exists(file)) throw Error(file.string() + ": not found");
  std::vector<ListedFile> list;
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

}  // namespace

RgbdSequence RgbdSequence::open_euroc(const std::filesystem::path& dir,
                                      const SequenceOptions& options) {
  if (!std::filesystem::is_directory(dir)) {
    throw Error(dir.string() + ": sequence directory not found");
  }
  const std::filesystem::path mav =
      std::filesystem::exists(dir / "mav0" / "cam0") ? dir / "mav0" : dir;
  if (!std::filesystem::exists(mav / "cam0" / "data.csv")) {
    throw Error(dir.string() +
                ": no mav0/cam0/data.csv (an EuRoC MAV sequence needs mav0/cam0 and mav0/cam1, "
                "each with data.csv, data/ and sensor.yaml)");
  }
  RgbdSequence sequence;
  sequence.dir_ = mav;
  sequence.options_ = options;
  sequence.options_.stereo = true;
  sequence.layout_ = SequenceLayout::euroc;
  const EurocCamera left = read_euroc_camera(mav / "cam0" / "sensor.yaml");
  const EurocCamera right = read_euroc_camera(mav / "cam1" / "sensor.yaml");
  sequence.rectification_ =
      std::make_shared<const StereoRectification>(StereoRectification::compute(
          left, right, (mav / "cam0" / "sensor.yaml").string() + " and " + "cam1/sensor.yaml"));
  const std::vector<ListedFile> cam0 = read_euroc_list(mav / "cam0" / "data.csv", "cam0");
  const std::vector<ListedFile> cam1 = read_euroc_list(mav / "cam1" / "data.csv", "cam1");
  sequence.listed_rgb_ = cam0.size();
  sequence.listed_depth_ = cam1.size();
  std::vector<Timestamp> t0, t1;
  std::vector<std::string> listed;
  for (const ListedFile& f : cam0) {
    t0.push_back(f.timestamp);
    listed.push_back(f.file);
  }
  for (const ListedFile& f : cam1) {
    t1.push_back(f.timestamp);
    listed.push_back(f.file);
  }
  // The two cameras are triggered together: their stamps agree to well under a millisecond.
  std::vector<FrameFiles> associated;
  for (const TimestampMatch& m : associate_timestamps(t0, t1, 1e-3)) {
    associated.push_back({cam0[m.first].timestamp, cam0[m.first].file, cam1[m.second].timestamp,
                          cam1[m.second].file});
  }
  sequence.keep_present_frames(std::move(associated), listed);
  if (sequence.frames_.empty()) {
    throw Error(dir.string() + ": no stereo frame: " + std::to_string(cam0.size()) + " cam0 and " +
                std::to_string(cam1.size()) +
                " cam1 images listed, none paired within 1 ms with both files present");
  }
  const std::filesystem::path ground_truth = mav / "state_groundtruth_estimate0" / "data.csv";
  if (std::filesystem::exists(ground_truth)) {
    // The rectified left camera: x_rect = R x_cam0, so T_cam0_rect rotates by R^T.
    Pose T_cam0_rect = Pose::Identity();
    T_cam0_rect.linear() = sequence.rectification_->R_rect_left.transpose();
    sequence.ground_truth_ =
        read_euroc_ground_truth(ground_truth, left.T_body_camera * T_cam0_rect);
  }
  return sequence;
}

KittiCalibration read_kitti_calibration(const std::filesystem::path& file) {
  std::optional<std::array<double, 12>> p0, p1;
  size_t p0_line = 0, p1_line = 0;
  for_each_data_line(file, "KITTI calibration", [&](const TextLine& line) {
    const std::string_view name = line.fields[0];
    if (name != "P0:" && name != "P1:") return;  // P2, P3, Tr: other sensors
    if (line.fields.size() != 13) {
      throw Error(line_prefix(file, line.line) + std::string(name) + " expected 12 numbers, got " +
                  std::to_string(line.fields.size() - 1));
    }
    std::array<double, 12> p{};
    for (size_t k = 0; k < 12; ++k) {
      p[k] = parse_number(line.fields[k + 1], file, line.line, std::string(name.substr(0, 2)));
    }
    (name == "P0:" ? p0 : p1) = p;
    (name == "P0:" ? p0_line : p1_line) = line.line;
  });
  if (!p0) throw Error(file.string() + ": no 'P0:' line (the left camera's projection matrix)");
  if (!p1) throw Error(file.string() + ": no 'P1:' line (the right camera's projection matrix)");
  KittiCalibration calibration;
  calibration.fx = (*p0)[0];
  calibration.cx = (*p0)[2];
  calibration.fy = (*p0)[5];
  calibration.cy = (*p0)[6];
  if (!(calibration.fx > 0.0) || !(calibration.fy > 0.0)) {
    throw Error(line_prefix(file, p0_line) + "P0 focal lengths must be > 0");
  }
  if (std::abs((*p1)[0] - calibration.fx) > 1e-6 * calibration.fx) {
    throw Error(line_prefix(file, p1_line) + "P1 fx " + std::to_string((*p1)[0]) +
                " differs from P0's " + std::to_string(calibration.fx) + ": not a rectified pair");
  }
  calibration.baseline = -(*p1)[3] / calibration.fx;
  if (!(calibration.baseline > 0.0)) {
    throw Error(line_prefix(file, p1_line) +
                "P1 must put the right camera at a positive baseline (P1[0][3] = -fx * baseline "
                "< 0), got P1[0][3] = " +
                std::to_string((*p1)[3]));
  }
  return calibration;
}

RgbdSequence RgbdSequence::open_kitti(const std::filesystem::path& dir,
                                      const SequenceOptions& options) {
  if (!std::filesystem::is_directory(dir)) {
    throw Error(dir.string() + ": sequence directory not found");
  }
  RgbdSequence sequence;
  sequence.dir_ = dir;
  sequence.options_ = options;
  sequence.options_.stereo = true;
  sequence.layout_ = SequenceLayout::kitti;
  const std::filesystem::path times = dir / "times.txt";
  if (!std::filesystem::exists(times)) {
    throw Error(dir.string() +
                ": no times.txt (a KITTI odometry sequence needs times.txt, "
                "calib.txt, image_0/ and image_1/)");
  }
  std::vector<FrameFiles> frames;
  std::vector<std::string> listed;
  Timestamp previous = -std::numeric_limits<double>::infinity();
  for_each_data_line(times, "KITTI times", [&](const TextLine& line) {
    if (line.fields.size() != 1) {
      throw Error(line_prefix(times, line.line) + "expected one timestamp, got " +
                  std::to_string(line.fields.size()) + " fields");
    }
    const double t = parse_number(line.fields[0], times, line.line, "timestamp");
    if (!(t > previous)) {
      throw Error(line_prefix(times, line.line) + "timestamp " + std::string(line.fields[0]) +
                  " does not increase");
    }
    previous = t;
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", frames.size());
    FrameFiles files{t, std::string("image_0/") + name, t, std::string("image_1/") + name};
    listed.push_back(files.rgb_file);
    listed.push_back(files.depth_file);
    frames.push_back(std::move(files));
  });
  sequence.listed_rgb_ = sequence.listed_depth_ = frames.size();
  std::vector<Timestamp> stamps;
  for (const FrameFiles& f : frames) stamps.push_back(f.rgb_timestamp);
  sequence.keep_present_frames(std::move(frames), listed);
  if (sequence.frames_.empty()) {
    throw Error(dir.string() + ": no stereo frame: " + std::to_string(sequence.listed_rgb_) +
                " listed in times.txt, none with both image_0/ and image_1/ files present");
  }
  const std::filesystem::path poses = dir / "poses.txt";
  if (std::filesystem::exists(poses)) sequence.ground_truth_ = read_kitti_trajectory(poses, stamps);
  return sequence;
}

std::optional<std::filesystem::path> RgbdSequence::config_path() const {
  const std::filesystem::path config = dir_ / "config.yaml";
  if (std::filesystem::exists(config)) return config;
  return std::nullopt;
}

InputFrame RgbdSequence::load(size_t i) const {
  const FrameFiles& files = frames_.at(i);
  InputFrame frame;
  frame.index = i;
  frame.timestamp = files.rgb_timestamp;
  frame.depth_timestamp = files.depth_timestamp;
  frame.name = files.rgb_file;
  const std::filesystem::path rgb_path = dir_ / files.rgb_file;
  const std::filesystem::path depth_path = dir_ / files.depth_file;
  frame.bgr = read_color_image(rgb_path);  // KITTI's grey images load as three equal channels
  if (options_.stereo) {
    frame.right = cv::imread(depth_path.string(), cv::IMREAD_GRAYSCALE);
    if (frame.right.empty()) {
      throw Error(depth_path.string() +
                  ": cannot read right image (missing, empty or not an image)");
    }
    if (frame.right.size() != frame.bgr.size()) {
      throw Error(rgb_path.string() + " is " + std::to_string(frame.bgr.cols) + "x" +
                  std::to_string(frame.bgr.rows) + " but " + depth_path.string() + " is " +
                  std::to_string(frame.right.cols) + "x" + std::to_string(frame.right.rows));
    }
    if (rectification_) {
      cv::Mat left, right;
      rectification_->rectify(frame.bgr, frame.right, left, right);
      frame.bgr = left;
      frame.right = right;
    }
    if (options_.load_gray) cv::cvtColor(frame.bgr, frame.gray, cv::COLOR_BGR2GRAY);
    return frame;
  }
  if (options_.colour_only) {
    if (options_.load_gray) cv::cvtColor(frame.bgr, frame.gray, cv::COLOR_BGR2GRAY);
    return frame;
  }
  frame.depth = read_depth_image(depth_path, options_.depth_factor, options_.depth_shift_x,
                                 options_.depth_shift_y);
  if (frame.bgr.size() != frame.depth.size()) {
    throw Error(rgb_path.string() + " is " + std::to_string(frame.bgr.cols) + "x" +
                std::to_string(frame.bgr.rows) + " but " + depth_path.string() + " is " +
                std::to_string(frame.depth.cols) + "x" + std::to_string(frame.depth.rows));
  }
  if (options_.load_gray) cv::cvtColor(frame.bgr, frame.gray, cv::COLOR_BGR2GRAY);
  return frame;
}

std::filesystem::path per_frame_png_name(const std::filesystem::path& rgb_file) {
  return rgb_file.filename().stem().string() + ".png";
}

}  // namespace pspslam
