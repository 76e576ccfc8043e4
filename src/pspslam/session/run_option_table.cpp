#include "pspslam/session/run_option_table.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <optional>
#include <sstream>
#include <type_traits>

#include "pspslam/core/error.h"
#include "pspslam/semantic/semantic_delay.h"

namespace pspslam {
namespace {

using Kind = RunOptionKind;

// The type an optional member holds, or the member's own type.
template <typename T>
struct Unwrapped {
  using type = T;
};
template <typename T>
struct Unwrapped<std::optional<T>> {
  using type = T;
};

RunOption make_option(std::string flag, std::string keyword, Kind kind, std::string help) {
  RunOption option;
  option.flag = std::move(flag);
  option.keyword = std::move(keyword);
  option.kind = kind;
  option.help = std::move(help);
  return option;
}

std::string number_text(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

// "an integer in [0, 100]" / "a number in [0.01, 1]".
std::string range_text(const RunOption& option) {
  return std::string(option.kind == Kind::integer ? "an integer" : "a number") + " in [" +
         number_text(option.low) + ", " + number_text(option.high) + "]";
}

std::string joined(const std::vector<std::string>& words, const char* separator) {
  std::string text;
  for (const std::string& word : words) text += (text.empty() ? "" : separator) + word;
  return text;
}

template <auto member>
RunOption flag_option(std::string flag, std::string keyword, std::string help, bool negated) {
  RunOption option = make_option(std::move(flag), std::move(keyword),
                                 negated ? Kind::negated_flag : Kind::flag, std::move(help));
  option.set = [](RunSettings& s, const RunValue& v) { s.*member = std::get<bool>(v); };
  option.value_text = [](const RunSettings& s) {
    return std::string(s.*member ? "true" : "false");
  };
  return option;
}

// An int, double or long long member, or an optional one (unset: the run's own default).
template <auto member>
RunOption number_option(std::string flag, std::string keyword, std::string help, Kind kind,
                        double low, double high) {
  RunOption option = make_option(std::move(flag), std::move(keyword), kind, std::move(help));
  option.low = low;
  option.high = high;
  option.set = [](RunSettings& s, const RunValue& v) {
    using Value = typename Unwrapped<std::remove_cvref_t<decltype(s.*member)>>::type;
    if (std::holds_alternative<long long>(v))
      s.*member = static_cast<Value>(std::get<long long>(v));
    else
      s.*member = static_cast<Value>(std::get<double>(v));
  };
  option.value_text = [](const RunSettings& s) {
    const auto& value = s.*member;
    if constexpr (requires { value.has_value(); })
      return value ? number_text(static_cast<double>(*value)) : std::string();
    else
      return number_text(static_cast<double>(value));
  };
  return option;
}

template <auto member>
RunOption choice_option(std::string flag, std::string keyword, std::string help,
                        std::vector<std::string> choices) {
  RunOption option =
      make_option(std::move(flag), std::move(keyword), Kind::choice, std::move(help));
  option.choices = std::move(choices);
  option.set = [](RunSettings& s, const RunValue& v) { s.*member = std::get<std::string>(v); };
  option.value_text = [](const RunSettings& s) { return s.*member; };
  return option;
}

template <auto member>
RunOption path_option(std::string flag, std::string keyword, std::string help, PathMustBe must) {
  RunOption option = make_option(std::move(flag), std::move(keyword), Kind::path, std::move(help));
  option.path_must_be = must;
  option.set = [](RunSettings& s, const RunValue& v) {
    s.*member = std::filesystem::path(std::get<std::string>(v));
  };
  option.value_text = [](const RunSettings& s) {
    return s.*member ? (s.*member)->string() : std::string();
  };
  return option;
}

const std::vector<std::string> kOnOff = {"on", "off"};

// How dynamic content is found, and where the frames come from.
void add_dynamic_options(std::vector<RunOption>& table) {
  RunOption mode = choice_option<&RunSettings::mode>(
      "--dynamic", "mode",
      "dynamic-scene mode: off | semantic | geometry | full | exhaustive | auto (auto = full "
      "when the segmentation model loads, else geometry)",
      {"off", "semantic", "geometry", "full", "exhaustive", "auto"});
  mode.effective_text = [](const SystemOptions& s) {
    return std::string(to_string(s.dynamic.mode));
  };
  table.push_back(std::move(mode));
  RunOption model = path_option<&RunSettings::model>(
      "--model", "model",
      "segmentation metadata YAML (default: the shipped models/pspnet/pspnet.yaml)",
      PathMustBe::anything);
  model.effective_text = [](const SystemOptions& s) { return s.dynamic.model.string(); };
  table.push_back(std::move(model));
  table.push_back(flag_option<&RunSettings::realtime>(
      "--realtime", "realtime",
      "feed frames at the sequence's rate (late frames are dropped) and never wait for "
      "segmentation or the back end: use the newest mask, warped into the frame (default: "
      "deterministic, each frame waits for its mask and for local mapping, loop closing and any "
      "global BA to finish the previous keyframe; a camera waits for local mapping only)",
      false));
  table.push_back(flag_option<&RunSettings::live_camera>(
      "", "live",
      "frames come from a live source as they arrive, as with `pspslam run --camera`: the live "
      "defaults, and each frame waits for local mapping only",
      false));
  table.push_back(flag_option<&RunSettings::local_mapping>(
      "--no-local-mapping", "local_mapping",
      "track only: keyframes enter the map but are never refined (debugging)", true));
  RunOption nice = number_option<&RunSettings::background_nice>(
      "--background-nice", "background_nice",
      "scheduling priority given up by the semantic, local mapping and loop closing threads "
      "below tracking's (nice increment, 0-19) so that tracking gets a core when a frame "
      "arrives (default: " +
          std::to_string(kLiveBackgroundNice) + " with --realtime or --camera, 0 otherwise)",
      Kind::integer, 0, 19);
  nice.effective_text = [](const SystemOptions& s) {
    return std::to_string(s.background_thread_nice);
  };
  table.push_back(std::move(nice));
}

// How often the network runs and how the frames between use an older mask.
void add_stale_mask_options(std::vector<RunOption>& table) {
  table.push_back(number_option<&RunSettings::segment_every>(
      "--segment-every", "segment_every",
      "segment every n-th frame; the frames between use the newest mask, moved with the camera "
      "by the frame-to-frame homographies",
      Kind::integer, 1, 30));
  table.push_back(choice_option<&RunSettings::semantic_pace>(
      "--semantic-pace", "semantic_pace",
      "with --realtime: when segmentation falls behind the camera, step down by itself to the "
      "smaller network input (--smaller-model), then to segmenting every 2nd or 3rd frame, and "
      "back up when there is room (off: one network on every frame it can take)",
      kOnOff));
  RunOption smaller = path_option<&RunSettings::smaller_model>(
      "--smaller-model", "smaller_model",
      "the smaller segmentation model --semantic-pace steps down to (default: the shipped "
      "models/pspnet/pspnet_288x192.yaml when --model is the shipped one, else none: only "
      "sparser frames)",
      PathMustBe::existing_file);
  smaller.effective_text = [](const SystemOptions& s) { return s.dynamic.smaller_model.string(); };
  table.push_back(std::move(smaller));
  table.push_back(choice_option<&RunSettings::stale_masks>(
      "--stale-masks", "stale_masks",
      "with --realtime, how an older mask is brought into the frame: flow = each person moves "
      "by the optical flow inside it and the mask grows with its age, and keypoints near a mask "
      "more than 2 frames old get the geometry test (experimental: it can leave a crowd too few "
      "static keypoints); homography = moved with the camera only",
      {"flow", "homography"}));
  table.push_back(number_option<&RunSettings::stale_mask_growth>(
      "--stale-mask-growth", "stale_mask_growth",
      "with --stale-masks flow: the most pixels a moved mask grows by for its age", Kind::integer,
      0, 200));
  table.push_back(choice_option<&RunSettings::stale_geometry>(
      "--stale-geometry", "stale_geometry",
      "with --realtime and --stale-masks flow: while the mask is more than 2 frames old, every "
      "keypoint in a band around it gets the multi-view geometry test",
      kOnOff));
  table.push_back(choice_option<&RunSettings::late_mask_culling>(
      "--late-mask-culling", "late_mask_culling",
      "with --realtime: a mask that arrives after its frame was tracked still judges that frame; "
      "map points the frame saw on its people count towards their culling, and a mask more than "
      "2 frames old culls nothing (off: the newest mask culls, however old)",
      kOnOff));
  table.push_back(choice_option<&RunSettings::judged_points_first>(
      "--judged-points-first", "judged_points_first",
      "with --realtime and --late-mask-culling on: while the mask is more than 2 frames old, a "
      "frame's pose is solved on the map points an exact mask has judged first, and newer points "
      "count only where they agree with it (off: every match alike, which lets a crowd the stale "
      "mask missed carry the pose)",
      kOnOff));
  table.push_back(choice_option<&RunSettings::mover_guard>(
      "--mover-guard", "mover_guard",
      "experimental: when a frame's inliers drop and its pose jumps off the constant-velocity "
      "prediction (tracking following a crowd), hold the prediction for up to 3 frames",
      kOnOff));
}

// Where the semantic masks come from (the network, slowed down on purpose, or a folder) and how
// far they are grown.
void add_mask_source_options(std::vector<RunOption>& table) {
  RunOption delay = make_option(
      "--semantic-delay-ms", "semantic_delay_ms", Kind::text,
      "fault injection: MS or random:MIN:MAX milliseconds of extra wait after each "
      "segmentation, as if the network were that much slower (reproduces a network that falls "
      "behind the camera)");
  delay.value_name = "MS|random:MIN:MAX";
  delay.check_text = [](const std::string& text) {
    try {
      parse_semantic_delay(text, "");
      return std::string();
    } catch (const Error& e) {
      // The parser's message names the flag first (here: nothing); each front end names it.
      std::string message = e.what();
      while (!message.empty() && (message.front() == ':' || message.front() == ' '))
        message.erase(0, 1);
      return message;
    }
  };
  delay.set = [](RunSettings& s, const RunValue& v) {
    s.semantic_delay_ms = std::get<std::string>(v);
  };
  delay.value_text = [](const RunSettings& s) { return s.semantic_delay_ms; };
  table.push_back(std::move(delay));
  table.push_back(number_option<&RunSettings::semantic_delay_seed>(
      "--semantic-delay-seed", "semantic_delay_seed",
      "seed of the random:MIN:MAX delays (the same seed draws the same delays)", Kind::integer, 0,
      4294967295.0));
  table.push_back(path_option<&RunSettings::semantic_masks>(
      "--semantic-masks", "semantic_masks",
      "read each frame's semantic mask from this folder instead of running the network: "
      "DIR/<colour image name>.png, 8-bit, non-zero = dynamic (what --save-masks writes; a synth "
      "sequence's mask/ folder); grown by --mask-margin",
      PathMustBe::existing_folder));
  table.push_back(number_option<&RunSettings::mask_margin>(
      "--mask-margin", "mask_margin", "dilation of the semantic dynamic mask (pixels)",
      Kind::integer, 0, 100));
}

// When a frame becomes a keyframe, how far local BA reaches and how a frame's pose is optimised.
void add_keyframe_options(std::vector<RunOption>& table) {
  table.push_back(number_option<&RunSettings::keyframe_ratio>(
      "--keyframe-ratio", "keyframe_ratio",
      "a frame becomes a keyframe when it tracks fewer than this share of its reference "
      "keyframe's points (ORB-SLAM2: 0.75; higher = denser keyframes)",
      Kind::real, 0.01, 1.0));
  RunOption window = number_option<&RunSettings::local_ba_keyframes>(
      "--local-ba-keyframes", "local_ba_keyframes",
      "local BA optimises the new keyframe and at most this many of its best covisible "
      "keyframes; 0 = all of them, as ORB-SLAM2 (default: " +
          std::to_string(kLiveLocalBaKeyframes) +
          " with --realtime or --camera, so that local BA keeps up on two cores; 0 otherwise)",
      Kind::integer, 0, 1000);
  window.effective_text = [](const SystemOptions& s) {
    return std::to_string(s.local_ba_keyframes);
  };
  table.push_back(std::move(window));
  table.push_back(number_option<&RunSettings::local_ba_fixed_keyframes>(
      "--local-ba-fixed-keyframes", "local_ba_fixed_keyframes",
      "of the keyframes held fixed around the local BA window (those that see its points), keep "
      "the ones that see the most of them; 0 = all, as ORB-SLAM2 (bounds local BA where a "
      "revisited room has many)",
      Kind::integer, 0, 1000));
  table.push_back(number_option<&RunSettings::ba_tracking_factors>(
      "--ba-tracking-factors", "ba_tracking_factors",
      "WEIGHT: local BA also keeps each keyframe's pose relative to the keyframe before it as "
      "tracking measured it, weighted by WEIGHT times the information of its pose-only "
      "optimisation (0 = off, ORB-SLAM2's BA)",
      Kind::real, 0.0, 1e6));
  table.push_back(flag_option<&RunSettings::due_keyframes>(
      "--due-keyframes", "due_keyframes",
      "also make a keyframe once a second has passed since the last one, whatever "
      "--keyframe-ratio says (keeps keyframes dense on a camera that keeps exploring; off by "
      "default: docs/decisions/due-keyframes.md)",
      false));
  RunOption prior = make_option(
      "--motion-prior", "motion_prior", Kind::real_pair,
      "MM DEG: optimise each frame tracked with the motion model with its constant-velocity "
      "prediction as a prior of these σs (translation mm, rotation degrees; default: no prior; "
      "it lowers the jitter, not the ATE)");
  prior.low = 1e-3;
  prior.high = 1e3;
  prior.value_name = "MM DEG";
  prior.set = [](RunSettings& s, const RunValue& v) {
    s.motion_prior = std::get<std::pair<double, double>>(v);
  };
  prior.value_text = [](const RunSettings& s) {
    return s.motion_prior
               ? number_text(s.motion_prior->first) + " " + number_text(s.motion_prior->second)
               : std::string();
  };
  table.push_back(std::move(prior));
}

// The map: vocabulary, relocalisation, new maps, loop closing, a saved map, culling.
void add_map_options(std::vector<RunOption>& table) {
  RunOption vocabulary = path_option<&RunSettings::vocabulary>(
      "--vocabulary", "vocabulary",
      "ORB bag-of-words vocabulary for relocalisation and loop closing (default: the shipped "
      "models/vocabulary/orb_k10_l5.pspvoc)",
      PathMustBe::anything);
  vocabulary.effective_text = [](const SystemOptions& s) { return s.place.vocabulary.string(); };
  table.push_back(std::move(vocabulary));
  table.push_back(flag_option<&RunSettings::relocalization>(
      "--no-relocalization", "relocalization",
      "do not relocalise when tracking is lost (and do not load the vocabulary)", true));
  RunOption new_map = number_option<&RunSettings::new_map_after>(
      "--new-map-after", "new_map_after",
      "SECONDS lost, with relocalisation failing in every map, before tracking starts a new map "
      "in the atlas; loop closing merges it when a place is recognised across the two (0: "
      "never; the run stays lost until relocalised; default: " +
          fmt::format("{:g} s, {:g} s for live runs", kNewMapAfterSeconds,
                      kLiveNewMapAfterSeconds) +
          ")",
      Kind::real, 0.0, 3600.0);
  new_map.effective_text = [](const SystemOptions& s) {
    return number_text(s.tracker.new_map_after_seconds);
  };
  table.push_back(std::move(new_map));
  RunOption loops = choice_option<&RunSettings::loop_closing>(
      "--loop-closing", "loop_closing",
      "loop closing thread (detection, essential-graph correction, global BA); auto = on when "
      "the vocabulary file exists",
      {"on", "off", "auto"});
  loops.effective_text = [](const SystemOptions& s) {
    return std::string(s.place.loop_closing ? "on" : "off");
  };
  table.push_back(std::move(loops));
  table.push_back(path_option<&RunSettings::load_map>(
      "--load-map", "load_map", "start from this saved map: the first frame is relocalised in it",
      PathMustBe::existing_file));
  table.push_back(flag_option<&RunSettings::localization>(
      "--localization", "localization",
      "localisation only (needs --load-map): track in the map, never add to it", false));
  table.push_back(number_option<&RunSettings::cull_hits>(
      "--cull-hits", "cull_hits",
      "with --cull-evidence mask or seen-through: erase a map point after this many frames of "
      "evidence against it",
      Kind::integer, 1, 1000));
  table.push_back(choice_option<&RunSettings::cull_evidence>(
      "--cull-evidence", "cull_evidence",
      "what erases a map point as dynamic: off (nothing; local mapping's own culling removes "
      "points that stop being matched), mask (it lies on the frame's dynamic mask at its own "
      "depth) or seen-through (the frame's depth sees through where the map has it, whatever the "
      "masks); see docs/decisions/map-hygiene.md",
      {"off", "mask", "seen-through"}));
}

// The occupancy map of the static scene; its outputs (--export-octomap, --export-grid) and its
// scoring are the CLI's own, the 2D grid's band is an argument of Python's occupancy_grid().
void add_occupancy_options(std::vector<RunOption>& table) {
  table.push_back(flag_option<&RunSettings::occupancy>(
      "--occupancy", "occupancy",
      "build an occupancy map of the static scene while the run goes (keyframes' depth without "
      "the dynamic pixels, ray cast into an OctoMap on its own thread); its memory, cost and "
      "counts go to stats.json",
      false));
  table.push_back(number_option<&RunSettings::occupancy_resolution>(
      "--occupancy-resolution", "occupancy_resolution", "occupancy voxel edge in metres",
      Kind::real, 0.005, 2.0));
  table.push_back(number_option<&RunSettings::occupancy_max_range>(
      "--occupancy-max-range", "occupancy_max_range",
      "depth readings farther than this (metres) mark free space only", Kind::real, 0.1, 100.0));
  table.push_back(choice_option<&RunSettings::occupancy_masks>(
      "--occupancy-masks", "occupancy_masks",
      "leave each keyframe's dynamic pixels out of the occupancy map", kOnOff));
  table.push_back(choice_option<&RunSettings::occupancy_clearing>(
      "--occupancy-clearing", "occupancy_clearing",
      "rays free the voxels they pass through (off: only hits count, as a point cloud)", kOnOff));
}

std::vector<RunOption> make_table() {
  std::vector<RunOption> table;
  add_dynamic_options(table);
  add_stale_mask_options(table);
  add_mask_source_options(table);
  add_keyframe_options(table);
  add_map_options(table);
  add_occupancy_options(table);
  return table;
}

std::string number_problem(const RunOption& option, double value, const std::string& shown) {
  if (!(value >= option.low && value <= option.high))
    return "must be " + range_text(option) + ", got '" + shown + "'";
  return {};
}

// A whole number (integer options) or any number, as the whole text; none otherwise.
std::optional<double> parse_number(const RunOption& option, const std::string& text) {
  const char* end = text.data() + text.size();
  if (option.kind == Kind::integer) {
    long long value = 0;
    const auto [stop, status] = std::from_chars(text.data(), end, value);
    if (text.empty() || status != std::errc() || stop != end) return std::nullopt;
    return static_cast<double>(value);
  }
  double value = 0.0;
  const auto [stop, status] = std::from_chars(text.data(), end, value);
  if (text.empty() || status != std::errc() || stop != end) return std::nullopt;
  return value;
}

std::string path_problem(const RunOption& option, const std::string& text) {
  namespace fs = std::filesystem;
  if (option.path_must_be == PathMustBe::existing_file && !fs::is_regular_file(text))
    return "must be an existing file, got '" + text + "'";
  if (option.path_must_be == PathMustBe::existing_folder && !fs::is_directory(text))
    return "must be an existing folder, got '" + text + "'";
  return {};
}

}  // namespace

const std::vector<RunOption>& run_option_table() {
  static const std::vector<RunOption> table = make_table();
  return table;
}

const RunOption* find_run_option_by_flag(const std::string& flag) {
  const auto& table = run_option_table();
  const auto it = std::find_if(table.begin(), table.end(),
                               [&](const RunOption& o) { return !flag.empty() && o.flag == flag; });
  return it == table.end() ? nullptr : &*it;
}

const RunOption* find_run_option_by_keyword(const std::string& keyword) {
  const auto& table = run_option_table();
  const auto it = std::find_if(table.begin(), table.end(),
                               [&](const RunOption& o) { return o.keyword == keyword; });
  return it == table.end() ? nullptr : &*it;
}

std::string run_text_problem(const RunOption& option, const std::vector<std::string>& words) {
  switch (option.kind) {
    case Kind::flag:
    case Kind::negated_flag:
      return {};
    case Kind::integer:
    case Kind::real:
    case Kind::real_pair:
      for (const std::string& word : words) {
        const std::optional<double> value = parse_number(option, word);
        if (!value) return "must be " + range_text(option) + ", got '" + word + "'";
        if (std::string problem = number_problem(option, *value, word); !problem.empty())
          return problem;
      }
      return {};
    case Kind::choice:
      if (std::find(option.choices.begin(), option.choices.end(), words.at(0)) ==
          option.choices.end())
        return "must be one of " + joined(option.choices, " | ") + ", got '" + words.at(0) + "'";
      return {};
    case Kind::text:
      return option.check_text ? option.check_text(words.at(0)) : std::string();
    case Kind::path:
      return path_problem(option, words.at(0));
  }
  return {};
}

RunValue parse_run_text(const RunOption& option, const std::vector<std::string>& words) {
  switch (option.kind) {
    case Kind::flag:
      return true;
    case Kind::negated_flag:
      return false;
    case Kind::integer:
      return static_cast<long long>(*parse_number(option, words.at(0)));
    case Kind::real:
      return *parse_number(option, words.at(0));
    case Kind::real_pair:
      return std::pair(*parse_number(option, words.at(0)), *parse_number(option, words.at(1)));
    case Kind::choice:
    case Kind::text:
    case Kind::path:
      break;
  }
  return words.at(0);
}

std::string run_value_problem(const RunOption& option, const RunValue& value,
                              const std::vector<std::string>& shown) {
  switch (option.kind) {
    case Kind::integer:
      return number_problem(option, static_cast<double>(std::get<long long>(value)), shown.at(0));
    case Kind::real:
      return number_problem(option, std::get<double>(value), shown.at(0));
    case Kind::real_pair: {
      const auto [first, second] = std::get<std::pair<double, double>>(value);
      std::string problem = number_problem(option, first, shown.at(0));
      return problem.empty() ? number_problem(option, second, shown.at(1)) : problem;
    }
    case Kind::choice:
    case Kind::text:
    case Kind::path:
      return run_text_problem(option, {std::get<std::string>(value)});
    case Kind::flag:
    case Kind::negated_flag:
      break;
  }
  return {};
}

void check_run_settings(const RunSettings& settings, const SettingNames& names) {
  const auto name = [&](const char* keyword) {
    const RunOption* option = find_run_option_by_keyword(keyword);
    return names.keywords ? option->keyword : option->flag;
  };
  if (settings.localization && !settings.load_map)
    throw Error(name("localization") + ": needs " + name("load_map") + " (a map to localise in)");
  if (settings.semantic_delay_seed != RunSettings{}.semantic_delay_seed &&
      settings.semantic_delay_ms.empty())
    throw Error(name("semantic_delay_seed") + ": needs " + name("semantic_delay_ms"));
  if (!(settings.occupancy_max_range > settings.occupancy_resolution))
    throw Error(name("occupancy_max_range") + ": must exceed " + name("occupancy_resolution"));
}

std::vector<std::pair<std::string, std::string>> effective_settings(const RunSettings& settings,
                                                                    const SystemOptions& system) {
  std::vector<std::pair<std::string, std::string>> values;
  for (const RunOption& option : run_option_table()) {
    values.emplace_back(option.keyword, option.effective_text ? option.effective_text(system)
                                                              : option.value_text(settings));
  }
  return values;
}

}  // namespace pspslam
