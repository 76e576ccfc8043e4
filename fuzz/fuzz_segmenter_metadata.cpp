// The segmentation model's metadata YAML (--model).
#include "fuzz_input.h"
#include "pspslam/semantic/segmenter_metadata.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pspslam;
  const auto file = fuzz::scratch().write("model.yaml", fuzz::as_text(data, size));
  fuzz::expect_clean([&] { load_segmenter_metadata(file); });
  return 0;
}
