#include "pspslam/session/run_settings.h"

#include <spdlog/spdlog.h>

#include <cstdint>
#include <numbers>
#include <string>

#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/place/place_recognition.h"
#include "pspslam/semantic/segmenter_metadata.h"
#include "pspslam/semantic/semantic_delay.h"

namespace pspslam {
namespace {

// Why the model does not load, with how to get one where the caller explains it.
std::string model_problem(const Error& e, const SettingNames& names) {
  if (!names.explain_model) return e.what();
  return "segmentation model not usable: " + std::string(e.what()) +
         "\n  get it: train/export our PSPNet with tools/pspnet (models/pspnet/pspnet.yaml + "
         ".onnx),\n  or pass a teacher, e.g. --model models/teachers/deeplabv3_mnv2_pascal.yaml "
         "(ONNX in ../shared/models)";
}

// `loop_closing` on | off | auto: auto = on when the vocabulary file exists.
bool wants_loop_closing(const std::string& value, const std::filesystem::path& vocabulary) {
  return value == "on" || (value == "auto" && std::filesystem::exists(vocabulary));
}

void set_tracking(const RunSettings& settings, SystemOptions& system) {
  system.tracker.keyframes.tracked_ratio_to_reference = settings.keyframe_ratio;
  system.tracker.keyframes.insert_when_due = settings.due_keyframes;
  system.tracker.new_map_after_seconds = settings.new_map_after.value_or(
      settings.live() ? kLiveNewMapAfterSeconds : kNewMapAfterSeconds);
  if (settings.motion_prior) {
    system.tracker.motion_prior_sigma_translation = settings.motion_prior->first * 1e-3;
    system.tracker.motion_prior_sigma_rotation =
        settings.motion_prior->second * std::numbers::pi / 180.0;
  }
}

void set_dynamic(const RunSettings& settings, const SettingNames& names, DynamicOptions& dynamic) {
  dynamic.model = settings.model.value_or(data_dir() / "models/pspnet/pspnet.yaml");
  dynamic.mode = choose_mode(settings, dynamic.model, names);
  dynamic.semantic_masks = settings.semantic_masks.value_or(std::filesystem::path());
  dynamic.realtime = settings.realtime;
  dynamic.semantic.mask_dilation_px = settings.mask_margin;
  dynamic.segment_every = settings.segment_every;
  dynamic.culling.min_dynamic_hits = settings.cull_hits;
  dynamic.culling.evidence = parse_culling_evidence(
      settings.cull_evidence, names.keywords ? "cull_evidence" : "--cull-evidence");
}

// A live run's answers to a network that falls behind the camera.
void set_stale_masks(const RunSettings& settings, SystemOptions& system) {
  DynamicOptions& dynamic = system.dynamic;
  dynamic.keep_pace = settings.semantic_pace == "on";
  const std::filesystem::path shipped_smaller = data_dir() / "models/pspnet/pspnet_288x192.yaml";
  if (settings.smaller_model)
    dynamic.smaller_model = *settings.smaller_model;
  else if (!settings.model && std::filesystem::is_regular_file(shipped_smaller))
    dynamic.smaller_model = shipped_smaller;
  system.tracker.mover_guard.enabled = settings.mover_guard == "on";
  dynamic.tighten_geometry = settings.stale_geometry == "on";
  dynamic.cull_with_late_masks = settings.late_mask_culling == "on";
  system.tracker.judged_points_first = settings.judged_points_first == "on";
  dynamic.propagation.max_growth_px = settings.stale_mask_growth;
  dynamic.stale_masks =
      settings.stale_masks == "flow" ? StaleMaskPolicy::flow : StaleMaskPolicy::homography;
  if (!settings.semantic_delay_ms.empty()) {
    dynamic.semantic.injected_delay =
        parse_semantic_delay(settings.semantic_delay_ms, "--semantic-delay-ms");
    dynamic.semantic.injected_delay.seed = static_cast<std::uint32_t>(settings.semantic_delay_seed);
  }
}

void set_place(const RunSettings& settings, SystemOptions& system) {
  system.place.relocalization = settings.relocalization;
  if (settings.load_map) {
    system.map_file = *settings.load_map;
    system.localization_only = settings.localization;
  }
  system.place.vocabulary = settings.vocabulary.value_or(default_vocabulary_path());
  // Localisation never changes the map, so it never closes loops (System turns it off too).
  system.place.loop_closing = !system.localization_only &&
                              wants_loop_closing(settings.loop_closing, system.place.vocabulary);
}

}  // namespace

DynamicMode choose_mode(const RunSettings& settings, const std::filesystem::path& model,
                        const SettingNames& names) {
  const bool automatic = settings.mode == "auto";
  const DynamicMode wanted =
      automatic ? DynamicMode::full : parse_dynamic_mode(settings.mode, names.mode);
  if (settings.semantic_masks) {
    if (!uses_semantics(wanted)) {
      throw Error(std::string(names.semantic_masks) + " replaces the network's masks, but " +
                  names.mode + " " + settings.mode +
                  " uses none (use semantic, full or exhaustive)");
    }
    return wanted;
  }
  if (!uses_semantics(wanted)) return wanted;
  try {
    load_segmenter_metadata(model);
    return wanted;
  } catch (const Error& e) {
    const std::string problem = model_problem(e, names);
    if (!automatic || settings.model)
      throw Error(std::string(names.mode) + " " + settings.mode + ": " + problem);
    if (names.explain_model) spdlog::warn("{}\n  falling back to {} geometry", problem, names.mode);
    return DynamicMode::geometry;
  }
}

SystemOptions system_options(const RunSettings& settings, const SettingNames& names) {
  SystemOptions system;
  set_dynamic(settings, names, system.dynamic);
  system.local_mapping = settings.local_mapping;
  const bool live = settings.live();
  system.background_thread_nice = settings.background_nice.value_or(live ? kLiveBackgroundNice : 0);
  system.local_ba_keyframes =
      settings.local_ba_keyframes.value_or(live ? kLiveLocalBaKeyframes : 0);
  system.ba_tracking_factors = settings.ba_tracking_factors;
  system.local_ba_fixed_keyframes = settings.local_ba_fixed_keyframes;
  set_tracking(settings, system);
  set_place(settings, system);
  set_stale_masks(settings, system);
  // A live source keeps delivering while the run waits: a loop's global BA (seconds) would drop
  // a second of frames, so without realtime it waits for local mapping only.
  system.back_end_wait = settings.realtime      ? BackEndWait::none
                         : settings.live_camera ? BackEndWait::local_mapping
                                                : BackEndWait::whole_back_end;
  return system;
}

}  // namespace pspslam
