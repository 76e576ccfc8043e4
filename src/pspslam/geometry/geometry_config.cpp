#include "pspslam/geometry/geometry_config.h"

#include "pspslam/core/yaml_section.h"

namespace pspslam {

GeometryParams read_geometry_config(const ConfigSection& config_section) {
  YamlSection section = config_section.reader();
  YamlSection search = section.section("search");
  if (search.contains("strategy")) {
    throw search.invalid("strategy",
                         "is not a config key: pspslam run --dynamic chooses the search (full: "
                         "ant_colony, exhaustive: every point)");
  }
  if (section.contains("output_warped_previous_mask")) {
    throw section.invalid("output_warped_previous_mask",
                          "is not a config key: a run does not use the warped mask");
  }
  return GeometryParams::from_yaml(section);
}

}  // namespace pspslam
