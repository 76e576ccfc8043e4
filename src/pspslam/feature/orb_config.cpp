#include "pspslam/feature/orb_config.h"

#include "pspslam/core/yaml_section.h"

namespace pspslam {

OrbConfig read_orb_config(const ConfigSection& config_section) {
  YamlSection section = config_section.reader();
  OrbConfig orb;
  orb.n_features = section.optional("n_features", orb.n_features);
  orb.scale_factor = section.optional("scale_factor", orb.scale_factor);
  orb.n_levels = section.optional("n_levels", orb.n_levels);
  orb.initial_fast_threshold =
      section.optional("initial_fast_threshold", orb.initial_fast_threshold);
  orb.min_fast_threshold = section.optional("min_fast_threshold", orb.min_fast_threshold);
  orb.mask_compensation = section.optional("mask_compensation", orb.mask_compensation);
  section.require(orb.n_features > 0, "n_features", "must be > 0");
  section.require(orb.scale_factor > 1.0, "scale_factor", "must be > 1");
  section.require(orb.n_levels > 0, "n_levels", "must be > 0");
  section.finish();
  return orb;
}

}  // namespace pspslam
