#include "pspslam/dynamic/dynamic_mode.h"

#include "pspslam/core/error.h"

namespace pspslam {

const char* to_string(DynamicMode mode) {
  switch (mode) {
    case DynamicMode::off:
      return "off";
    case DynamicMode::semantic:
      return "semantic";
    case DynamicMode::geometry:
      return "geometry";
    case DynamicMode::full:
      return "full";
    case DynamicMode::exhaustive:
      return "exhaustive";
  }
  return "?";
}

DynamicMode parse_dynamic_mode(const std::string& text, const std::string& flag) {
  for (const DynamicMode mode : {DynamicMode::off, DynamicMode::semantic, DynamicMode::geometry,
                                 DynamicMode::full, DynamicMode::exhaustive}) {
    if (text == to_string(mode)) return mode;
  }
  throw Error(flag + ": unknown mode '" + text +
              "' (expected off, semantic, geometry, full or exhaustive)");
}

}  // namespace pspslam
