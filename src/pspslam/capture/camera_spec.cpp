#include "pspslam/capture/camera_spec.h"

#include <unistd.h>

#include <charconv>
#include <cstdio>
#include <fstream>
#include <system_error>

#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"

namespace pspslam {
namespace {

std::string read_word(const std::filesystem::path& file) {
  std::ifstream stream(file);
  std::string word;
  stream >> word;
  return word;
}

}  // namespace

CameraSpec parse_camera_spec(const std::string& text) {
  const size_t colon = text.find(':');
  CameraSpec spec;
  spec.driver = text.substr(0, colon);
  if (spec.driver != "freenect") {
    throw Error("--camera: unknown camera driver '" + spec.driver +
                "' (supported: freenect, a Kinect v1 through libfreenect)");
  }
  if (colon != std::string::npos) {
    const std::string index = text.substr(colon + 1);
    const char* end = index.data() + index.size();
    const auto [stop, status] = std::from_chars(index.data(), end, spec.index);
    if (index.empty() || status != std::errc() || stop != end || spec.index < 0) {
      throw Error("--camera: '" + text + "': INDEX must be a device number (0, 1, ...)");
    }
  }
  return spec;
}

std::filesystem::path camera_config_preset(const CameraSpec&) {
  return data_dir() / "config" / "kinect_v1.yaml";
}

std::vector<UsbCameraNode> find_kinect_cameras(const std::filesystem::path& sysfs_devices,
                                               const std::filesystem::path& dev_root) {
  std::vector<UsbCameraNode> nodes;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(sysfs_devices, ec)) {
    const std::filesystem::path& dir = entry.path();
    if (read_word(dir / "idVendor") != "045e" || read_word(dir / "idProduct") != "02ae") continue;
    const std::string bus = read_word(dir / "busnum");
    const std::string device = read_word(dir / "devnum");
    if (bus.empty() || device.empty()) continue;
    char name[32];
    std::snprintf(name, sizeof(name), "%03d/%03d", std::atoi(bus.c_str()),
                  std::atoi(device.c_str()));
    const std::filesystem::path file = dev_root / name;
    nodes.push_back({file.string(), ::access(file.c_str(), R_OK | W_OK) == 0});
  }
  return nodes;
}

std::string explain_camera_failure(int index, int devices_seen,
                                   const std::vector<UsbCameraNode>& nodes) {
  const std::string camera = "--camera freenect:" + std::to_string(index);
  for (const UsbCameraNode& node : nodes) {
    if (node.accessible) continue;
    return camera + ": permission denied on the Kinect's USB device " + node.device_file +
           ": install the udev rule that Debian's libfreenect0.5 ships "
           "(/lib/udev/rules.d/60-libfreenect0.5.rules: MODE 0666, GROUP plugdev; then "
           "`sudo udevadm control --reload && sudo udevadm trigger` and replug the Kinect) "
           "or add yourself to the plugdev group (`sudo usermod -aG plugdev $USER`, log in again)";
  }
  if (devices_seen == 0) {
    if (nodes.empty()) {
      return camera +
             ": no Kinect v1 found (libfreenect sees no device and the USB bus lists no "
             "045e:02ae 'Xbox NUI Camera'): is it plugged in and on its own power supply?";
    }
    return camera + ": the USB bus lists a Kinect camera (" + nodes.front().device_file +
           ") but libfreenect sees no device: unplug it and plug it in again";
  }
  if (index >= devices_seen) {
    return camera + ": only " + std::to_string(devices_seen) + " Kinect" +
           (devices_seen == 1 ? "" : "s") + " found (indices 0.." +
           std::to_string(devices_seen - 1) + ")";
  }
  return camera +
         ": libfreenect cannot open the Kinect (is another program using it? a Kinect for "
         "Windows or model 1473 may need newer firmware support)";
}

}  // namespace pspslam
