// PLY point clouds (what --export-map writes; read back by `view` and the tests).
#include "fuzz_input.h"
#include "pspslam/io/point_cloud_ply.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pspslam;
  const auto file = fuzz::scratch().write("cloud.ply", fuzz::as_text(data, size));
  fuzz::expect_clean([&] { read_point_cloud_ply(file); });
  return 0;
}
