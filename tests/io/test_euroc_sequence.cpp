#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "pspslam/core/error.h"
#include "pspslam/io/euroc_calibration.h"
#include "pspslam/io/euroc_sequence.h"
#include "pspslam/io/sequence_setup.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

namespace fs = std::filesystem;

using testing::error_of;
using testing::write_text;

constexpr int kWidth = 200;
constexpr int kHeight = 150;

// sensor.yaml as EuRoC writes it (OpenCV's %YAML:1.0 first line included).
std::string sensor_yaml(const Pose& T_BS, const std::string& distortion) {
  std::ostringstream out;
  out << "%YAML:1.0\n"
      << "sensor_type: camera\ncomment: test camera\n"
      << "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  const Eigen::Matrix4d m = T_BS.matrix();
  for (int k = 0; k < 16; ++k) out << (k ? ", " : "") << m(k / 4, k % 4);
  out << "]\nrate_hz: 20\nresolution: [" << kWidth << ", " << kHeight << "]\n"
      << "camera_model: pinhole\nintrinsics: [150.0, 151.0, 99.5, 74.5]\n"
      << "distortion_model: radial-tangential\ndistortion_coefficients: " << distortion << "\n";
  return out.str();
}

// cam1 0.11 m to the right of cam0, turned 1 degree about y, both with radial distortion.
Pose right_in_body() {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(0.0175, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.11, 0.002, 0.0);
  return T;
}

constexpr const char* kDistortion = "[-0.2, 0.05, 0.0005, -0.0003]";

// A small EuRoC folder: `frames` pairs at 20 Hz, ground truth of the body.
fs::path make_euroc(const std::string& tag, int frames = 3) {
  const fs::path dir = testing::make_temp_dir(tag);
  const fs::path mav = dir / "mav0";
  for (const char* cam : {"cam0", "cam1"}) {
    fs::create_directories(mav / cam / "data");
    std::string list = "#timestamp [ns],filename\n";
    for (int i = 0; i < frames; ++i) {
      const std::string stamp = std::to_string(1403636579763555584LL + 50000000LL * i);
      cv::imwrite((mav / cam / "data" / (stamp + ".png")).string(),
                  cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(40 + i)));
      list += stamp + "," + stamp + ".png\n";
    }
    write_text(mav / cam / "data.csv", list);
  }
  write_text(mav / "cam0" / "sensor.yaml", sensor_yaml(Pose::Identity(), kDistortion));
  write_text(mav / "cam1" / "sensor.yaml", sensor_yaml(right_in_body(), kDistortion));
  fs::create_directories(mav / "state_groundtruth_estimate0");
  std::string gt = "#timestamp, p_RS_R_x [m], ...\n";
  for (int i = 0; i < frames; ++i) {
    gt += std::to_string(1403636579763555584LL + 50000000LL * i) + "," + std::to_string(i) +
          ",2,3,1,0,0,0,0,0,0,0,0,0,0,0,0\n";
  }
  write_text(mav / "state_groundtruth_estimate0" / "data.csv", gt);
  return dir;
}

SequenceOptions quiet() {
  SequenceOptions options;
  options.warnings = nullptr;
  return options;
}

TEST(EurocSequence, ReadsRectifiesAndMovesTheGroundTruthOntoTheCamera) {
  const fs::path dir = make_euroc("euroc_ok");
  const SequenceSetup setup = open_sequence_with_config(dir, std::nullopt, nullptr);
  const RecordedSequence& sequence = *setup.sequence;
  ASSERT_EQ(sequence.size(), 3u);
  EXPECT_EQ(sequence.layout(), SequenceLayout::euroc);
  EXPECT_NEAR(sequence.timestamp(1), 1403636579.813555584, 1e-6);
  const CameraConfig& camera = setup.config.camera;
  EXPECT_EQ(camera.type, SensorType::stereo);
  EXPECT_EQ(camera.pinhole.width, kWidth);
  EXPECT_FALSE(camera.pinhole.has_distortion());
  // The baseline is the distance between the camera centres (0.11, 0.002, 0).
  EXPECT_NEAR(camera.baseline, std::hypot(0.11, 0.002), 1e-9);
  EXPECT_DOUBLE_EQ(camera.fps, 20.0);
  const InputFrame frame = sequence.load(2);
  EXPECT_EQ(frame.right.size(), cv::Size(kWidth, kHeight));
  EXPECT_EQ(frame.gray.at<uint8_t>(kHeight / 2, kWidth / 2), 42);
  ASSERT_TRUE(sequence.ground_truth());
  ASSERT_EQ(sequence.ground_truth()->size(), 3u);
  EXPECT_TRUE(sequence.ground_truth()->at(2).T_world_camera.translation().isApprox(
      Eigen::Vector3d(2, 2, 3), 1e-9));
}

// Dots at the projections of known 3D points in the two raw (distorted, rotated) images land
// on one row after rectification, at the disparity fx * baseline / z.
TEST(EurocSequence, RectifiedRowsAgreeAndDisparityMatchesDepth) {
  const fs::path dir = make_euroc("euroc_rect");
  const fs::path mav = dir / "mav0";
  const EurocCamera left = read_euroc_camera(mav / "cam0" / "sensor.yaml");
  const EurocCamera right = read_euroc_camera(mav / "cam1" / "sensor.yaml");
  const StereoRectification rect = StereoRectification::compute(left, right, "test");
  const Pose T_right_left = right.T_body_camera.inverse() * left.T_body_camera;
  for (const Eigen::Vector3d& X :
       {Eigen::Vector3d(0.1, -0.05, 1.5), Eigen::Vector3d(-0.3, 0.2, 3.0),
        Eigen::Vector3d(0.4, 0.25, 2.2)}) {
    cv::Mat raw_left(kHeight, kWidth, CV_8UC1, cv::Scalar(0));
    cv::Mat raw_right = raw_left.clone();
    const auto draw = [](cv::Mat& image, const EurocCamera& camera, const Eigen::Vector3d& p) {
      std::vector<cv::Point3d> points{{p.x(), p.y(), p.z()}};
      std::vector<cv::Point2d> pixels;
      cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cv::Mat(camera.K),
                        camera.distortion, pixels);
      cv::circle(image, cv::Point(cvRound(pixels[0].x * 16), cvRound(pixels[0].y * 16)), 3 * 16,
                 cv::Scalar(255), cv::FILLED, cv::LINE_AA, 4);
    };
    draw(raw_left, left, X);
    draw(raw_right, right, T_right_left * X);
    cv::Mat rect_left, rect_right;
    rect.rectify(raw_left, raw_right, rect_left, rect_right);
    const cv::Moments ml = cv::moments(rect_left), mr = cv::moments(rect_right);
    ASSERT_GT(ml.m00, 0.0);
    ASSERT_GT(mr.m00, 0.0);
    const double row_left = ml.m01 / ml.m00, row_right = mr.m01 / mr.m00;
    const double disparity = ml.m10 / ml.m00 - mr.m10 / mr.m00;
    const double z = (rect.R_rect_left * X).z();
    EXPECT_NEAR(row_left, row_right, 0.3);
    EXPECT_NEAR(disparity, rect.fx * rect.baseline / z, 0.3);
  }
}

// cam0 alone (a monocular run): a dot at the projection of a known 3D point in the raw,
// distorted image lands, once the frame is loaded, at its pinhole projection by the camera the
// sequence reports; the ground truth is cam0's.
TEST(EurocSequence, Cam0AloneIsUndistortedOntoItsReportedCamera) {
  const fs::path dir = make_euroc("euroc_mono");
  const fs::path mav = dir / "mav0";
  fs::remove_all(mav / "cam1");
  const EurocCamera left = read_euroc_camera(mav / "cam0" / "sensor.yaml");
  const Eigen::Vector3d X(0.3, -0.2, 1.5);
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(std::vector<cv::Point3d>{{X.x(), X.y(), X.z()}}, cv::Vec3d(0, 0, 0),
                    cv::Vec3d(0, 0, 0), cv::Mat(left.K), left.distortion, pixels);
  cv::Mat raw(kHeight, kWidth, CV_8UC1, cv::Scalar(0));
  cv::circle(raw, cv::Point(cvRound(pixels[0].x * 16), cvRound(pixels[0].y * 16)), 3 * 16,
             cv::Scalar(255), cv::FILLED, cv::LINE_AA, 4);
  const std::string first = std::to_string(1403636579763555584LL) + ".png";
  cv::imwrite((mav / "cam0" / "data" / first).string(), raw);

  const SequenceSetup setup = open_sequence_with_config(dir, std::nullopt, nullptr);
  const RecordedSequence& sequence = *setup.sequence;
  EXPECT_EQ(sequence.sensor(), SensorType::monocular);
  ASSERT_EQ(sequence.size(), 3u);
  const CameraConfig& camera = setup.config.camera;
  EXPECT_EQ(camera.type, SensorType::monocular);
  EXPECT_FALSE(camera.pinhole.has_distortion());
  EXPECT_EQ(camera.pinhole.width, kWidth);
  const cv::Mat gray = sequence.load(0).gray;
  const cv::Moments m = cv::moments(gray);
  ASSERT_GT(m.m00, 0.0);
  EXPECT_NEAR(m.m10 / m.m00, camera.pinhole.fx * X.x() / X.z() + camera.pinhole.cx, 0.3);
  EXPECT_NEAR(m.m01 / m.m00, camera.pinhole.fy * X.y() / X.z() + camera.pinhole.cy, 0.3);
  ASSERT_TRUE(sequence.ground_truth());
  EXPECT_TRUE(sequence.ground_truth()->at(2).T_world_camera.isApprox(
      Pose(Eigen::Translation3d(2, 2, 3)), 1e-9));
}

TEST(EurocSequence, MalformedFilesNameFileLineAndKey) {
  const fs::path dir = make_euroc("euroc_bad");
  const fs::path mav = dir / "mav0";
  write_text(mav / "cam0" / "data.csv", "#timestamp [ns],filename\n1,1.png\n2\n");
  EXPECT_EQ(error_of([&] { EurocSequence::open(dir, quiet()); }),
            (mav / "cam0" / "data.csv").string() +
                ":3: expected 'timestamp [ns],filename', got 1 fields");
  write_text(mav / "cam0" / "data.csv", "#timestamp [ns],filename\nx,1.png\n");
  EXPECT_EQ(error_of([&] { EurocSequence::open(dir, quiet()); }),
            (mav / "cam0" / "data.csv").string() + ":2: timestamp 'x' is not a number");

  std::string yaml = sensor_yaml(Pose::Identity(), kDistortion);
  std::string short_intrinsics = yaml;
  short_intrinsics.replace(short_intrinsics.find("intrinsics: [150.0, 151.0, 99.5, 74.5]"), 38,
                           "intrinsics: [150.0, 151.0, 99.5]");
  write_text(mav / "cam1" / "sensor.yaml", short_intrinsics);
  EXPECT_EQ(
      error_of([&] { read_euroc_camera(mav / "cam1" / "sensor.yaml"); }),
      (mav / "cam1" / "sensor.yaml").string() + ":11: key 'intrinsics' must list 4 values, got 3");
  write_text(mav / "cam1" / "sensor.yaml", yaml.substr(0, yaml.find("T_BS")));
  EXPECT_EQ(error_of([&] { read_euroc_camera(mav / "cam1" / "sensor.yaml"); }),
            (mav / "cam1" / "sensor.yaml").string() + ": missing key 'camera_model'");
  Pose above = Pose::Identity();
  above.translation() = Eigen::Vector3d(0.0, 0.11, 0.0);
  write_text(mav / "cam1" / "sensor.yaml", sensor_yaml(above, kDistortion));
  EXPECT_NE(error_of([&] {
              EurocSequence::open(dir, quiet());
            }).find("the right camera is above or below the left one (a vertical pair)"),
            std::string::npos);

  write_text(mav / "cam1" / "sensor.yaml", sensor_yaml(Pose::Identity(), kDistortion));
  EXPECT_NE(error_of([&] {
              EurocSequence::open(dir, quiet());
            }).find("the two cameras are at the same place (T_BS): no stereo baseline"),
            std::string::npos);

  const fs::path empty = testing::make_temp_dir("euroc_empty");
  EXPECT_EQ(error_of([&] { EurocSequence::open(empty, quiet()); }),
            empty.string() +
                ": no mav0/cam0/data.csv (an EuRoC MAV sequence needs mav0/cam0, and mav0/cam1 "
                "for stereo, each with data.csv, data/ and sensor.yaml)");
}

TEST(EurocSequence, MissingImagesAreCountedOnce) {
  const fs::path dir = make_euroc("euroc_missing", 4);
  const fs::path data = dir / "mav0" / "cam1" / "data";
  fs::remove(data / (std::to_string(1403636579763555584LL + 50000000LL) + ".png"));
  std::ostringstream warnings;
  SequenceOptions options;
  options.warnings = &warnings;
  const EurocSequence sequence = EurocSequence::open(dir, options);
  EXPECT_EQ(sequence.size(), 3u);
  EXPECT_EQ(sequence.missing_files(), 1u);
  EXPECT_NE(warnings.str().find("1 listed files are missing; skipped 1 frames (first: "
                                "cam1/data/1403636579813555584.png)"),
            std::string::npos)
      << warnings.str();
}

}  // namespace
}  // namespace pspslam
