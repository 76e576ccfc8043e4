#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "pspslam/core/types.h"

namespace pspslam {

// Largest accepted | |q| - 1 | of a quaternion read from a file. TUM files print 4-6 significant
// digits, so the norm of a valid quaternion can be off by ~1e-5; anything beyond 1e-3 is a
// corrupt or mis-ordered line, not rounding.
inline constexpr double kQuaternionNormTolerance = 1e-3;

// Reads a TUM trajectory: one pose per line, `timestamp tx ty tz qx qy qz qw` (camera-to-world),
// `#` comments and blank lines ignored, fields separated by spaces, tabs or commas.
// Quaternions are normalised after the tolerance check. Poses are returned in file order.
// Errors (pspslam::Error): "<file>: cannot open trajectory file", and per line
// "<file>:<line>: expected 8 fields ..., got N", "... '<text>' is not a number",
// "... quaternion ... has norm X, expected a unit quaternion", "... timestamp ... repeats line N".
Trajectory read_tum_trajectory(const std::filesystem::path& file);

// Reads one rigid transform: either 7 numbers `tx ty tz qx qy qz qw` (one line) or a 4x4
// matrix (4 lines of 4 numbers, last row 0 0 0 1; a 3x4 matrix is accepted too), `#` comments
// ignored. The rotation must be orthonormal within 1e-3. Errors name the file and line.
Pose read_rigid_transform(const std::filesystem::path& file);

// The ground truth of the camera when `ground_truth` tracks another body (a motion-capture
// marker): every pose becomes T_world_body * T_body_camera.
Trajectory body_to_camera(const Trajectory& ground_truth, const Pose& T_body_camera);

// One TUM line (no newline); every number in its shortest exact form, so reading the line back
// gives the same doubles (timestamps bit-exact; the pose up to the quaternion conversion).
std::string format_tum_pose(const StampedPose& pose);

// The comment written at the top of every trajectory file.
inline constexpr const char* kTrajectoryHeader =
    "# pspslam trajectory: T_world_camera (camera-to-world), TUM format: timestamp tx ty tz qx qy "
    "qz qw";

// Writes a whole trajectory at once (header + one line per pose).
void write_tum_trajectory(const std::filesystem::path& file, const Trajectory& trajectory);

// KITTI odometry poses: one camera-to-world pose per line as 12 numbers, the 3x4 matrix
// [R | t] row by row. KITTI files carry no timestamps: read_kitti_trajectory pairs line i with
// timestamps[i] (times.txt) and needs as many lines as timestamps. Errors name file:line (field
// count, non-numbers, a rotation not orthonormal within 1e-3, too few or too many lines).
Trajectory read_kitti_trajectory(const std::filesystem::path& file,
                                 const std::vector<Timestamp>& timestamps);
// Writes `trajectory` in that format (timestamps dropped, poses in the order given).
void write_kitti_trajectory(const std::filesystem::path& file, const Trajectory& trajectory);

// Writes poses one at a time as they are computed. Every write() reaches the operating system
// before it returns (flush), so if the process is interrupted or killed the file still holds a
// valid trajectory with every pose written so far (a run's partial result stays evaluable).
class TrajectoryWriter {
 public:
  // Creates/truncates `file` (parent directories are created) and writes the header.
  explicit TrajectoryWriter(const std::filesystem::path& file);

  void write(const StampedPose& pose);
  void write(Timestamp timestamp, const Pose& T_world_camera) {
    write({timestamp, T_world_camera});
  }

  size_t count() const { return count_; }
  // Truncates the file back to its header (a monocular map restarted in another world frame:
  // the poses written so far do not belong with the ones to come).
  void clear();

 private:
  std::filesystem::path path_;
  std::ofstream stream_;
  size_t count_ = 0;
};

}  // namespace pspslam
