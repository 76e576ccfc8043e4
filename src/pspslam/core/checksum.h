#pragma once

#include <cstddef>
#include <cstdint>
#include <iomanip>
#include <sstream>
#include <string>

namespace pspslam {

// 64-bit FNV-1a over a byte range: the checksum of the project's binary files (vocabulary, map).
// It detects corruption and truncation, not tampering.
inline std::uint64_t fnv1a64(const char* data, std::size_t size) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= static_cast<std::uint8_t>(data[i]);
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

// "0x" + 16 hex digits, for checksums in error messages.
inline std::string hex64(std::uint64_t value) {
  std::ostringstream out;
  out << "0x" << std::hex << std::setw(16) << std::setfill('0') << value;
  return out.str();
}

}  // namespace pspslam
