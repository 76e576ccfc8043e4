#include "pspslam/core/version.h"

#include "git_revision.h"  // generated at build time (cmake/git_revision.cmake)

namespace pspslam {

std::string version_string() {
  return std::string("pspslam ") + PSPSLAM_VERSION + " (git " + PSPSLAM_GIT_REVISION + ")";
}

}  // namespace pspslam
