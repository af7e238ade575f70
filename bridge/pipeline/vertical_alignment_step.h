// The joint adjuster's use of the vertical alignment (bridge/initialization/vertical_alignment.h):
// measured on the registered images with clouds, turned into a measurement of cam_from_lidar's rotation about the two
// horizontal camera axes, and reported (report.json's "vertical_alignment", vertical_alignment.png).
#pragma once

#include "bridge/initialization/vertical_alignment.h"
#include "bridge/joint/extrinsic_observability.h"
#include "bridge/joint/joint_adjuster.h"
#include "bridge/joint/joint_problem_data.h"
#include "colmap_ext/station_dataset.h"

#include "colmap/scene/reconstruction.h"

#include <nlohmann/json.hpp>

#include <string>

namespace colmap_lidar {

// Every registered image with a cloud (`loaded.data.clouds`), its image read from the dataset; the
// vertical's guess is the stations' common turn axis,
// else the LiDAR's z axis. Prints its summary.
VerticalAlignment MeasureStationVerticals(const StationDataset& dataset,
                                          const colmap::Reconstruction& reconstruction,
                                          const LoadedJointData& loaded,
                                          const colmap::Rigid3d& cam_from_lidar,
                                          const ObservabilityOptions& observability);

// cam_from_lidar with the corrected rotation; the covariance measures the two horizontal axes only
// (the rotation about the vertical and the translation get a variance of 1 rad^2 / 1 m^2). `alignment`
// must be valid.
ExtrinsicMeasurement VerticalAlignmentMeasurement(const VerticalAlignment& alignment,
                                                  const colmap::Rigid3d& cam_from_lidar);

// Conventions: angles in degrees, on the measured axes (camera frame); a station's residual is its
// LiDAR vertical rotated into the camera minus its camera vertical.
nlohmann::json VerticalAlignmentJson(const VerticalAlignment& alignment);

// Each station's residual on the two measured axes [deg] against its index.
void WriteVerticalAlignmentPlot(const std::string& path, const VerticalAlignment& alignment);

}  // namespace colmap_lidar
