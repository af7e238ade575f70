#include "bridge/initialization/selected_frames.h"

#include "bridge/initialization/lidar_registration_files.h"
#include "colmap_ext/rigid3_isometry.h"
#include "colmap_ext/station_dataset.h"
#include "colmap_ext/text_lines.h"
#include "lidar/util/atomic_file.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;
using NamePair = std::pair<std::string, std::string>;

NamePair Unordered(const std::string& a, const std::string& b) {
  return a < b ? NamePair{a, b} : NamePair{b, a};
}

// The weakest quality of `edges` (see the header) on a record from `a` to `b`.
LidarPairRecord WeakestOf(const std::vector<const LidarPairRecord*>& edges) {
  LidarPairRecord weakest = *edges.front();
  for (const LidarPairRecord* e : edges) {
    weakest.num_inliers = std::min(weakest.num_inliers, e->num_inliers);
    weakest.overlap = std::min(weakest.overlap, e->overlap);
    weakest.rmse_m = std::max(weakest.rmse_m, e->rmse_m);
    weakest.noise_m = std::max(weakest.noise_m, e->noise_m);
    if (e->constraint_ratio < weakest.constraint_ratio) {
      weakest.constraint_ratio = e->constraint_ratio;
      weakest.weakest_axis = e->weakest_axis;
    }
    weakest.degenerate = weakest.degenerate || e->degenerate;
  }
  weakest.from_identity = false;
  return weakest;
}

// The accepted edges between kept frames, and the trajectory's edge between consecutive kept frames
// that only frames left out join (every consecutive frame pair between them has an edge).
std::vector<LidarPairRecord> SelectedPairs(const std::vector<LidarPairRecord>& pairs,
                                           const std::vector<std::string>& names,
                                           const std::vector<colmap::Rigid3d>& world_from_lidar,
                                           const std::vector<int>& kept,
                                           size_t* num_composed) {
  std::map<NamePair, const LidarPairRecord*> by_pair;
  for (const LidarPairRecord& p : pairs) by_pair.emplace(Unordered(p.target, p.source), &p);
  std::vector<bool> is_kept(names.size(), false);
  for (int i : kept) is_kept[i] = true;
  const auto index = [&names](const std::string& name) {
    return std::lower_bound(names.begin(), names.end(), name) - names.begin();
  };
  std::vector<LidarPairRecord> selected;
  for (const LidarPairRecord& p : pairs) {
    if (is_kept[index(p.target)] && is_kept[index(p.source)]) selected.push_back(p);
  }
  *num_composed = 0;
  for (size_t k = 1; k < kept.size(); ++k) {
    const int a = kept[k - 1], b = kept[k];
    if (b == a + 1 || by_pair.count(Unordered(names[a], names[b])) > 0) continue;
    std::vector<const LidarPairRecord*> chain;
    for (int m = a; m < b; ++m) {
      const auto edge = by_pair.find(Unordered(names[m], names[m + 1]));
      if (edge == by_pair.end()) break;
      chain.push_back(edge->second);
    }
    if (chain.size() != static_cast<size_t>(b - a)) continue;  // not joined: separate components
    LidarPairRecord composed = WeakestOf(chain);
    composed.target = names[a];
    composed.source = names[b];
    composed.target_from_source = colmap::Inverse(world_from_lidar[a]) * world_from_lidar[b];
    selected.push_back(composed);
    ++*num_composed;
  }
  return selected;
}

std::string SelectionTable(const std::vector<std::string>& names, const FrameSelection& selection) {
  std::ostringstream table;
  table << "# frame reason (first | distance | rotation | last: kept; left out), spacing factor "
        << selection.spacing_factor << "\n";
  for (size_t i = 0; i < names.size(); ++i) {
    table << names[i] << " " << FrameSelectionReasonName(selection.reasons[i]) << "\n";
  }
  return table.str();
}

}  // namespace

SelectedFramesSummary WriteSelectedFrames(const std::string& registration_path,
                                          const std::string& output_path,
                                          const FrameSelectionOptions& options) {
  const fs::path input(registration_path);
  const std::map<std::string, colmap::Rigid3d> poses =
      ReadNamedPoses((input / "lidar_poses.txt").string());
  const std::vector<LidarPairRecord> pairs = ReadLidarPairs((input / "pairs.txt").string());
  std::vector<std::string> names;
  std::vector<colmap::Rigid3d> world_from_lidar;
  std::vector<Eigen::Isometry3d> trajectory;
  for (const auto& [name, pose] : poses) {
    names.push_back(name);
    world_from_lidar.push_back(pose);
    trajectory.push_back(ToIsometry(pose));
  }
  for (const LidarPairRecord& p : pairs) {
    if (poses.count(p.target) == 0 || poses.count(p.source) == 0) {
      throw std::runtime_error((input / "pairs.txt").string() + ": edge " + p.target + " " +
                               p.source + " names a station missing from lidar_poses.txt");
    }
  }
  const FrameSelection selection = SelectFrames(trajectory, options);
  SelectedFramesSummary summary;
  summary.num_frames = names.size();
  summary.num_kept = selection.kept.size();
  summary.spacing_factor = selection.spacing_factor;
  const std::vector<LidarPairRecord> selected_pairs =
      SelectedPairs(pairs, names, world_from_lidar, selection.kept, &summary.num_composed_edges);
  std::map<std::string, colmap::Rigid3d> kept_poses;
  for (int i : selection.kept) kept_poses.emplace(names[i], world_from_lidar[i]);

  const fs::path output(output_path), partial(output_path + ".partial");
  fs::remove_all(partial);
  fs::create_directories(partial);
  WriteNamedPoses((partial / "lidar_poses.txt").string(),
                  "world_from_lidar of the frames selected for the camera steps",
                  kept_poses);
  WriteLidarPairs((partial / "pairs.txt").string(), selected_pairs, {});
  WriteFileAtomically((partial / "selected_frames.txt").string(), SelectionTable(names, selection));
  fs::remove_all(output);
  fs::rename(partial, output);
  return summary;
}

std::vector<std::string> ReadSelectedFrames(const std::string& selected_path) {
  const std::string path = (fs::path(selected_path) / "selected_frames.txt").string();
  std::vector<std::string> kept;
  ForEachDataLine(path, [&](const std::string& line, size_t line_number) {
    std::istringstream fields(line);
    std::string name, reason;
    fields >> name;
    std::getline(fields >> std::ws, reason);
    bool known = false;
    for (FrameSelectionReason r : {FrameSelectionReason::kFirst,
                                   FrameSelectionReason::kDistance,
                                   FrameSelectionReason::kRotation,
                                   FrameSelectionReason::kLast,
                                   FrameSelectionReason::kLeftOut}) {
      known = known || reason == FrameSelectionReasonName(r);
    }
    if (!known) {
      throw std::runtime_error(path + ":" + std::to_string(line_number) +
                               ": expected \"<frame> <reason>\"");
    }
    if (reason != FrameSelectionReasonName(FrameSelectionReason::kLeftOut)) kept.push_back(name);
  });
  return kept;
}

}  // namespace colmap_lidar
