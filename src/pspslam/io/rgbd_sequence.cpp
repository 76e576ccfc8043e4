#include "pspslam/io/rgbd_sequence.h"

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
  if (std::filesystem::exists(associations)) {
    associated = read_associations(associations);
    sequence.used_associations_file_ = true;
    sequence.listed_rgb_ = sequence.listed_depth_ = associated.size();
    for (const FrameFiles& f : associated) {
      listed_files.push_back(f.rgb_file);
      listed_files.push_back(f.depth_file);
    }
  } else {
    const std::filesystem::path rgb_list = dir / "rgb.txt";
    const std::filesystem::path depth_list = dir / "depth.txt";
    for (const auto& list : {rgb_list, depth_list}) {
      if (!std::filesystem::exists(list)) {
        throw Error(dir.string() + ": no " + list.filename().string() +
                    " (a TUM RGB-D sequence needs rgb.txt and depth.txt, or associations.txt)");
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
  if (sequence.frames_.empty()) {
    throw Error(dir.string() + ": no RGB-D frame: " + std::to_string(sequence.listed_rgb_) +
                " colour and " + std::to_string(sequence.listed_depth_) +
                " depth files listed, none associated within " +
                std::to_string(options.max_difference) + " s with both files present");
  }

  const std::filesystem::path ground_truth = dir / "groundtruth.txt";
  if (std::filesystem::exists(ground_truth)) {
    sequence.ground_truth_ = read_tum_trajectory(ground_truth);
  }
  return sequence;
}

std::optional<std::filesystem::path> RgbdSequence::config_path() const {
  const std::filesystem::path config = dir_ / "config.yaml";
  if (std::filesystem::exists(config)) return config;
  return std::nullopt;
}

RgbdFrame RgbdSequence::load(size_t i) const {
  const FrameFiles& files = frames_.at(i);
  RgbdFrame frame;
  frame.index = i;
  frame.timestamp = files.rgb_timestamp;
  frame.depth_timestamp = files.depth_timestamp;
  frame.name = files.rgb_file;
  const std::filesystem::path rgb_path = dir_ / files.rgb_file;
  const std::filesystem::path depth_path = dir_ / files.depth_file;
  frame.bgr = read_color_image(rgb_path);
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

}  // namespace pspslam
