#include "lidar/cycle_consistency.h"

#include "lidar/util/check_option.h"

#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace colmap_lidar {
namespace {

struct Cycle {
  std::vector<size_t> edges;  // 3, or 2 for two edges between the same stations
  double translation_m = 0;
  double rotation_deg = 0;
  bool closed = false;
};

// from_to {a, b} -> (edge index, a_from_b) for both directions of every edge; parallel edges (two
// measurements of one pair) are all kept.
using Directed = std::multimap<std::pair<size_t, size_t>, std::pair<size_t, Eigen::Isometry3d>>;

Cycle MakeCycle(std::vector<size_t> edges,
                const Eigen::Isometry3d& loop,
                const CycleConsistencyOptions& options) {
  Cycle cycle{std::move(edges)};
  cycle.translation_m = loop.translation().norm();
  cycle.rotation_deg = Eigen::AngleAxisd(loop.linear()).angle() * 180 / M_PI;
  cycle.closed = cycle.translation_m <= options.max_translation_m &&
                 cycle.rotation_deg <= options.max_rotation_deg;
  return cycle;
}

std::vector<Cycle> FindCycles(const std::vector<RelativePose>& edges,
                              const CycleConsistencyOptions& options) {
  Directed directed;
  for (size_t e = 0; e < edges.size(); ++e) {
    const RelativePose& r = edges[e];
    directed.insert({{r.target, r.source}, {e, r.target_from_source}});
    directed.insert({{r.source, r.target}, {e, r.target_from_source.inverse()}});
  }
  std::vector<Cycle> cycles;
  for (const auto& [ij, first] : directed) {
    const auto [i, j] = ij;
    if (i >= j) continue;
    // Parallel edges: each later one with this one (i -> j, then back j -> i).
    for (auto [it, end] = directed.equal_range({j, i}); it != end; ++it) {
      if (it->second.first <= first.first) continue;
      cycles.push_back(
          MakeCycle({first.first, it->second.first}, first.second * it->second.second, options));
    }
    for (auto it = directed.lower_bound({j, 0}); it != directed.end() && it->first.first == j;
         ++it) {
      const size_t k = it->first.second;
      if (k <= j) continue;  // each cycle once: i < j < k
      for (auto [back, end] = directed.equal_range({k, i}); back != end; ++back) {
        cycles.push_back(MakeCycle({first.first, it->second.first, back->second.first},
                                   first.second * it->second.second * back->second.second,
                                   options));
      }
    }
  }
  return cycles;
}

bool AnyRemoved(const Cycle& cycle, const std::vector<bool>& removed) {
  for (size_t e : cycle.edges) {
    if (removed[e]) return true;
  }
  return false;
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
      if (AnyRemoved(c, check.removed)) continue;
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
    reason << "inconsistent: breaks " << broken[candidate] << " cycle(s) and closes none (loop "
           << "error up to " << worst[candidate] << " m)";
    check.reason[candidate] = reason.str();
  }
  for (const Cycle& c : cycles) {
    if (AnyRemoved(c, check.removed)) continue;
    check.worst_translation_m = std::max(check.worst_translation_m, c.translation_m);
    check.worst_rotation_deg = std::max(check.worst_rotation_deg, c.rotation_deg);
  }
  return check;
}

}  // namespace colmap_lidar
