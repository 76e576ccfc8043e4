// The binary map file (--load-map). The file is checksummed, so random bytes stop at the
// checksum; the first input byte therefore picks: 0 = the bytes are the whole file (header
// checks), 1 = the bytes are the payload, behind a valid header with its true checksum (so the
// fuzzer reaches the content checks: camera, counts, ids, keypoints, descriptors).
#include <cstring>
#include <memory>

#include "fuzz_input.h"
#include "pspslam/core/checksum.h"
#include "pspslam/map/camera_model.h"
#include "pspslam/map/map.h"
#include "pspslam/map/scale_pyramid.h"
#include "pspslam/persistence/map_file.h"
#include "pspslam/synth/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pspslam;
  if (size == 0) return 0;
  // The camera of `pspslam synth` sequences, which the seed maps were made with.
  static const auto camera = std::make_shared<const CameraModel>(
      CameraModel::from_config(synthetic_camera_config(), 0.08));
  static const auto pyramid =
      std::make_shared<const ScalePyramid>(ScalePyramid::from_config(OrbConfig{}));
  const std::string_view body = fuzz::as_text(data + 1, size - 1);
  std::string file_bytes;
  if (data[0] % 2 == 0) {
    file_bytes = body;
  } else {
    file_bytes = "PSPSLMAP";
    const std::uint32_t version = 1, reserved = 0;
    const std::uint64_t payload_bytes = body.size();
    const std::uint64_t checksum = fnv1a64(body.data(), body.size());
    for (const auto& [value, bytes] : {std::pair<const void*, size_t>{&version, 4},
                                       {&reserved, 4},
                                       {&payload_bytes, 8},
                                       {&checksum, 8}}) {
      file_bytes.append(static_cast<const char*>(value), bytes);
    }
    file_bytes += body;
  }
  const auto file = fuzz::scratch().write("room.map", file_bytes);
  Map map;
  fuzz::expect_clean([&] { load_map(file, map, camera, pyramid); });
  return 0;
}
