// The TUM/Bonn frame lists: rgb.txt + depth.txt (associated by time stamp) or associations.txt.
// The first byte picks the layout; for the first, the rest is split at the first NUL byte into
// rgb.txt and depth.txt. The listed images do not exist, so the reader also meets its
// "missing files" path.
#include "fuzz_input.h"
#include "pspslam/io/tum_sequence.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pspslam;
  if (size == 0) return 0;
  const auto& folder = fuzz::scratch();
  const std::string_view text = fuzz::as_text(data + 1, size - 1);
  std::filesystem::remove(folder.path() / "rgb.txt");
  std::filesystem::remove(folder.path() / "depth.txt");
  std::filesystem::remove(folder.path() / "associations.txt");
  if (data[0] % 2 == 0) {
    const size_t split = text.find('\0');
    folder.write("rgb.txt", text.substr(0, split));
    folder.write("depth.txt", split == std::string_view::npos ? "" : text.substr(split + 1));
  } else {
    folder.write("associations.txt", text);
  }
  SequenceOptions options;
  options.warnings = nullptr;
  fuzz::expect_clean([&] { TumSequence::open(folder.path(), options); });
  return 0;
}
