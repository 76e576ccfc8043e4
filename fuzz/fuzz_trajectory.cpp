// TUM trajectory files (groundtruth.txt, trajectory.txt, eval --gt/--est).
#include "fuzz_input.h"
#include "pspslam/io/trajectory_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pspslam;
  const auto file = fuzz::scratch().write("trajectory.txt", fuzz::as_text(data, size));
  fuzz::expect_clean([&] { read_tum_trajectory(file); });
  return 0;
}
