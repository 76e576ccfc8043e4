#include "pspslam/people/people_score.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

long long frame_key(Timestamp t) { return std::llround(t * 1e6); }

double quantile_of(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(q * (values.size() - 1) + 0.5);
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

struct FrameRows {
  std::vector<const PersonTruth*> truth;
  std::vector<const PersonEstimate*> estimates;
};

}  // namespace

std::vector<PersonTruth> read_people_truth(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot open the people ground truth");
  std::vector<PersonTruth> rows;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    PersonTruth row;
    Eigen::Vector3d& p = row.position;
    Eigen::Vector3d& v = row.velocity;
    if (!(fields >> row.timestamp >> row.id >> p.x() >> p.y() >> p.z() >> v.x() >> v.y() >> v.z() >>
          row.visible_pixels)) {
      throw Error(file.string() + ":" + std::to_string(number) +
                  ": expected 'timestamp id x y z vx vy vz visible_pixels'");
    }
    rows.push_back(row);
  }
  return rows;
}

void write_people_truth(const std::filesystem::path& file, const std::vector<PersonTruth>& rows) {
  std::ofstream out(file);
  out << "# every walking person at every frame: timestamp id x y z vx vy vz visible_pixels\n"
      << "# position: torso centre, world frame of groundtruth.txt (z up), metres; velocity m/s;\n"
      << "# visible_pixels: pixels of the colour image that show her (label 15)\n";
  char buffer[200];
  for (const PersonTruth& row : rows) {
    std::snprintf(buffer, sizeof(buffer), "%.6f %d %.4f %.4f %.4f %.4f %.4f %.4f %d\n",
                  row.timestamp, row.id, row.position.x(), row.position.y(), row.position.z(),
                  row.velocity.x(), row.velocity.y(), row.velocity.z(), row.visible_pixels);
    out << buffer;
  }
  if (!out) throw Error(file.string() + ": cannot write the people ground truth");
}

PeopleScore score_people(const std::vector<PersonTruth>& truth,
                         const std::vector<PersonEstimate>& estimates,
                         const std::function<std::optional<Pose>(Timestamp)>& truth_from_estimate,
                         const PeopleScoreOptions& options) {
  std::map<long long, FrameRows> frames;
  for (const PersonTruth& row : truth) frames[frame_key(row.timestamp)].truth.push_back(&row);
  for (const PersonEstimate& row : estimates) {
    const auto frame = frames.find(frame_key(row.timestamp));
    if (frame != frames.end()) frame->second.estimates.push_back(&row);
  }
  PeopleScore score;
  std::vector<double> errors, horizontal, velocity_errors;
  std::map<int, int> last_track_of;  // truth id -> the track id matched last
  std::set<int> ids;
  double previous_time = -1.0, period = 0.0;
  for (const auto& [key, rows] : frames) {
    const Timestamp t = static_cast<double>(key) * 1e-6;
    if (previous_time >= 0.0 && period == 0.0) period = t - previous_time;
    previous_time = t;
    const std::optional<Pose> T = truth_from_estimate(t);
    if (!T) continue;
    std::vector<std::tuple<double, size_t, size_t>> pairs;
    for (size_t i = 0; i < rows.truth.size(); ++i) {
      if (rows.truth[i]->visible_pixels <= 0) continue;
      for (size_t j = 0; j < rows.estimates.size(); ++j) {
        const double d = (*T * rows.estimates[j]->person.position - rows.truth[i]->position).norm();
        if (d <= options.match_distance_m) pairs.emplace_back(d, i, j);
      }
    }
    std::sort(pairs.begin(), pairs.end());
    std::vector<int> match(rows.truth.size(), -1);
    std::vector<bool> used(rows.estimates.size(), false);
    for (const auto& [d, i, j] : pairs) {
      if (match[i] >= 0 || used[j]) continue;
      match[i] = static_cast<int>(j);
      used[j] = true;
    }
    score.reported += static_cast<int>(rows.estimates.size());
    score.false_reports += static_cast<int>(std::count(used.begin(), used.end(), false));
    for (const PersonEstimate* row : rows.estimates) ids.insert(row->person.id);
    for (size_t i = 0; i < rows.truth.size(); ++i) {
      const PersonTruth& person = *rows.truth[i];
      const bool counted = person.visible_pixels >= options.min_visible_pixels;
      if (counted) ++score.person_frames;
      if (match[i] < 0) continue;
      const TrackedPerson& track = rows.estimates[static_cast<size_t>(match[i])]->person;
      if (counted) ++score.tracked;
      const Eigen::Vector3d error = *T * track.position - person.position;
      errors.push_back(error.norm());
      horizontal.push_back(error.head<2>().norm());
      velocity_errors.push_back((T->linear() * track.velocity - person.velocity).norm());
      const auto last = last_track_of.find(person.id);
      if (last != last_track_of.end() && last->second != track.id) ++score.id_switches;
      last_track_of[person.id] = track.id;
    }
  }
  score.person_minutes = score.person_frames * period / 60.0;
  score.median_position_error_m = quantile_of(errors, 0.5);
  score.p90_position_error_m = quantile_of(errors, 0.9);
  score.median_horizontal_error_m = quantile_of(horizontal, 0.5);
  score.median_velocity_error_mps = quantile_of(velocity_errors, 0.5);
  score.distinct_ids = static_cast<int>(ids.size());
  return score;
}

}  // namespace pspslam
