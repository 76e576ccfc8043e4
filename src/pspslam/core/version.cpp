#include "pspslam/core/version.h"

namespace pspslam {

std::string version_string() {
  return std::string("pspslam ") + PSPSLAM_VERSION + " (git " + PSPSLAM_GIT_REVISION + ")";
}

}  // namespace pspslam
