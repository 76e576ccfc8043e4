#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "pspslam/io/frame_source.h"

namespace pspslam {

// `--camera DRIVER[:INDEX]`. Only `freenect` (Kinect v1 through libfreenect) exists.
struct CameraSpec {
  std::string driver;
  int index = 0;
  std::string text() const { return driver + ":" + std::to_string(index); }
};

// Errors name the flag: "--camera: unknown camera driver 'x' (supported: freenect)",
// "--camera: 'freenect:x': INDEX must be a device number (0, 1, ...)".
CameraSpec parse_camera_spec(const std::string& text);

struct CameraOptions {
  // The stream counts as ended (camera unplugged or hung) after this long without a frame; the
  // first frame may take longer (the device starts its streams).
  double silence_timeout_s = 3.0;
  double first_frame_timeout_s = 10.0;
  // Frames waiting for the SLAM loop; more arrive: the oldest is dropped.
  size_t queue_capacity = 2;
};

// The camera as a FrameSource. Frames: colour CV_8UC3 BGR, depth CV_32FC1 metres registered to
// the colour image, gray filled, timestamps from the device clock (device_clock.h).
// Throws pspslam::Error: no device, index out of range, permission denied on the USB device
// (the message names the udev rule), built without libfreenect.
std::unique_ptr<FrameSource> open_camera(const CameraSpec& spec, const CameraOptions& options = {});

// The camera config preset shipped for the driver (config/kinect_v1.yaml).
std::filesystem::path camera_config_preset(const CameraSpec& spec);

// A Kinect camera node as the USB subsystem lists it.
struct UsbCameraNode {
  std::string device_file;  // /dev/bus/usb/BBB/DDD
  bool accessible = false;  // this process may open it read-write
};

// Kinect v1 cameras (USB 045e:02ae) under `sysfs_devices` (/sys/bus/usb/devices), with their
// device files under `dev_root` (/dev/bus/usb) and whether they can be opened.
std::vector<UsbCameraNode> find_kinect_cameras(
    const std::filesystem::path& sysfs_devices = "/sys/bus/usb/devices",
    const std::filesystem::path& dev_root = "/dev/bus/usb");

// What to tell the user when libfreenect cannot open camera `index` (or sees no device), from
// the USB nodes found: no Kinect on the bus, no permission on its device file (which udev rule
// or group is missing), or busy / other error.
std::string explain_camera_failure(int index, int devices_seen,
                                   const std::vector<UsbCameraNode>& nodes);

}  // namespace pspslam
