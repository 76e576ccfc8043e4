#include "system_options.h"

#include <pybind11/pybind11.h>

#include <initializer_list>
#include <numbers>
#include <string>

#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/place/place_recognition.h"
#include "pspslam/semantic/segmenter_metadata.h"

namespace pspslam::python {
namespace {

namespace py = pybind11;

// The values `pspslam run` gives live runs; Python runs are live only with realtime=True.
constexpr int kLiveBackgroundNice = 10;
constexpr int kLiveLocalBaKeyframes = 10;

// A number as Python prints it (1e-3 as 0.001, 100 as 100).
template <typename T>
std::string python_text(T value) {
  return py::str(py::cast(value));
}

template <typename T>
void require_range(T value, T low, T high, const char* keyword) {
  if (!(value >= low && value <= high)) {
    throw py::value_error(std::string(keyword) + ": expected a value in [" + python_text(low) +
                          ", " + python_text(high) + "], got " + python_text(value));
  }
}

void require_member(const std::string& value, std::initializer_list<const char*> allowed,
                    const char* keyword) {
  std::string listed;
  for (const char* name : allowed) {
    if (value == name) return;
    if (!listed.empty()) listed += " | ";
    listed += name;
  }
  throw py::value_error(std::string(keyword) + ": expected " + listed + ", got '" + value + "'");
}

// As `pspslam run --dynamic`: auto = full when the segmentation model loads, else geometry; a
// semantic mode asked for by name needs its model (or masks from files).
DynamicMode choose_mode(const RunSettings& settings, const std::filesystem::path& model) {
  const bool automatic = settings.mode == "auto";
  const DynamicMode wanted =
      automatic ? DynamicMode::full : parse_dynamic_mode(settings.mode, "mode");
  if (!uses_semantics(wanted) || settings.semantic_masks) return wanted;
  try {
    load_segmenter_metadata(model);
    return wanted;
  } catch (const Error& e) {
    if (!automatic || settings.model) throw Error("mode " + settings.mode + ": " + e.what());
    return DynamicMode::geometry;
  }
}

void check_ranges(const RunSettings& settings) {
  require_member(settings.mode, {"off", "semantic", "geometry", "full", "exhaustive", "auto"},
                 "mode");
  require_member(settings.loop_closing, {"on", "off", "auto"}, "loop_closing");
  require_range(settings.mask_margin, 0, 100, "mask_margin");
  require_range(settings.segment_every, 1, 30, "segment_every");
  require_range(settings.cull_hits, 1, 1000, "cull_hits");
  require_range(settings.keyframe_ratio, 0.01, 1.0, "keyframe_ratio");
  if (settings.local_ba_keyframes)
    require_range(*settings.local_ba_keyframes, 0, 1000, "local_ba_keyframes");
  if (settings.background_nice) require_range(*settings.background_nice, 0, 19, "background_nice");
  if (settings.motion_prior) {
    require_range(settings.motion_prior->first, 1e-3, 1e3, "motion_prior");
    require_range(settings.motion_prior->second, 1e-3, 1e3, "motion_prior");
  }
  if (settings.localization && !settings.load_map)
    throw py::value_error("localization: needs load_map (a map to localise in)");
  if (settings.semantic_masks && settings.mode != "auto" &&
      !uses_semantics(parse_dynamic_mode(settings.mode, "mode")))
    throw py::value_error("semantic_masks: replaces the network's masks, but mode " +
                          settings.mode + " uses none (use semantic, full or exhaustive)");
}

}  // namespace

SystemOptions system_options(const RunSettings& settings) {
  check_ranges(settings);
  SystemOptions system;
  DynamicOptions& dynamic = system.dynamic;
  dynamic.model = settings.model.value_or(data_dir() / "models/pspnet/pspnet.yaml");
  dynamic.mode = choose_mode(settings, dynamic.model);
  dynamic.semantic_masks = settings.semantic_masks.value_or(std::filesystem::path());
  system.local_mapping = settings.local_mapping;
  const bool live = settings.realtime;
  system.background_thread_nice = settings.background_nice.value_or(live ? kLiveBackgroundNice : 0);
  system.tracker.keyframes.tracked_ratio_to_reference = settings.keyframe_ratio;
  system.tracker.keyframes.insert_when_due = settings.due_keyframes;
  system.local_ba_keyframes =
      settings.local_ba_keyframes.value_or(live ? kLiveLocalBaKeyframes : 0);
  if (settings.motion_prior) {
    system.tracker.motion_prior_sigma_translation = settings.motion_prior->first * 1e-3;
    system.tracker.motion_prior_sigma_rotation =
        settings.motion_prior->second * std::numbers::pi / 180.0;
  }
  dynamic.realtime = settings.realtime;
  dynamic.semantic.mask_dilation_px = settings.mask_margin;
  dynamic.segment_every = settings.segment_every;
  dynamic.culling.min_dynamic_hits = settings.cull_hits;
  system.place.relocalization = settings.relocalization;
  if (settings.load_map) {
    system.map_file = *settings.load_map;
    system.localization_only = settings.localization;
  }
  system.place.vocabulary = settings.vocabulary.value_or(default_vocabulary_path());
  system.place.loop_closing =
      !system.localization_only &&
      (settings.loop_closing == "on" ||
       (settings.loop_closing == "auto" && std::filesystem::exists(system.place.vocabulary)));
  system.back_end_wait = settings.realtime ? BackEndWait::none : BackEndWait::whole_back_end;
  return system;
}

}  // namespace pspslam::python
