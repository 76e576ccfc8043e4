#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "pspslam/io/recorded_sequence.h"

namespace pspslam::testing {

// The folder layout libfreenect's replay library fakenect plays back in place of a Kinect
// (FAKENECT_PATH=DIR, LD_LIBRARY_PATH=<libdir>/fakenect): DIR/INDEX.txt lists one file per line,
// in playing order, named `<type>-<record time s>-<device ticks>-<anything>`; fakenect sleeps
// between lines as the record times say, skips the first text line of a file and hands the rest
// to the callback as the device buffer: `d` 640x480 uint16 raw 11-bit disparity (the buffer in
// host byte order, although the header says PGM), `r` 640x480 RGB. This writes a sequence's
// frames as such a dump: depth converted to raw disparity with kinect_metres_to_raw, device
// ticks at 60 MHz from the sequence's timestamps starting at `first_ticks` (so a dump can make
// the 32-bit counter wrap), played one frame every `interval_s`.
struct FakenectDumpOptions {
  size_t frames = 0;  // 0 = all
  double interval_s = 1.0 / 30.0;
  uint32_t first_ticks = 0;
  // The replay stalls this long after frame `pause_after` (a camera that hangs); 0 = never.
  size_t pause_after = 0;
  double pause_s = 0.0;
};

void write_fakenect_dump(const RecordedSequence& sequence, const std::filesystem::path& dir,
                         const FakenectDumpOptions& options = {});

// The environment prefix that makes a command run against the dump instead of a device.
std::string fakenect_environment(const std::filesystem::path& dump);

// The directory that holds fakenect's libfreenect, empty when it is not installed.
std::filesystem::path fakenect_library_dir();

}  // namespace pspslam::testing
