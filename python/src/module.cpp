// pspslam._pspslam: the compiled half of `import pspslam` (the package's __init__.py adds the
// pure-Python helpers). Frames in and out are numpy arrays.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "arrays.h"
#include "evaluation.h"
#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/core/version.h"
#include "pspslam/io/sequence_setup.h"
#include "pspslam/session/run_option_table.h"
#include "python_system.h"
#include "sequence_reader.h"
#include "system_options.h"

namespace pspslam::python {
namespace {

std::string type_name(const py::handle& object) {
  return py::str(py::type::of(object).attr("__name__"));
}

// A keyword option of the given C++ type; TypeError naming it otherwise.
template <typename T>
T keyword_value(const py::handle& value, const std::string& keyword, const char* expected) {
  const bool is_bool = py::isinstance<py::bool_>(value);
  if constexpr (std::is_same_v<T, bool>) {
    if (!is_bool)
      throw py::type_error(keyword + ": expected " + expected + ", got " + type_name(value));
  } else if constexpr (std::is_arithmetic_v<T>) {
    if (is_bool || !(py::isinstance<py::int_>(value) ||
                     (std::is_floating_point_v<T> && py::isinstance<py::float_>(value))))
      throw py::type_error(keyword + ": expected " + expected + ", got " + type_name(value));
  }
  try {
    return value.cast<T>();
  } catch (const py::cast_error&) {
    throw py::type_error(keyword + ": expected " + expected + ", got " + type_name(value));
  }
}

std::filesystem::path path_value(const py::handle& value, const std::string& keyword) {
  if (!py::isinstance<py::str>(value) && !py::hasattr(value, "__fspath__"))
    throw py::type_error(keyword + ": expected a path (str or os.PathLike), got " +
                         type_name(value));
  return value.cast<std::filesystem::path>();
}

// A keyword's value as the table's kind wants it (TypeError naming the keyword otherwise), with
// the text Python prints for each number (the messages quote it, as the CLI quotes what was
// typed).
std::pair<RunValue, std::vector<std::string>> keyword_run_value(const RunOption& option,
                                                                const py::handle& value) {
  const std::string& keyword = option.keyword;
  switch (option.kind) {
    case RunOptionKind::flag:
    case RunOptionKind::negated_flag:
      return {keyword_value<bool>(value, keyword, "a bool"), {}};
    case RunOptionKind::integer:
      return {keyword_value<long long>(value, keyword, "an int"), {py::str(value)}};
    case RunOptionKind::real:
      return {keyword_value<double>(value, keyword, "a float"), {py::str(value)}};
    case RunOptionKind::real_pair: {
      const auto pair =
          keyword_value<std::pair<double, double>>(value, keyword, "(millimetres, degrees)");
      return {pair, {py::str(py::cast(pair.first)), py::str(py::cast(pair.second))}};
    }
    case RunOptionKind::choice:
    case RunOptionKind::text:
      return {keyword_value<std::string>(value, keyword, "a str"), {}};
    case RunOptionKind::path:
      return {path_value(value, keyword).string(), {}};
  }
  throw py::type_error(keyword + ": not an option");
}

void set_keyword(RunSettings& settings, const std::string& key, const py::handle& value) {
  const RunOption* option = find_run_option_by_keyword(key);
  if (option == nullptr) {
    std::string names;
    for (const RunOption& entry : run_option_table()) {
      if (entry.keyword == "mode") continue;  // System's second argument
      names += (names.empty() ? "" : ", ") + entry.keyword;
    }
    throw py::type_error("System: unexpected keyword '" + key + "' (the run options: " + names +
                         ")");
  }
  const auto [run_value, shown] = keyword_run_value(*option, value);
  if (const std::string problem = run_value_problem(*option, run_value, shown); !problem.empty())
    throw py::value_error(key + ": " + problem);
  option->set(settings, run_value);
}

// The `pspslam run` flags as keywords (session/run_option_table.h): `--mask-margin 3` is
// mask_margin=3, `--no-local-mapping` is local_mapping=False, `--dynamic` is mode.
RunSettings run_settings(const std::string& mode, const py::kwargs& keywords) {
  RunSettings settings;
  set_keyword(settings, "mode", py::str(mode));
  for (const auto& [key_object, value] : keywords)
    set_keyword(settings, py::str(key_object), value);
  return settings;
}

// The table as Python data: what each keyword is, its flag, range or choices and default.
py::list run_option_list() {
  py::list options;
  const RunSettings defaults;
  for (const RunOption& option : run_option_table()) {
    py::dict entry;
    entry["keyword"] = option.keyword;
    entry["flag"] = option.flag.empty() ? py::object(py::none()) : py::object(py::str(option.flag));
    static constexpr const char* kinds[] = {"flag",   "negated_flag", "integer", "real",
                                            "choice", "text",         "path",    "real_pair"};
    entry["kind"] = kinds[static_cast<int>(option.kind)];
    entry["low"] = option.low;
    entry["high"] = option.high;
    entry["choices"] = option.choices;
    entry["default"] = option.value_text(defaults);
    entry["help"] = option.help;
    options.append(entry);
  }
  return options;
}

// The config argument: a YAML file, a dict of the same keys, or a sequence (its config as
// `pspslam run` reads it: SEQUENCE/config.yaml, a KITTI calibration).
std::pair<SystemConfig, std::string> config_from(const py::handle& config) {
  if (py::isinstance<PySequence>(config)) {
    const SequenceSetup& setup = config.cast<const PySequence&>().setup();
    return {setup.config, setup.config_file.string()};
  }
  if (py::isinstance<py::dict>(config)) {
    const std::string yaml = py::str(py::module_::import("json").attr("dumps")(config));
    return {parse_config(yaml, "config dict"), "config dict"};
  }
  const std::filesystem::path file = path_value(config, "config");
  return {load_config(file), file.string()};
}

// The 2D grid's band as `pspslam run --grid-min-height --grid-max-height --grid-floor` takes it,
// checked by the same GridOptions::validate(), its message naming the keywords.
GridOptions grid_band(double min_height, double max_height, const std::optional<double>& floor) {
  GridOptions band{.min_height_m = min_height, .max_height_m = max_height, .floor_height_m = floor};
  try {
    band.validate();
  } catch (const Error& e) {
    std::string message = e.what();
    for (const auto& [flag, keyword] :
         {std::pair{"flags ", ""}, std::pair{"flag ", ""},
          std::pair{"--grid-min-height", "min_height"},
          std::pair{"--grid-max-height", "max_height"}, std::pair{"--grid-floor", "floor"}}) {
      for (size_t at = message.find(flag); at != std::string::npos; at = message.find(flag))
        message.replace(at, std::string(flag).size(), keyword);
    }
    throw py::value_error(message);
  }
  return band;
}

std::unique_ptr<PySystem> make_system(const py::handle& config, const std::string& mode,
                                      const std::optional<std::string>& sensor, bool keypoints,
                                      const py::kwargs& options) {
  const RunSettings settings = run_settings(mode, options);
  auto [system_config, name] = config_from(config);
  if (sensor) apply_sensor_override(system_config, parse_sensor_type(*sensor, "sensor"), name);
  return std::make_unique<PySystem>(std::move(system_config), std::move(name), settings, keypoints);
}

py::object optional_view(const cv::Mat& mat) {
  return mat.empty() ? py::none() : py::object(view_of(mat));
}

void register_frame(py::module_& m) {
  py::class_<PyFrame>(m, "Frame",
                      "One frame: image (HxWx3 uint8 BGR), depth (HxW float32 metres) or right "
                      "(HxW uint8) as read-only views, timestamp (s), index, name.")
      .def_property_readonly("index", [](const PyFrame& f) { return f.frame->index; })
      .def_property_readonly("timestamp", [](const PyFrame& f) { return f.frame->timestamp; })
      .def_property_readonly("name", [](const PyFrame& f) { return f.frame->name; })
      .def_property_readonly("image", [](const PyFrame& f) { return view_of(f.frame->bgr); })
      .def_property_readonly("gray", [](const PyFrame& f) { return optional_view(f.frame->gray); })
      .def_property_readonly("depth",
                             [](const PyFrame& f) { return optional_view(f.frame->depth); })
      .def_property_readonly("right",
                             [](const PyFrame& f) { return optional_view(f.frame->right); })
      .def("__repr__", [](const PyFrame& f) {
        return "<pspslam.Frame " + std::to_string(f.frame->index) +
               " t=" + std::to_string(f.frame->timestamp) + " " +
               std::to_string(f.frame->bgr.cols) + "x" + std::to_string(f.frame->bgr.rows) + ">";
      });
}

py::array_t<float> keypoint_positions(const std::vector<KeypointRecord>& records) {
  py::array_t<float> positions({static_cast<py::ssize_t>(records.size()), py::ssize_t{2}});
  auto xy = positions.mutable_unchecked<2>();
  for (size_t i = 0; i < records.size(); ++i) {
    xy(static_cast<py::ssize_t>(i), 0) = records[i].position.x;
    xy(static_cast<py::ssize_t>(i), 1) = records[i].position.y;
  }
  return positions;
}

py::array_t<std::uint8_t> keypoint_fates(const std::vector<KeypointRecord>& records) {
  py::array_t<std::uint8_t> fates(static_cast<py::ssize_t>(records.size()));
  auto fate = fates.mutable_unchecked<1>();
  for (size_t i = 0; i < records.size(); ++i)
    fate(static_cast<py::ssize_t>(i)) = static_cast<std::uint8_t>(records[i].fate);
  return fates;
}

py::list people_list(const PeopleFrame& frame) {
  py::list people;
  for (const TrackedPerson& person : frame.people) {
    py::dict entry;
    entry["id"] = person.id;
    entry["position"] = py::array_t<double>(3, person.position.data());
    entry["velocity"] = py::array_t<double>(3, person.velocity.data());
    entry["extent"] = person.extent_m;
    entry["visible_pixels"] = person.visible_pixels;
    people.append(entry);
  }
  return people;
}

void register_result(py::module_& m) {
  py::class_<PyResult>(m, "Result", "What track() made of one frame.")
      .def_property_readonly("timestamp", [](const PyResult& r) { return r.timestamp; })
      .def_property_readonly(
          "pose",
          [](const PyResult& r) -> py::object {
            const std::optional<Pose>& pose = r.report.tracking.T_world_camera;
            return pose ? py::object(pose_matrix(*pose)) : py::none();
          },
          "4x4 float64 camera-to-world pose, None when the frame was not tracked")
      .def_property_readonly(
          "state", [](const PyResult& r) { return to_string(r.report.tracking.state); },
          "'ok', 'lost' or 'not_initialized'")
      .def_property_readonly("method",
                             [](const PyResult& r) { return to_string(r.report.tracking.method); })
      .def_property_readonly("keyframe",
                             [](const PyResult& r) { return r.report.tracking.keyframe_inserted; })
      .def_property_readonly("inliers",
                             [](const PyResult& r) { return r.report.tracking.num_inliers; })
      .def_property_readonly(
          "mask", [](const PyResult& r) { return view_of(r.mask); },
          "the frame's final dynamic mask (semantic + geometry): HxW uint8, non-zero = dynamic; "
          "a read-only view, no copy")
      .def_property_readonly(
          "keypoints", [](const PyResult& r) { return keypoint_positions(r.report.keypoints); },
          "Nx2 float32 keypoint positions (pixels); empty unless System(keypoints=True)")
      .def_property_readonly(
          "fates", [](const PyResult& r) { return keypoint_fates(r.report.keypoints); },
          "N uint8: what became of each keypoint, an index into pspslam.FATES")
      .def_property_readonly(
          "earlier_poses",
          [](const PyResult& r) { return trajectory_arrays(r.report.tracking.earlier_frames); },
          "(timestamps, poses) of earlier frames placed by the frame that started a monocular "
          "map; empty otherwise")
      .def_property_readonly(
          "map_id", [](const PyResult& r) { return r.report.tracking.map_id; },
          "the map of the atlas the pose is in, as the frame was tracked (maps merge later)")
      .def_property_readonly(
          "new_map", [](const PyResult& r) { return r.report.tracking.new_map; },
          "the frame started a map while others existed (new_map_after seconds lost)")
      .def_property_readonly(
          "restarted", [](const PyResult& r) { return r.report.tracking.restart_due; },
          "a monocular map was lost while young and starts anew: the poses "
          "so far belong to the old map")
      .def_property_readonly(
          "people", [](const PyResult& r) { return people_list(r.report.people); },
          "the people tracked in this frame: a list of dicts with 'id', 'position' and "
          "'velocity' (world frame of the map, metres and m/s), 'extent' (m) and "
          "'visible_pixels'; empty without depth (monocular) or without the network's labels")
      .def_property_readonly("extraction_ms",
                             [](const PyResult& r) { return r.report.extraction_ms; })
      .def_property_readonly("tracking_ms", [](const PyResult& r) { return r.report.tracking_ms; })
      .def("__repr__", [](const PyResult& r) {
        return "<pspslam.Result t=" + std::to_string(r.timestamp) + " " +
               to_string(r.report.tracking.state) + ">";
      });
}

void register_system(py::module_& m) {
  py::class_<PySystem>(m, "System")
      .def(py::init(&make_system), py::arg("config"), py::arg("mode") = "auto",
           py::arg("sensor") = py::none(), py::arg("keypoints") = false)
      .def(
          "make_frame",
          [](PySystem& s, const py::handle& image, const py::handle& depth, const py::handle& right,
             const py::handle& timestamp) { return s.make_frame(image, depth, right, timestamp); },
          py::arg("image"), py::arg("depth") = py::none(), py::arg("right") = py::none(),
          py::kw_only(), py::arg("timestamp") = py::none())
      .def(
          "track",
          [](PySystem& s, const py::handle& image, const py::handle& depth, const py::handle& right,
             const py::handle& timestamp) {
            if (py::isinstance<PyFrame>(image)) {
              if (!depth.is_none() || !right.is_none() || !timestamp.is_none())
                throw py::value_error("track: a Frame carries its own depth, right and timestamp");
              return s.track(image.cast<const PyFrame&>());
            }
            return s.track(s.make_frame(image, depth, right, timestamp));
          },
          py::arg("image"), py::arg("depth") = py::none(), py::arg("right") = py::none(),
          py::kw_only(), py::arg("timestamp") = py::none())
      .def("announce", &PySystem::announce, py::arg("frame"))
      .def("shutdown", &PySystem::shutdown)
      .def("map_points", &PySystem::map_points)
      .def("keyframe_poses", &PySystem::keyframe_trajectory)
      .def("refined_poses", &PySystem::refined_trajectory,
           "The final trajectory (pspslam run's trajectory_refined.txt, the file to evaluate): "
           "(timestamps, Nx4x4 camera-to-world poses) of every tracked frame moved with the "
           "bundle-adjusted keyframes around it. Finishes the run first, as close() does.")
      .def("save_map", &PySystem::save_map, py::arg("path"))
      .def(
          "occupancy_grid",
          [](PySystem& s, double min_height, double max_height,
             const std::optional<double>& floor) {
            return s.occupancy_grid(grid_band(min_height, max_height, floor));
          },
          py::kw_only(), py::arg("min_height") = GridOptions{}.min_height_m,
          py::arg("max_height") = GridOptions{}.max_height_m, py::arg("floor") = py::none(),
          "the occupancy map's 2D grid over the band min_height..max_height metres above the "
          "floor (floor: its height, None: found in the map), as `pspslam run --export-grid` "
          "writes it: grid (int8 rows x cols, row 0 at the origin's y; -1 unknown, 0 free, 100 "
          "occupied), resolution, origin (x, y), T_world_grid (4x4) and floor_height")
      .def_property_readonly("mode", &PySystem::dynamic_mode)
      .def_property_readonly(
          "settings",
          [](const PySystem& s) {
            py::dict settings;
            for (const auto& [keyword, value] : s.settings()) settings[py::str(keyword)] = value;
            return settings;
          },
          "every run setting the System got, the run's own defaults resolved, as text: what "
          "`pspslam run` writes to stats.json \"settings\"")
      .def_property_readonly("sensor",
                             [](const PySystem& s) { return to_string(s.config().camera.type); })
      .def_property_readonly("image_size", [](const PySystem& s) {
        return py::make_tuple(s.config().camera.pinhole.width, s.config().camera.pinhole.height);
      });
}

void register_sequence(py::module_& m) {
  py::class_<PySequence, std::shared_ptr<PySequence>>(m, "Sequence")
      .def(py::init([](const py::handle& folder, const py::handle& config,
                       const std::optional<std::string>& sensor, size_t max_frames) {
             std::optional<std::filesystem::path> config_file;
             if (!config.is_none()) config_file = path_value(config, "config");
             return std::make_shared<PySequence>(path_value(folder, "folder"), config_file, sensor,
                                                 max_frames);
           }),
           py::arg("folder"), py::arg("config") = py::none(), py::arg("sensor") = py::none(),
           py::arg("max_frames") = 0)
      .def("__len__", &PySequence::size)
      .def("__getitem__", &PySequence::frame)
      .def("__iter__",
           [](const std::shared_ptr<PySequence>& sequence) {
             return PySequenceIterator{sequence, 0};
           })
      .def_property_readonly("ground_truth", &PySequence::ground_truth)
      .def_property_readonly("config_file",
                             [](const PySequence& s) { return s.setup().config_file; })
      .def_property_readonly("folder",
                             [](const PySequence& s) { return s.setup().sequence->directory(); });
  py::class_<PySequenceIterator>(m, "SequenceIterator")
      .def("__iter__", [](PySequenceIterator& it) -> PySequenceIterator& { return it; })
      .def("__next__", [](PySequenceIterator& it) {
        if (it.next >= it.sequence->size()) throw py::stop_iteration();
        return it.sequence->frame(it.next++);
      });
}

}  // namespace
}  // namespace pspslam::python

PYBIND11_MODULE(_pspslam, m) {
  using namespace pspslam;
  using namespace pspslam::python;
  m.doc() = "pspslam: visual SLAM with dynamic-feature removal, driven from numpy.";
  py::register_exception<Error>(m, "Error", PyExc_RuntimeError);
  m.attr("FATES") = py::make_tuple("tracked", "unmatched", "semantic", "geometry");
  m.attr("__version__") = version_string();
  m.def("data_dir", &data_dir, "Where the shipped models, vocabulary and configs are.");
  m.def("run_options", &run_option_list,
        "The System's keyword options: keyword, the `pspslam run` flag, kind, range or choices, "
        "default (as text; empty: the run's own) and help.");
  register_frame(m);
  register_result(m);
  register_system(m);
  register_sequence(m);
  register_evaluation(m);
}
