// The bag-of-words vocabulary file (--vocabulary). Checksummed like the map file: the first
// input byte picks 0 = the bytes are the whole file, 1 = the next 20 bytes are the header's
// k, L, node count, word count and training images, the rest the payload, written behind a
// valid magic, version, size and checksum (so the tree-shape checks are reached).
#include <cstring>

#include "fuzz_input.h"
#include "pspslam/core/checksum.h"
#include "pspslam/place/vocabulary.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pspslam;
  if (size == 0) return 0;
  const std::string_view body = fuzz::as_text(data + 1, size - 1);
  std::string file_bytes;
  if (data[0] % 2 == 0 || body.size() < 20) {
    file_bytes = body;
  } else {
    const std::string_view shape = body.substr(0, 20);
    const std::string_view payload = body.substr(20);
    file_bytes = "PSPVOCAB";
    const std::uint32_t version = 1;
    const std::uint64_t payload_bytes = payload.size();
    const std::uint64_t checksum = fnv1a64(payload.data(), payload.size());
    file_bytes.append(reinterpret_cast<const char*>(&version), 4);
    file_bytes += shape;
    file_bytes.append(reinterpret_cast<const char*>(&payload_bytes), 8);
    file_bytes.append(reinterpret_cast<const char*>(&checksum), 8);
    file_bytes += payload;
  }
  const auto file = fuzz::scratch().write("words.pspvoc", file_bytes);
  fuzz::expect_clean([&] { Vocabulary::load(file); });
  return 0;
}
