#include "pspslam/io/trajectory_io.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <fstream>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <unordered_map>

#include "pspslam/core/error.h"
#include "pspslam/io/text_lines.h"

namespace pspslam {
namespace {

constexpr const char* kFieldNames[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};

std::string format_number(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return buffer;
}

}  // namespace

Trajectory read_tum_trajectory(const std::filesystem::path& file) {
  Trajectory trajectory;
  std::unordered_map<double, size_t> line_of_timestamp;
  for_each_data_line(file, "trajectory file", [&](const TextLine& line) {
    if (line.fields.size() != 8) {
      throw Error(line_prefix(file, line.line) +
                  "expected 8 fields 'timestamp tx ty tz qx qy qz qw', got " +
                  std::to_string(line.fields.size()));
    }
    double values[8];
    for (size_t i = 0; i < 8; ++i) {
      values[i] = parse_number(line.fields[i], file, line.line, kFieldNames[i]);
    }
    Eigen::Quaterniond q(values[7], values[4], values[5], values[6]);
    const double norm = q.norm();
    if (!(std::abs(norm - 1.0) <= kQuaternionNormTolerance)) {
      throw Error(line_prefix(file, line.line) + "quaternion (qx qy qz qw) has norm " +
                  format_number(norm, 6) + ", expected a unit quaternion");
    }
    const auto [it, inserted] = line_of_timestamp.emplace(values[0], line.line);
    if (!inserted) {
      throw Error(line_prefix(file, line.line) + "timestamp " + std::string(line.fields[0]) +
                  " repeats line " + std::to_string(it->second));
    }
    StampedPose pose;
    pose.timestamp = values[0];
    pose.T_world_camera.linear() = q.normalized().toRotationMatrix();
    pose.T_world_camera.translation() = Eigen::Vector3d(values[1], values[2], values[3]);
    trajectory.push_back(pose);
  });
  return trajectory;
}

Pose read_rigid_transform(const std::filesystem::path& file) {
  std::vector<std::vector<double>> rows;
  std::vector<size_t> row_lines;
  for_each_data_line(file, "transform file", [&](const TextLine& line) {
    std::vector<double> row;
    for (size_t i = 0; i < line.fields.size(); ++i) {
      row.push_back(
          parse_number(line.fields[i], file, line.line, "value " + std::to_string(i + 1)));
    }
    rows.push_back(std::move(row));
    row_lines.push_back(line.line);
  });
  const std::string form =
      "expected 'tx ty tz qx qy qz qw' on one line or a 4x4 matrix (4 lines of 4 numbers)";
  Pose pose = Pose::Identity();
  if (rows.size() == 1 && rows[0].size() == 7) {
    const std::vector<double>& v = rows[0];
    const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
    if (!(std::abs(q.norm() - 1.0) <= kQuaternionNormTolerance)) {
      throw Error(line_prefix(file, row_lines[0]) + "quaternion (qx qy qz qw) has norm " +
                  format_number(q.norm(), 6) + ", expected a unit quaternion");
    }
    pose.linear() = q.normalized().toRotationMatrix();
    pose.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    return pose;
  }
  if (rows.size() != 3 && rows.size() != 4) {
    throw Error(file.string() + ": " + form + ", got " + std::to_string(rows.size()) + " lines");
  }
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
  for (size_t r = 0; r < rows.size(); ++r) {
    if (rows[r].size() != 4) {
      throw Error(line_prefix(file, row_lines[r]) + form + ", got " +
                  std::to_string(rows[r].size()) + " numbers on this line");
    }
    for (size_t c = 0; c < 4; ++c) matrix(static_cast<int>(r), static_cast<int>(c)) = rows[r][c];
  }
  if (rows.size() == 4 && !matrix.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1), 1e-9)) {
    throw Error(line_prefix(file, row_lines[3]) + "the last row of a rigid transform is 0 0 0 1");
  }
  const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
  const double orthonormal_error =
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(orthonormal_error <= 1e-3) || !(rotation.determinant() > 0.0)) {
    throw Error(file.string() + ": the 3x3 part is not a rotation (R^T R differs from I by " +
                format_number(orthonormal_error, 6) + ", det " +
                format_number(rotation.determinant(), 6) + ")");
  }
  // Re-orthonormalise: 4-digit matrices are rotations only up to rounding.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  pose.linear() = svd.matrixU() * svd.matrixV().transpose();
  pose.translation() = matrix.topRightCorner<3, 1>();
  return pose;
}

Trajectory body_to_camera(const Trajectory& ground_truth, const Pose& T_body_camera) {
  Trajectory camera = ground_truth;
  for (StampedPose& pose : camera) pose.T_world_camera = pose.T_world_camera * T_body_camera;
  return camera;
}

std::string format_tum_pose(const StampedPose& pose) {
  const Eigen::Vector3d t = pose.T_world_camera.translation();
  const Eigen::Quaterniond q(pose.T_world_camera.rotation());
  // Shortest text that parses back to the same double: exact round trip, and input timestamps
  // such as 1548339819.87426 are written exactly as the dataset lists them.
  char buffer[64];
  std::string line;
  line.reserve(160);
  auto append = [&](double value, std::chars_format format) {
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value, format);
    line.append(buffer, result.ptr);
  };
  append(pose.timestamp, std::chars_format::fixed);
  for (const double v : {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}) {
    line += ' ';
    append(v, std::chars_format::general);
  }
  return line;
}

void write_tum_trajectory(const std::filesystem::path& file, const Trajectory& trajectory) {
  TrajectoryWriter writer(file);
  for (const StampedPose& pose : trajectory) writer.write(pose);
}

TrajectoryWriter::TrajectoryWriter(const std::filesystem::path& file) : path_(file) {
  if (file.has_parent_path()) {
    std::error_code ignored;
    std::filesystem::create_directories(file.parent_path(), ignored);
  }
  stream_.open(file, std::ios::out | std::ios::trunc);
  if (!stream_) throw Error(file.string() + ": cannot write trajectory file");
  stream_ << kTrajectoryHeader << '\n';
  stream_.flush();
}

void TrajectoryWriter::clear() {
  stream_.close();
  stream_.open(path_, std::ios::out | std::ios::trunc);
  if (!stream_) throw Error(path_.string() + ": cannot write trajectory file");
  stream_ << kTrajectoryHeader << '\n';
  stream_.flush();
  count_ = 0;
}

void TrajectoryWriter::write(const StampedPose& pose) {
  // One complete line per write + flush: a kill between two writes leaves only whole lines.
  const std::string line = format_tum_pose(pose) + '\n';
  stream_.write(line.data(), static_cast<std::streamsize>(line.size()));
  stream_.flush();
  if (!stream_) throw Error(path_.string() + ": cannot write trajectory file (disk full?)");
  ++count_;
}

Trajectory read_kitti_trajectory(const std::filesystem::path& file,
                                 const std::vector<Timestamp>& timestamps) {
  Trajectory trajectory;
  for_each_data_line(file, "KITTI poses", [&](const TextLine& line) {
    if (line.fields.size() != 12) {
      throw Error(line_prefix(file, line.line) + "expected 12 numbers (3x4 pose, row-major), got " +
                  std::to_string(line.fields.size()));
    }
    if (trajectory.size() >= timestamps.size()) {
      throw Error(line_prefix(file, line.line) + "more poses than the " +
                  std::to_string(timestamps.size()) + " timestamps of times.txt");
    }
    Eigen::Matrix<double, 3, 4> m;
    for (int k = 0; k < 12; ++k) {
      m(k / 4, k % 4) =
          parse_number(line.fields[static_cast<size_t>(k)], file, line.line, "pose entry");
    }
    const Eigen::Matrix3d r = m.leftCols<3>();
    if (!(r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-3)) {
      throw Error(line_prefix(file, line.line) + "the rotation is not orthonormal");
    }
    Pose pose = Pose::Identity();
    pose.linear() = Eigen::Quaterniond(r).normalized().toRotationMatrix();
    pose.translation() = m.col(3);
    trajectory.push_back({timestamps[trajectory.size()], pose});
  });
  if (trajectory.size() != timestamps.size()) {
    throw Error(file.string() + ": " + std::to_string(trajectory.size()) + " poses for " +
                std::to_string(timestamps.size()) + " timestamps in times.txt");
  }
  return trajectory;
}

void write_kitti_trajectory(const std::filesystem::path& file, const Trajectory& trajectory) {
  std::ofstream out(file);
  if (!out) throw Error(file.string() + ": cannot write trajectory file");
  char line[512];
  for (const StampedPose& stamped : trajectory) {
    // + 0.0 turns -0 into 0: the same pose always prints the same bytes.
    const Eigen::Matrix4d m = stamped.T_world_camera.matrix().array() + 0.0;
    std::snprintf(line, sizeof(line),
                  "%.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e\n", m(0, 0), m(0, 1),
                  m(0, 2), m(0, 3), m(1, 0), m(1, 1), m(1, 2), m(1, 3), m(2, 0), m(2, 1), m(2, 2),
                  m(2, 3));
    out << line;
  }
  if (!out) throw Error(file.string() + ": failed writing trajectory file");
}

}  // namespace pspslam
