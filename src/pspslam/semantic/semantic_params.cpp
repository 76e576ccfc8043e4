#include "pspslam/semantic/semantic_params.h"

namespace pspslam {

SemanticParams SemanticParams::from_yaml(YamlSection& section) {
  SemanticParams p;
  p.enabled = section.optional<bool>("enabled", p.enabled);
  p.model = section.optional<std::string>("model", p.model);
  p.dynamic_classes =
      section.optional<std::vector<std::string>>("dynamic_classes", p.dynamic_classes);
  p.mask_dilation_px = section.optional<int>("mask_dilation_px", p.mask_dilation_px);
  p.queue_size = section.optional<int>("queue_size", p.queue_size);
  p.history = section.optional<int>("history", p.history);
  section.finish();
  auto check = [&](bool ok, const std::string& key, const std::string& what) {
    if (!ok) throw Error(section.file() + ": key '" + section.qualified(key) + "' " + what);
  };
  check(p.mask_dilation_px >= 0, "mask_dilation_px", "must be >= 0");
  check(p.queue_size >= 1, "queue_size", "must be >= 1");
  check(p.history >= 1, "history", "must be >= 1");
  check(!p.model.empty(), "model", "must not be empty");
  return p;
}

}  // namespace pspslam
