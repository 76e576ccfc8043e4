#include "pspslam/io/tum_sequence.h"

#include <cstdio>
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

}  // namespace

TumSequence TumSequence::open(const std::filesystem::path& dir, const SequenceOptions& options) {
  if (!std::filesystem::is_directory(dir)) {
    throw Error(dir.string() + ": sequence directory not found");
  }
  if (!(options.depth_factor > 0.0)) {
    throw Error(dir.string() + ": depth factor must be > 0");
  }
  TumSequence sequence(dir, options, options.sensor.value_or(SensorType::rgbd));
  const bool monocular = sequence.sensor_ == SensorType::monocular;
  const std::filesystem::path associations = dir / "associations.txt";
  if (monocular && std::filesystem::exists(dir / "rgb.txt")) {
    std::vector<FrameFiles> frames;
    std::vector<std::string> listed_files;
    for (const ListedFile& f : read_file_list(dir / "rgb.txt")) {
      frames.push_back({f.timestamp, f.file, f.timestamp, std::string()});
      listed_files.push_back(f.file);
    }
    sequence.listed_rgb_ = frames.size();
    sequence.keep_present_frames(std::move(frames), listed_files);
  } else if (!sequence.stereo() && std::filesystem::exists(associations)) {
    // A monocular run without rgb.txt takes the colour column of associations.txt.
    std::vector<FrameFiles> frames = read_associations(associations);
    sequence.used_associations_file_ = true;
    sequence.listed_rgb_ = sequence.listed_depth_ = frames.size();
    std::vector<std::string> listed_files;
    for (const FrameFiles& f : frames) {
      listed_files.push_back(f.rgb_file);
      listed_files.push_back(f.depth_file);
    }
    sequence.keep_present_frames(std::move(frames), listed_files);
  } else {
    sequence.associate_lists();
  }
  if (sequence.frames_.empty()) {
    if (monocular) {
      throw Error(dir.string() + ": no colour frame: " + std::to_string(sequence.listed_rgb_) +
                  " colour files listed, none present");
    }
    throw Error(dir.string() + ": no " + (sequence.stereo() ? "stereo" : "RGB-D") +
                " frame: " + std::to_string(sequence.listed_rgb_) + " colour and " +
                std::to_string(sequence.listed_depth_) + (sequence.stereo() ? " right" : " depth") +
                " files listed, none associated within " + std::to_string(options.max_difference) +
                " s with both files present");
  }

  sequence.ground_truth_file_ = "groundtruth.txt";
  const std::filesystem::path ground_truth = dir / sequence.ground_truth_file_;
  if (std::filesystem::exists(ground_truth)) {
    sequence.ground_truth_ = read_tum_trajectory(ground_truth);
  }
  return sequence;
}

void TumSequence::associate_lists() {
  const std::filesystem::path rgb_list = dir_ / "rgb.txt";
  const std::filesystem::path depth_list = dir_ / (stereo() ? "right.txt" : "depth.txt");
  for (const auto& list : {rgb_list, depth_list}) {
    if (!std::filesystem::exists(list)) {
      throw Error(dir_.string() + ": no " + list.filename().string() +
                  (stereo() ? " (a stereo sequence in TUM layout needs rgb.txt and right.txt)"
                            : " (a TUM RGB-D sequence needs rgb.txt and depth.txt, or "
                              "associations.txt)"));
    }
  }
  const std::vector<ListedFile> rgb = read_file_list(rgb_list);
  const std::vector<ListedFile> depth = read_file_list(depth_list);
  listed_rgb_ = rgb.size();
  listed_depth_ = depth.size();
  std::vector<Timestamp> rgb_times, depth_times;
  std::vector<std::string> listed_files;  // every listed file, in listing order
  for (const ListedFile& f : rgb) {
    rgb_times.push_back(f.timestamp);
    listed_files.push_back(f.file);
  }
  for (const ListedFile& f : depth) {
    depth_times.push_back(f.timestamp);
    listed_files.push_back(f.file);
  }
  // Associate on the lists as associate.py does, so the pairs are those of the published
  // association files; a missing file then drops its frame.
  std::vector<FrameFiles> frames;
  for (const TimestampMatch& m :
       associate_timestamps(rgb_times, depth_times, options_.max_difference)) {
    frames.push_back({rgb[m.first].timestamp, rgb[m.first].file, depth[m.second].timestamp,
                      depth[m.second].file});
  }
  keep_present_frames(std::move(frames), listed_files);
}

std::string TumSequence::listing() const {
  char text[256];
  if (sensor_ == SensorType::monocular) {
    std::snprintf(text, sizeof(text), "%zu colour files listed in rgb.txt, colour only",
                  listed_rgb_);
    return text;
  }
  char how[64];
  if (used_associations_file_) {
    std::snprintf(how, sizeof(how), "in associations.txt");
  } else {
    std::snprintf(how, sizeof(how), "associated within %g s", options_.max_difference);
  }
  std::snprintf(text, sizeof(text), "%zu colour and %zu %s files listed, %s", listed_rgb_,
                listed_depth_, stereo() ? "right" : "depth", how);
  return text;
}

}  // namespace pspslam
