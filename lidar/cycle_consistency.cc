#include "lidar/cycle_consistency.h"

#include "lidar/check_option.h"

#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

namespace colmap_lidar {
namespace {

struct Cycle {
  size_t edges[3];
  double translation_m = 0;
  double rotation_deg = 0;
  bool closed = false;
};

// from_to[{a, b}] = (edge index, lidar_a_from_lidar_b) for both directions of every edge.
using Directed = std::map<std::pair<size_t, size_t>, std::pair<size_t, Eigen::Isometry3d>>;

std::vector<Cycle> FindCycles(const std::vector<RelativePose>& edges,
                              const CycleConsistencyOptions& options) {
  Directed directed;
  for (size_t e = 0; e < edges.size(); ++e) {
    const RelativePose& r = edges[e];
    directed[{r.target, r.source}] = {e, r.target_from_source};
    directed[{r.source, r.target}] = {e, r.target_from_source.inverse()};
  }
  std::vector<Cycle> cycles;
  for (const auto& [ij, first] : directed) {
    const auto [i, j] = ij;
    if (i >= j) continue;
    for (auto it = directed.lower_bound({j, 0}); it != directed.end() && it->first.first == j;
         ++it) {
      const size_t k = it->first.second;
      if (k <= j) continue;  // each cycle once: i < j < k
      const auto back = directed.find({k, i});
      if (back == directed.end()) continue;
      const Eigen::Isometry3d loop = first.second * it->second.second * back->second.second;
      Cycle cycle{{first.first, it->second.first, back->second.first}};
      cycle.translation_m = loop.translation().norm();
      cycle.rotation_deg = Eigen::AngleAxisd(loop.linear()).angle() * 180 / M_PI;
      cycle.closed = cycle.translation_m <= options.max_translation_m &&
                     cycle.rotation_deg <= options.max_rotation_deg;
      cycles.push_back(cycle);
    }
  }
  return cycles;
}

}  // namespace

bool CycleConsistencyOptions::Check() const {
  LIDAR_CHECK_OPTION_GT(max_translation_m, 0);
  LIDAR_CHECK_OPTION_GT(max_rotation_deg, 0);
  return true;
}

CycleCheck CheckThreeCycles(const std::vector<RelativePose>& edges,
                            const CycleConsistencyOptions& options) {
  ThrowUnlessValid(options, "CycleConsistencyOptions");
  const std::vector<Cycle> cycles = FindCycles(edges, options);
  CycleCheck check;
  check.num_cycles = cycles.size();
  check.removed.assign(edges.size(), false);
  check.reason.assign(edges.size(), "");
  while (true) {
    // Per kept edge: its closed and broken cycles among cycles of kept edges, and the worst loop.
    std::vector<int> closed(edges.size(), 0), broken(edges.size(), 0);
    std::vector<double> worst(edges.size(), 0);
    for (const Cycle& c : cycles) {
      if (check.removed[c.edges[0]] || check.removed[c.edges[1]] || check.removed[c.edges[2]]) {
        continue;
      }
      for (size_t e : c.edges) {
        (c.closed ? closed : broken)[e]++;
        worst[e] = std::max(worst[e], c.translation_m);
      }
    }
    int candidate = -1;
    for (size_t e = 0; e < edges.size(); ++e) {
      if (check.removed[e] || broken[e] == 0 || closed[e] > 0) continue;
      if (candidate < 0 || broken[e] > broken[candidate] ||
          (broken[e] == broken[candidate] && edges[e].weight < edges[candidate].weight)) {
        candidate = static_cast<int>(e);
      }
    }
    if (candidate < 0) break;
    check.removed[candidate] = true;
    std::ostringstream reason;
    reason << "inconsistent: breaks " << broken[candidate] << " 3-cycle(s) and closes none (loop "
           << "error up to " << worst[candidate] << " m)";
    check.reason[candidate] = reason.str();
  }
  for (const Cycle& c : cycles) {
    if (check.removed[c.edges[0]] || check.removed[c.edges[1]] || check.removed[c.edges[2]]) {
      continue;
    }
    check.worst_translation_m = std::max(check.worst_translation_m, c.translation_m);
    check.worst_rotation_deg = std::max(check.worst_rotation_deg, c.rotation_deg);
  }
  return check;
}

}  // namespace colmap_lidar
