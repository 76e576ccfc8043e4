#include "pspslam/persistence/map_file.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "pspslam/core/checksum.h"
#include "pspslam/core/error.h"
#include "pspslam/map/camera_model.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/map/scale_pyramid.h"

// File format, version 2 (little-endian, no padding):
//   header (32 bytes): char[8] "PSPSLMAP", u32 version, u32 reserved (0), u64 payload bytes,
//                      u64 FNV-1a 64 of the payload
//   payload:
//     camera   f64 fx, fy, cx, cy, bf; u32 width, height; u32 pyramid levels; f64 scale factor
//     counts   u64 keyframes, u64 map points
//     points   per map point: u64 id, f64 x, y, z (world), u64 reference keyframe id,
//              u64 first keyframe id
//     keyframes per keyframe (ascending id): u64 id, u64 frame id, f64 timestamp,
//              f64[12] T_camera_world (rotation row-major, then translation), u64 parent id
//              (kNone: none), u32 map id and u32 anchor (0 or 1) in the atlas, u32 keypoints N,
//              then per keypoint f32 x, y, size, angle,
//              response, i32 octave, f32 depth, u64 map point id (kNone: none);
//              then N x 32 descriptor bytes
// Version 1 is version 2 without the map id and anchor: one map, anchored by its first keyframe.
// Everything else (observations, descriptors and normals of points, covisibility) is derived
// on load, so the file cannot contradict itself there.

namespace pspslam {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the map file is little-endian and written by memcpy");

constexpr std::array<char, 8> kMagic = {'P', 'S', 'P', 'S', 'L', 'M', 'A', 'P'};
constexpr std::uint32_t kFormatVersion = 2;
constexpr std::uint32_t kOldestReadableVersion = 1;
constexpr std::size_t kHeaderBytes = 32;
constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();
constexpr std::size_t kKeypointBytes = 5 * 4 + 4 + 4 + 8;
constexpr std::size_t kDescriptorBytes = 32;

class Writer {
 public:
  template <typename T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* bytes = reinterpret_cast<const char*>(&value);
    buffer_.insert(buffer_.end(), bytes, bytes + sizeof(T));
  }
  void put_bytes(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const char*>(data);
    buffer_.insert(buffer_.end(), bytes, bytes + size);
  }
  std::vector<char>& buffer() { return buffer_; }

 private:
  std::vector<char> buffer_;
};

// Bounds-checked reading of the payload; every failure names the file, the byte offset and
// what was being read.
class Reader {
 public:
  Reader(const char* data, std::size_t size, std::string prefix)
      : data_(data), size_(size), prefix_(std::move(prefix)) {}

  template <typename T>
  T get(const char* what) {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T), what);
    T value;
    std::memcpy(&value, data_ + offset_, sizeof(T));
    offset_ += sizeof(T);
    return value;
  }
  const char* take(std::size_t bytes, const char* what) {
    need(bytes, what);
    const char* at = data_ + offset_;
    offset_ += bytes;
    return at;
  }
  std::size_t remaining() const { return size_ - offset_; }
  std::size_t offset() const { return offset_; }
  [[noreturn]] void fail(const std::string& message) const {
    throw Error(prefix_ + "inconsistent content at payload byte " + std::to_string(offset_) + ": " +
                message);
  }

 private:
  void need(std::size_t bytes, const char* what) const {
    if (bytes > size_ - offset_) {
      throw Error(prefix_ + "truncated payload: " + what + " needs " + std::to_string(bytes) +
                  " bytes at payload byte " + std::to_string(offset_) + ", only " +
                  std::to_string(size_ - offset_) + " left");
    }
  }

  const char* data_;
  std::size_t size_;
  std::size_t offset_ = 0;
  std::string prefix_;
};

void put_pose(Writer& out, const Pose& pose) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.put(pose.linear()(r, c));
  }
  for (int r = 0; r < 3; ++r) out.put(pose.translation()(r));
}

Pose get_pose(Reader& in) {
  Pose pose = Pose::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose.linear()(r, c) = in.get<double>("keyframe pose");
  }
  for (int r = 0; r < 3; ++r) pose.translation()(r) = in.get<double>("keyframe pose");
  if (!pose.matrix().allFinite()) in.fail("keyframe pose is not finite");
  const double orthogonality =
      (pose.linear() * pose.linear().transpose() - Eigen::Matrix3d::Identity()).norm();
  if (orthogonality > 1e-6) in.fail("keyframe rotation is not orthonormal");
  return pose;
}

void check_same(const std::string& prefix, const char* field, double in_file, double in_use) {
  if (std::abs(in_file - in_use) <= 1e-6 * std::max(1.0, std::abs(in_use))) return;
  std::ostringstream message;
  message << prefix << "made with " << field << " = " << in_file << " but the configuration in use "
          << "has " << in_use << " (load a map with the camera config it was built with)";
  throw Error(message.str());
}

struct PointRecord {
  std::uint64_t id = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::uint64_t reference_keyframe = kNone;
  std::uint64_t first_keyframe = 0;
};

struct KeyFrameRecord {
  std::uint64_t id = 0;
  std::uint64_t parent = kNone;
  std::uint32_t map_id = 0;
  std::optional<bool> anchor;  // none (version 1): the map's first keyframe
  KeyFrameData data;
  std::vector<std::uint64_t> point_ids;  // per keypoint
};

void put_camera(Writer& out, const CameraModel& camera, const ScalePyramid& pyramid) {
  out.put(camera.pinhole.fx);
  out.put(camera.pinhole.fy);
  out.put(camera.pinhole.cx);
  out.put(camera.pinhole.cy);
  out.put(camera.bf);
  out.put(static_cast<std::uint32_t>(camera.pinhole.width));
  out.put(static_cast<std::uint32_t>(camera.pinhole.height));
  out.put(static_cast<std::uint32_t>(pyramid.levels));
  out.put(pyramid.scale_factor);
}

void put_point(Writer& out, const MapPoint& point) {
  out.put(point.id());
  const Eigen::Vector3d position = point.position();
  for (int r = 0; r < 3; ++r) out.put(position(r));
  const auto reference = point.reference_keyframe();
  out.put(reference && !reference->is_bad() ? reference->id() : kNone);
  out.put(point.first_keyframe_id);
}

// A keyframe with its keypoints, their associations to the saved points and the descriptors.
// Returns the number of observations written.
std::size_t put_keyframe(Writer& out, const KeyFrame& keyframe,
                         const std::unordered_map<std::uint64_t, bool>& saved_point) {
  out.put(keyframe.id());
  out.put(keyframe.frame_id());
  out.put(keyframe.timestamp());
  put_pose(out, keyframe.T_camera_world());
  const auto parent = keyframe.parent();
  out.put(parent && !parent->is_bad() ? parent->id() : kNone);
  out.put(keyframe.map_id());
  out.put(static_cast<std::uint32_t>(keyframe.is_anchor() ? 1 : 0));
  const int n = keyframe.size();
  out.put(static_cast<std::uint32_t>(n));
  const auto associations = keyframe.map_points();
  std::size_t observations = 0;
  for (int i = 0; i < n; ++i) {
    const cv::KeyPoint& kp = keyframe.keypoints()[i];
    out.put(kp.pt.x);
    out.put(kp.pt.y);
    out.put(kp.size);
    out.put(kp.angle);
    out.put(kp.response);
    out.put(static_cast<std::int32_t>(kp.octave));
    out.put(keyframe.depth(i));
    const auto& point = associations[i];
    const bool saved = point && saved_point.contains(point->id());
    out.put(saved ? point->id() : kNone);
    observations += saved ? 1 : 0;
  }
  for (int i = 0; i < n; ++i) out.put_bytes(keyframe.descriptor(i), kDescriptorBytes);
  return observations;
}

// The header (magic, version, size and checksum of the payload), then the payload.
void write_map_file(const std::filesystem::path& file, const std::vector<char>& payload) {
  Writer header;
  header.put_bytes(kMagic.data(), kMagic.size());
  header.put(kFormatVersion);
  header.put(std::uint32_t{0});
  header.put(static_cast<std::uint64_t>(payload.size()));
  header.put(fnv1a64(payload.data(), payload.size()));

  std::ofstream stream(file, std::ios::binary | std::ios::trunc);
  if (!stream) throw Error("map file '" + file.string() + "': cannot open for writing");
  stream.write(header.buffer().data(), static_cast<std::streamsize>(header.buffer().size()));
  stream.write(payload.data(), static_cast<std::streamsize>(payload.size()));
  stream.close();
  if (!stream) throw Error("map file '" + file.string() + "': write failed (disk full?)");
}

std::string read_whole_file(const std::filesystem::path& file, const std::string& prefix) {
  std::ifstream stream(file, std::ios::binary);
  if (!stream) throw Error(prefix + "cannot open for reading");
  return std::string((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
}

// The payload of a file whose header (magic, version, size, checksum) holds, and its version.
std::pair<std::string_view, std::uint32_t> checked_payload(const std::string& bytes,
                                                           const std::string& prefix) {
  if (bytes.size() >= kMagic.size() && !std::equal(kMagic.begin(), kMagic.end(), bytes.begin()))
    throw Error(prefix + "not a pspslam map (bad magic, expected \"PSPSLMAP\")");
  if (bytes.size() < kHeaderBytes) {
    throw Error(prefix + "truncated (the header needs " + std::to_string(kHeaderBytes) +
                " bytes, the file has " + std::to_string(bytes.size()) + ")");
  }
  Reader header(bytes.data(), kHeaderBytes, prefix);
  header.take(kMagic.size(), "magic");
  const auto version = header.get<std::uint32_t>("version");
  if (version < kOldestReadableVersion || version > kFormatVersion) {
    throw Error(prefix + "unsupported format version " + std::to_string(version) +
                " (this build reads versions " + std::to_string(kOldestReadableVersion) + " to " +
                std::to_string(kFormatVersion) + ")");
  }
  header.get<std::uint32_t>("reserved");
  const auto payload_bytes = header.get<std::uint64_t>("payload size");
  const auto stored_checksum = header.get<std::uint64_t>("checksum");
  if (bytes.size() - kHeaderBytes < payload_bytes) {
    throw Error(prefix + "truncated (header announces " + std::to_string(payload_bytes) +
                " payload bytes, the file has " + std::to_string(bytes.size() - kHeaderBytes) +
                ")");
  }
  if (bytes.size() - kHeaderBytes > payload_bytes) {
    throw Error(prefix + std::to_string(bytes.size() - kHeaderBytes - payload_bytes) +
                " unexpected bytes after the payload");
  }
  const char* payload = bytes.data() + kHeaderBytes;
  const std::uint64_t checksum = fnv1a64(payload, payload_bytes);
  if (checksum != stored_checksum) {
    throw Error(prefix + "checksum mismatch (stored " + hex64(stored_checksum) + ", computed " +
                hex64(checksum) + "): the file is corrupt");
  }
  return {{payload, payload_bytes}, version};
}

void check_camera(Reader& in, const std::string& prefix, const CameraModel& camera,
                  const ScalePyramid& pyramid) {
  check_same(prefix, "fx", in.get<double>("camera"), camera.pinhole.fx);
  check_same(prefix, "fy", in.get<double>("camera"), camera.pinhole.fy);
  check_same(prefix, "cx", in.get<double>("camera"), camera.pinhole.cx);
  check_same(prefix, "cy", in.get<double>("camera"), camera.pinhole.cy);
  check_same(prefix, "bf (fx * virtual baseline)", in.get<double>("camera"), camera.bf);
  check_same(prefix, "image width", in.get<std::uint32_t>("camera"), camera.pinhole.width);
  check_same(prefix, "image height", in.get<std::uint32_t>("camera"), camera.pinhole.height);
  check_same(prefix, "ORB pyramid levels", in.get<std::uint32_t>("pyramid"), pyramid.levels);
  check_same(prefix, "ORB scale factor", in.get<double>("pyramid"), pyramid.scale_factor);
}

// What the payload holds, checked, with the index of every id.
struct MapRecords {
  std::vector<PointRecord> points;
  std::unordered_map<std::uint64_t, std::size_t> point_index;
  std::vector<KeyFrameRecord> keyframes;
  std::unordered_map<std::uint64_t, std::size_t> keyframe_index;
};

void read_points(Reader& in, std::uint64_t point_count, MapRecords& records) {
  // Counts are checked against what the rest of the payload could hold before reserving.
  if (point_count > in.remaining() / 48) in.fail("map point count " + std::to_string(point_count));
  records.points.resize(point_count);
  for (PointRecord& record : records.points) {
    record.id = in.get<std::uint64_t>("map point id");
    for (int r = 0; r < 3; ++r) record.position(r) = in.get<double>("map point position");
    record.reference_keyframe = in.get<std::uint64_t>("map point reference keyframe");
    record.first_keyframe = in.get<std::uint64_t>("map point first keyframe");
    if (!record.position.allFinite())
      in.fail("map point " + std::to_string(record.id) + " position is not finite");
    if (!records.point_index.emplace(record.id, records.point_index.size()).second)
      in.fail("map point id " + std::to_string(record.id) + " appears twice");
  }
}

// A keyframe's keypoints, map point ids and descriptors.
void read_keypoints(Reader& in, int pyramid_levels,
                    const std::unordered_map<std::uint64_t, std::size_t>& point_index,
                    KeyFrameRecord& record) {
  const auto n = in.get<std::uint32_t>("keypoint count");
  if (n > in.remaining() / (kKeypointBytes + kDescriptorBytes))
    in.fail("keyframe " + std::to_string(record.id) + " keypoint count " + std::to_string(n));
  record.data.keypoints.resize(n);
  record.data.depth.resize(n);
  record.point_ids.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    cv::KeyPoint& kp = record.data.keypoints[i];
    kp.pt.x = in.get<float>("keypoint");
    kp.pt.y = in.get<float>("keypoint");
    kp.size = in.get<float>("keypoint");
    kp.angle = in.get<float>("keypoint");
    kp.response = in.get<float>("keypoint");
    kp.octave = in.get<std::int32_t>("keypoint");
    record.data.depth[i] = in.get<float>("keypoint depth");
    record.point_ids[i] = in.get<std::uint64_t>("keypoint map point");
    if (kp.octave < 0 || kp.octave >= pyramid_levels || !std::isfinite(kp.pt.x) ||
        !std::isfinite(kp.pt.y) || !std::isfinite(record.data.depth[i]))
      in.fail("keyframe " + std::to_string(record.id) + " keypoint " + std::to_string(i));
    if (record.point_ids[i] != kNone && !point_index.contains(record.point_ids[i]))
      in.fail("keyframe " + std::to_string(record.id) + " refers to unknown map point " +
              std::to_string(record.point_ids[i]));
  }
  const char* descriptors = in.take(std::size_t{n} * kDescriptorBytes, "descriptors");
  record.data.descriptors.create(static_cast<int>(n), static_cast<int>(kDescriptorBytes), CV_8UC1);
  if (n > 0)
    std::memcpy(record.data.descriptors.data, descriptors, std::size_t{n} * kDescriptorBytes);
}

void read_keyframes(Reader& in, std::uint32_t version, std::uint64_t keyframe_count,
                    int pyramid_levels, MapRecords& records) {
  if (keyframe_count == 0) in.fail("no keyframes");
  if (keyframe_count > in.remaining() / 140)
    in.fail("keyframe count " + std::to_string(keyframe_count));
  records.keyframes.resize(keyframe_count);
  for (KeyFrameRecord& record : records.keyframes) {
    record.id = in.get<std::uint64_t>("keyframe id");
    if (!records.keyframe_index.emplace(record.id, records.keyframe_index.size()).second)
      in.fail("keyframe id " + std::to_string(record.id) + " appears twice");
    if (records.keyframe_index.size() > 1 && record.id <= (&record - 1)->id)
      in.fail("keyframe ids are not ascending");
    record.data.frame_id = in.get<std::uint64_t>("keyframe frame id");
    record.data.timestamp = in.get<double>("keyframe timestamp");
    record.data.T_camera_world = get_pose(in);
    record.parent = in.get<std::uint64_t>("keyframe parent");
    if (version >= 2) {
      record.map_id = in.get<std::uint32_t>("keyframe map id");
      const auto anchor = in.get<std::uint32_t>("keyframe anchor");
      if (anchor > 1)
        in.fail("keyframe " + std::to_string(record.id) + " anchor " + std::to_string(anchor));
      record.anchor = anchor == 1;
    }
    read_keypoints(in, pyramid_levels, records.point_index, record);
  }
}

// The payload after the camera check: points, keyframes, and nothing left over.
MapRecords read_records(Reader& in, std::uint32_t version, const std::string& prefix,
                        int pyramid_levels) {
  MapRecords records;
  const auto keyframe_count = in.get<std::uint64_t>("keyframe count");
  const auto point_count = in.get<std::uint64_t>("map point count");
  read_points(in, point_count, records);
  read_keyframes(in, version, keyframe_count, pyramid_levels, records);
  if (in.remaining() != 0)
    in.fail(std::to_string(in.remaining()) + " bytes left after the last keyframe");
  for (const KeyFrameRecord& record : records.keyframes) {
    if (record.parent != kNone && !records.keyframe_index.contains(record.parent))
      throw Error(prefix + "inconsistent content: keyframe " + std::to_string(record.id) +
                  " has unknown parent " + std::to_string(record.parent));
  }
  return records;
}

std::vector<std::shared_ptr<MapPoint>> make_points(
    const MapRecords& records, const std::vector<std::shared_ptr<KeyFrame>>& keyframes) {
  std::vector<std::shared_ptr<MapPoint>> points;
  points.reserve(records.points.size());
  for (const PointRecord& record : records.points) {
    const auto reference = records.keyframe_index.find(record.reference_keyframe);
    const std::shared_ptr<KeyFrame>& reference_keyframe =
        keyframes[reference != records.keyframe_index.end() ? reference->second : 0];
    auto point = std::make_shared<MapPoint>(record.id, record.position, reference_keyframe);
    // Kept as saved even when that keyframe was culled before saving: only its order against
    // newer keyframes matters (recent-point culling), and the file must save back unchanged.
    point->first_keyframe_id = record.first_keyframe;
    points.push_back(point);
  }
  return points;
}

// Links keyframes and points both ways; returns the number of observations.
std::size_t add_observations(const MapRecords& records,
                             const std::vector<std::shared_ptr<KeyFrame>>& keyframes,
                             const std::vector<std::shared_ptr<MapPoint>>& points) {
  std::size_t observations = 0;
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    const auto& ids = records.keyframes[k].point_ids;
    for (int i = 0; i < static_cast<int>(ids.size()); ++i) {
      if (ids[i] == kNone) continue;
      const auto& point = points[records.point_index.at(ids[i])];
      // A point has one observation per keyframe (the live system enforces it too).
      if (point->is_observed_by(keyframes[k]->id())) continue;
      keyframes[k]->add_map_point(i, point);
      point->add_observation(keyframes[k], i);
      ++observations;
    }
  }
  return observations;
}

// Builds the map of consistent records; the summary has no byte count yet.
MapFileSummary build_map(MapRecords& records, Map& map, std::shared_ptr<const CameraModel> camera,
                         std::shared_ptr<const ScalePyramid> pyramid) {
  // Keyframes and points keep the ids they were saved with (the file is in ascending id order),
  // so a map loaded and saved again without change is the same file byte for byte (localisation
  // promises not to change the map); new ids continue after the largest loaded ones.
  std::lock_guard lock(map.update_mutex());
  std::uint64_t max_point_id = 0;
  for (const PointRecord& record : records.points) max_point_id = std::max(max_point_id, record.id);
  map.continue_ids_after(records.keyframes.empty() ? 0 : records.keyframes.back().id, max_point_id);
  std::vector<std::shared_ptr<KeyFrame>> keyframes;
  keyframes.reserve(records.keyframes.size());
  for (KeyFrameRecord& record : records.keyframes) {
    keyframes.push_back(
        std::make_shared<KeyFrame>(record.id, std::move(record.data), camera, pyramid));
    keyframes.back()->set_map(record.map_id, false);
    map.add_keyframe(keyframes.back());  // anchors the first of each map
    if (record.anchor) keyframes.back()->set_map(record.map_id, *record.anchor);
  }
  const std::vector<std::shared_ptr<MapPoint>> points = make_points(records, keyframes);
  MapFileSummary summary;
  summary.observations = add_observations(records, keyframes, points);
  for (const auto& point : points) {
    if (point->num_observations() == 0) continue;  // observed by no saved keyframe
    point->compute_distinctive_descriptor();
    point->update_normal_and_depth(*pyramid);
    map.add_map_point(point);
    ++summary.map_points;
  }
  // Spanning tree as saved (parents before update_connections, which would otherwise pick
  // the best covisible keyframe, possibly a later one), then covisibility.
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    const std::uint64_t parent = records.keyframes[k].parent;
    if (parent != kNone && parent != records.keyframes[k].id)
      keyframes[k]->change_parent(keyframes[records.keyframe_index.at(parent)]);
  }
  for (const auto& keyframe : keyframes) keyframe->update_connections();
  summary.keyframes = keyframes.size();
  return summary;
}

}  // namespace

MapFileSummary save_map(Map& map, const CameraModel& camera, const ScalePyramid& pyramid,
                        const std::filesystem::path& file) {
  std::lock_guard lock(map.update_mutex());
  const auto keyframes = map.keyframes();
  const auto points = map.map_points();
  std::unordered_map<std::uint64_t, bool> saved_point;
  saved_point.reserve(points.size());

  Writer out;
  put_camera(out, camera, pyramid);
  std::vector<std::shared_ptr<KeyFrame>> good_keyframes;
  for (const auto& keyframe : keyframes) {
    if (!keyframe->is_bad()) good_keyframes.push_back(keyframe);
  }
  std::vector<std::shared_ptr<MapPoint>> good_points;
  for (const auto& point : points) {
    if (point->is_bad()) continue;
    good_points.push_back(point);
    saved_point[point->id()] = true;
  }
  out.put(static_cast<std::uint64_t>(good_keyframes.size()));
  out.put(static_cast<std::uint64_t>(good_points.size()));
  for (const auto& point : good_points) put_point(out, *point);
  MapFileSummary summary;
  for (const auto& keyframe : good_keyframes)
    summary.observations += put_keyframe(out, *keyframe, saved_point);

  const std::vector<char>& payload = out.buffer();
  write_map_file(file, payload);
  summary.keyframes = good_keyframes.size();
  summary.map_points = good_points.size();
  summary.bytes = kHeaderBytes + payload.size();
  return summary;
}

MapFileSummary load_map(const std::filesystem::path& file, Map& map,
                        std::shared_ptr<const CameraModel> camera,
                        std::shared_ptr<const ScalePyramid> pyramid) {
  const std::string prefix = "map file '" + file.string() + "': ";
  const std::string bytes = read_whole_file(file, prefix);
  const auto [payload, version] = checked_payload(bytes, prefix);
  Reader in(payload.data(), payload.size(), prefix);
  check_camera(in, prefix, *camera, *pyramid);
  MapRecords records = read_records(in, version, prefix, pyramid->levels);

  // The file is consistent: build the map.
  if (map.num_keyframes() != 0 || map.num_map_points() != 0)
    throw Error(prefix + "cannot load into a map that already has keyframes or points");
  MapFileSummary summary = build_map(records, map, std::move(camera), std::move(pyramid));
  summary.bytes = bytes.size();
  return summary;
}

}  // namespace pspslam
