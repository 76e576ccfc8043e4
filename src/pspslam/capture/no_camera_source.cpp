// Built when libfreenect was not found: --camera is refused with the way to get it.
#include "pspslam/capture/camera_spec.h"
#include "pspslam/core/error.h"

namespace pspslam {

std::unique_ptr<FrameSource> open_camera(const CameraSpec& spec, const CameraOptions&) {
  throw Error("--camera " + spec.text() +
              ": this pspslam was built without libfreenect (install libfreenect-dev, "
              "scripts/install-deps does, and build again)");
}

}  // namespace pspslam
