// What the joint adjuster step reports: OUTPUT/report.json (the schema is in
// docs/joint_adjuster.md), its plots, and the console's summary of the uncertainty.
#pragma once

#include "bridge/initialization/vertical_alignment.h"
#include "bridge/joint/joint_adjuster.h"
#include "bridge/joint/joint_problem_data.h"

#include "colmap/geometry/rigid3.h"

#include <optional>
#include <string>

namespace colmap_lidar {

// What one joint adjustment ended with, for its report.
struct JointOutcome {
  const colmap::Rigid3d& initial;  // cam_from_lidar at the start
  const colmap::Rigid3d& refined;
  const JointAdjustmentSummary& summary;
  const std::string& caveat;  // UncertaintyCaveat
  const std::optional<VerticalAlignment>& vertical;
};

// report.json in `directory`, written atomically.
void WriteJointReport(const std::string& directory,
                      const JointAdjusterOptions& options,
                      const LoadedJointData& loaded,
                      const JointOutcome& outcome);

// cost.png, the perturbation curves (PNG and CSV) and vertical_alignment.png (if it ran).
void WriteJointPlots(const std::string& directory,
                     const JointAdjustmentSummary& summary,
                     const std::optional<VerticalAlignment>& vertical);

// The sigmas per camera axis, the unobservable and held directions.
void PrintJointUncertainty(const JointAdjustmentSummary& summary, const std::string& caveat);

}  // namespace colmap_lidar
