// The camera/system config YAML (--config, SEQUENCE/config.yaml).
#include "fuzz_input.h"
#include "pspslam/config/config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pspslam;
  const auto file = fuzz::scratch().write("config.yaml", fuzz::as_text(data, size));
  fuzz::expect_clean([&] { load_config(file); });
  return 0;
}
