#include "pspslam/session/run_options.h"

#include <string>
#include <utility>

#include "pspslam/core/output_paths.h"

namespace pspslam {

void prepare_run_outputs(const RunOutputs& outputs) {
  prepare_output_folder(outputs.folder, "--out");
  const std::pair<const char*, const std::filesystem::path*> folders[] = {
      {"--save-masks", &outputs.masks}, {"--save-overlays", &outputs.overlays}};
  for (const auto& [flag, folder] : folders) {
    if (!folder->empty()) prepare_output_folder(*folder, flag);
  }
  const std::pair<const char*, const std::filesystem::path*> files[] = {
      {"--save-map", &outputs.save_map},
      {"--export-map", &outputs.export_map},
      {"--export-dense", &outputs.export_dense}};
  for (const auto& [flag, file] : files) {
    if (!file->empty()) prepare_output_file(*file, flag);
  }
}

void prepare_occupancy_outputs(const OccupancyRunOptions& occupancy) {
  occupancy.validate();
  if (!occupancy.export_octomap.empty())
    prepare_output_file(occupancy.export_octomap, "--export-octomap");
  if (!occupancy.export_grid.empty()) {
    prepare_output_file(occupancy.export_grid, "--export-grid");
    std::filesystem::path image = occupancy.export_grid;
    prepare_output_file(image.replace_extension(".pgm"), "--export-grid");
  }
}

}  // namespace pspslam
