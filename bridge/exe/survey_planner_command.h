// The survey planner's CLI command (linked into the colmap-lidar executable only).
#pragma once

namespace colmap_lidar {

// colmap-lidar plan_survey --scene NAME --stations FILE --output_path DIR [options]
int RunPlanSurvey(int argc, char** argv);

}  // namespace colmap_lidar
