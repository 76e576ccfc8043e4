// The stereo layouts' text files: the first byte picks which one the rest becomes, written into an
// otherwise valid folder: KITTI times.txt, calib.txt or poses.txt, EuRoC cam0/data.csv or
// cam1/sensor.yaml. Listed images do not exist (the missing-files path).
#include "fuzz_input.h"
#include "pspslam/io/euroc_sequence.h"
#include "pspslam/io/kitti_sequence.h"
#include "pspslam/io/trajectory_io.h"

namespace {

constexpr const char* kSensorYaml =
    "%YAML:1.0\nT_BS:\n  cols: 4\n  rows: 4\n  data: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, "
    "0, 1]\nrate_hz: 20\nresolution: [64, 48]\ncamera_model: pinhole\nintrinsics: [50, 50, 31.5, "
    "23.5]\ndistortion_model: radial-tangential\ndistortion_coefficients: [0, 0, 0, 0]\n";

// cam1 0.1 m to the right of cam0.
constexpr const char* kRightSensorYaml =
    "%YAML:1.0\nT_BS:\n  cols: 4\n  rows: 4\n  data: [1, 0, 0, 0.1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, "
    "0, 1]\nrate_hz: 20\nresolution: [64, 48]\ncamera_model: pinhole\nintrinsics: [50, 50, 31.5, "
    "23.5]\ndistortion_model: radial-tangential\ndistortion_coefficients: [0, 0, 0, 0]\n";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pspslam;
  if (size == 0) return 0;
  const auto& folder = fuzz::scratch();
  const std::string_view text = fuzz::as_text(data + 1, size - 1);
  SequenceOptions options;
  options.warnings = nullptr;
  switch (data[0] % 5) {
    case 0:
      folder.write("times.txt", text);
      fuzz::expect_clean([&] { KittiSequence::open(folder.path(), options); });
      break;
    case 1:
      folder.write("calib.txt", text);
      fuzz::expect_clean([&] { read_kitti_calibration(folder.path() / "calib.txt"); });
      break;
    case 2:
      folder.write("poses.txt", text);
      fuzz::expect_clean([&] {
        read_kitti_trajectory(folder.path() / "poses.txt", {0.0, 0.1, 0.2});
      });
      break;
    case 3:
    case 4: {
      std::filesystem::create_directories(folder.path() / "mav0" / "cam0");
      std::filesystem::create_directories(folder.path() / "mav0" / "cam1");
      folder.write("mav0/cam0/sensor.yaml", kSensorYaml);
      folder.write("mav0/cam1/sensor.yaml",
                   data[0] % 5 == 4 ? text : std::string_view(kRightSensorYaml));
      folder.write("mav0/cam0/data.csv", data[0] % 5 == 3 ? text : "1,1.png\n");
      folder.write("mav0/cam1/data.csv", "1,1.png\n");
      fuzz::expect_clean([&] { EurocSequence::open(folder.path(), options); });
      break;
    }
  }
  return 0;
}
