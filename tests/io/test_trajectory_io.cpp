#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <fstream>
#include <sstream>

#include "pspslam/core/error.h"
#include "pspslam/io/trajectory_io.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

std::filesystem::path write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file) << text;
  return file;
}

std::string read_error(const std::filesystem::path& file) {
  try {
    read_tum_trajectory(file);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

Trajectory make_trajectory(size_t count) {
  Trajectory trajectory;
  for (size_t i = 0; i < count; ++i) {
    StampedPose pose;
    pose.timestamp = 1548339819.87426 + 0.0333 * static_cast<double>(i);
    pose.T_world_camera.linear() =
        Eigen::AngleAxisd(0.1 * static_cast<double>(i), Eigen::Vector3d(1, 2, 3).normalized())
            .toRotationMatrix();
    pose.T_world_camera.translation() =
        Eigen::Vector3d(0.5 * static_cast<double>(i), -1.25, 0.001 * static_cast<double>(i * i));
    trajectory.push_back(pose);
  }
  return trajectory;
}

void expect_same(const Trajectory& a, const Trajectory& b, double tolerance) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].timestamp, b[i].timestamp) << i;
    EXPECT_LT((a[i].T_world_camera.matrix() - b[i].T_world_camera.matrix()).cwiseAbs().maxCoeff(),
              tolerance)
        << i;
  }
}

TEST(TrajectoryIo, RoundTrip) {
  const auto dir = testing::make_temp_dir("trajectory");
  const Trajectory original = make_trajectory(50);
  write_tum_trajectory(dir / "sub" / "trajectory.txt", original);
  std::ifstream stream(dir / "sub" / "trajectory.txt");
  std::string header;
  std::getline(stream, header);
  EXPECT_EQ(header, kTrajectoryHeader);
  EXPECT_NE(header.find("camera-to-world"), std::string::npos);
  // Timestamps bit-exact; matrices up to the rotation -> quaternion -> rotation conversion.
  expect_same(read_tum_trajectory(dir / "sub" / "trajectory.txt"), original, 1e-12);
}

TEST(TrajectoryIo, ReadsCommentsBlankLinesTabsAndCommas) {
  const auto dir = testing::make_temp_dir("trajectory");
  const auto file =
      write_text(dir / "t.txt",
                 "# ground truth\n\n1.5 1 2 3 0 0 0 1\n"
                 "  \n2.5,4,5,6,0,0,0.7071068,0.7071068\r\n3.5\t0\t0\t0\t0\t0\t0\t1\n");
  const Trajectory trajectory = read_tum_trajectory(file);
  ASSERT_EQ(trajectory.size(), 3u);
  EXPECT_EQ(trajectory[0].timestamp, 1.5);
  EXPECT_EQ(trajectory[1].T_world_camera.translation(), Eigen::Vector3d(4, 5, 6));
  // 90 degrees about z, normalised.
  EXPECT_NEAR((trajectory[1].T_world_camera.rotation() * Eigen::Vector3d::UnitX() -
               Eigen::Vector3d::UnitY())
                  .norm(),
              0.0, 1e-12);
}

TEST(TrajectoryIo, MalformedLinesNameFileAndLine) {
  const auto dir = testing::make_temp_dir("trajectory");
  const std::string good = "# comment\n1.0 0 0 0 0 0 0 1\n";
  const auto fields = write_text(dir / "fields.txt", good + "2.0 0 0 0 0 0 1\n");
  EXPECT_EQ(read_error(fields),
            fields.string() + ":3: expected 8 fields 'timestamp tx ty tz qx qy qz qw', got 7");
  const auto text = write_text(dir / "text.txt", good + "2.0 0 zero 0 0 0 0 1\n");
  EXPECT_EQ(read_error(text), text.string() + ":3: ty 'zero' is not a number");
  const auto stamp = write_text(dir / "stamp.txt", good + "2.0s 0 0 0 0 0 0 1\n");
  EXPECT_EQ(read_error(stamp), stamp.string() + ":3: timestamp '2.0s' is not a number");
  const auto quaternion = write_text(dir / "quaternion.txt", good + "2.0 0 0 0 0 0 0 0.5\n");
  EXPECT_EQ(read_error(quaternion),
            quaternion.string() +
                ":3: quaternion (qx qy qz qw) has norm 0.500000, expected a unit quaternion");
  const auto nan = write_text(dir / "nan.txt", good + "2.0 nan 0 0 0 0 0 1\n");
  EXPECT_EQ(read_error(nan), nan.string() + ":3: tx 'nan' is not finite");
  const auto repeated = write_text(dir / "repeated.txt", good + "\n1.0 0 0 0 0 0 0 1\n");
  EXPECT_EQ(read_error(repeated), repeated.string() + ":4: timestamp 1.0 repeats line 2");
  EXPECT_EQ(read_error(dir / "absent.txt"),
            (dir / "absent.txt").string() + ": cannot open trajectory file");
}

TEST(TrajectoryIo, AcceptsRoundingOfSixDigitQuaternions) {
  const auto dir = testing::make_temp_dir("trajectory");
  // Bonn ground truth line: the printed quaternion has norm 1 - 4e-7.
  const auto file = write_text(
      dir / "t.txt",
      "1548339819.89427 -0.194787 -1.44487 1.46988 0.163205 0.0885024 -0.227926 -0.955814\n");
  const Trajectory trajectory = read_tum_trajectory(file);
  ASSERT_EQ(trajectory.size(), 1u);
  EXPECT_NEAR(trajectory[0].T_world_camera.rotation().determinant(), 1.0, 1e-12);
}

TEST(TrajectoryWriter, EveryPoseIsOnDiskAsSoonAsWritten) {
  const auto dir = testing::make_temp_dir("trajectory");
  const Trajectory poses = make_trajectory(4);
  TrajectoryWriter writer(dir / "live.txt");
  for (size_t i = 0; i < poses.size(); ++i) {
    writer.write(poses[i]);
    // Read while the writer is still open: the file is already a valid trajectory.
    const Trajectory so_far = read_tum_trajectory(dir / "live.txt");
    EXPECT_EQ(so_far.size(), i + 1);
  }
  EXPECT_EQ(writer.count(), 4u);
}

TEST(TrajectoryWriter, KilledProcessLeavesValidFile) {
  const auto dir = testing::make_temp_dir("trajectory");
  const std::filesystem::path file = dir / "killed.txt";
  const Trajectory poses = make_trajectory(7);
  const pid_t child = fork();
  ASSERT_NE(child, -1);
  if (child == 0) {
    TrajectoryWriter writer(file);
    for (const StampedPose& pose : poses) writer.write(pose);
    std::raise(SIGKILL);  // no destructor, no stream close: only what write() flushed survives
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGKILL);
  expect_same(read_tum_trajectory(file), poses, 1e-12);
}

TEST(TrajectoryWriter, UnwritableFileIsAnError) {
  const auto dir = testing::make_temp_dir("trajectory");
  try {
    TrajectoryWriter writer(dir);  // a directory cannot be opened as a file
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), dir.string() + ": cannot write trajectory file");
  }
}

}  // namespace
}  // namespace pspslam

namespace pspslam {
namespace {

std::filesystem::path transform_file(const std::string& name, const std::string& text) {
  return write_text(std::filesystem::temp_directory_path() / ("pspslam_transform_" + name), text);
}

std::string transform_error(const std::filesystem::path& file) {
  try {
    read_rigid_transform(file);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Both forms of a transform file read to the same pose: a 90 degree turn about z and an offset.
TEST(RigidTransform, QuaternionLineAndMatrixAgree) {
  const double h = std::sqrt(0.5);
  const Pose from_line = read_rigid_transform(
      transform_file("line.txt", "# marker to camera\n0.1 -0.02 0.03 0 0 " + std::to_string(h) +
                                     " " + std::to_string(h) + "\n"));
  const Pose from_matrix = read_rigid_transform(
      transform_file("matrix.txt", "0 -1 0 0.1\n1 0 0 -0.02\n0 0 1 0.03\n0 0 0 1\n"));
  EXPECT_TRUE(from_line.isApprox(from_matrix, 1e-6));
  EXPECT_NEAR(from_matrix.translation().x(), 0.1, 1e-12);
  EXPECT_NEAR((from_matrix.linear() * Eigen::Vector3d::UnitX()).y(), 1.0, 1e-12);
}

TEST(RigidTransform, BadFilesNameTheProblem) {
  auto file = transform_file("five.txt", "1 2 3 4 5\n");
  EXPECT_EQ(transform_error(file),
            file.string() +
                ": expected 'tx ty tz qx qy qz qw' on one line or a 4x4 matrix (4 lines of 4 "
                "numbers), got 1 lines");
  file = transform_file("scaled.txt", "2 0 0 0\n0 2 0 0\n0 0 2 0\n0 0 0 1\n");
  EXPECT_EQ(transform_error(file).substr(0, file.string().size() + 32),
            file.string() + ": the 3x3 part is not a rotation");
  file = transform_file("row.txt", "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 1 1\n");
  EXPECT_EQ(transform_error(file),
            file.string() + ":4: the last row of a rigid transform is 0 0 0 1");
  file = transform_file("quat.txt", "0 0 0 0 0 0 2\n");
  EXPECT_EQ(transform_error(file),
            file.string() +
                ":1: quaternion (qx qy qz qw) has norm 2.000000, expected a unit "
                "quaternion");
}

// A marker 10 cm beside the camera: moving the ground truth onto the camera recovers the
// camera's trajectory exactly.
TEST(RigidTransform, BodyToCameraMovesEveryPose) {
  Trajectory camera;
  Pose T_body_camera = Pose::Identity();
  T_body_camera.translation() = Eigen::Vector3d(0.1, 0.0, 0.0);
  T_body_camera.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  Trajectory marker;
  for (int i = 0; i < 5; ++i) {
    StampedPose pose;
    pose.timestamp = i;
    pose.T_world_camera.linear() =
        Eigen::AngleAxisd(0.2 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pose.T_world_camera.translation() = Eigen::Vector3d(i, 0.5 * i, 1.0);
    camera.push_back(pose);
    pose.T_world_camera = pose.T_world_camera * T_body_camera.inverse();
    marker.push_back(pose);
  }
  const Trajectory moved = body_to_camera(marker, T_body_camera);
  ASSERT_EQ(moved.size(), camera.size());
  for (size_t i = 0; i < moved.size(); ++i)
    EXPECT_TRUE(moved[i].T_world_camera.isApprox(camera[i].T_world_camera, 1e-12)) << i;
}

}  // namespace
}  // namespace pspslam
