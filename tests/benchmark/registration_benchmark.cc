// Benchmark (not a test): our BSC + RANSAC rough registration against PCL's FPFH +
// SampleConsensusPrerejective on the same simulated station pairs, both followed by the same
// point-to-plane ICP. Prints a markdown table (success rate, rotation/translation error, time).
//   registration_benchmark DATASET_DIR [num_stations]
#include "colmap_ext/rigid3_isometry.h"
#include "colmap_ext/station_dataset.h"
#include "lidar/cloud_io.h"
#include "lidar/pair_registration.h"
#include "lidar/point_to_plane_icp.h"
#include "lidar/station_cloud.h"

#include <pcl/features/fpfh_omp.h>
#include <pcl/point_types.h>
#include <pcl/registration/sample_consensus_prerejective.h>

#include <chrono>
#include <iomanip>
#include <iostream>

namespace colmap_lidar {
namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct FpfhCloud {
  pcl::PointCloud<pcl::PointNormal>::Ptr points{new pcl::PointCloud<pcl::PointNormal>};
  pcl::PointCloud<pcl::FPFHSignature33>::Ptr features{new pcl::PointCloud<pcl::FPFHSignature33>};
};

// FPFH on the same 0.1 m voxel cloud the BSC features use, normals from our estimator.
FpfhCloud PrepareFpfh(const PointCloud& raw, double voxel, double radius) {
  PointCloud coarse = VoxelDownsample(raw, voxel);
  coarse.normals.clear();
  const KdTree3 tree(coarse.points);
  EstimateNormals(tree, NormalEstimationOptions(), &coarse);
  FpfhCloud result;
  for (size_t i = 0; i < coarse.Size(); ++i) {
    pcl::PointNormal p;
    p.x = coarse.points[i].x(), p.y = coarse.points[i].y(), p.z = coarse.points[i].z();
    p.normal_x = coarse.normals[i].x(), p.normal_y = coarse.normals[i].y(),
    p.normal_z = coarse.normals[i].z();
    result.points->push_back(p);
  }
  pcl::FPFHEstimationOMP<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> fpfh;
  fpfh.setInputCloud(result.points);
  fpfh.setInputNormals(result.points);
  fpfh.setRadiusSearch(radius);
  fpfh.compute(*result.features);
  return result;
}

struct Tally {
  int success = 0, attempted = 0;
  double sum_deg = 0, sum_mm = 0, max_deg = 0, max_mm = 0, seconds = 0;
  void Add(bool ok, double deg, double mm) {
    ++attempted;
    if (!ok) return;
    ++success;
    sum_deg += deg, sum_mm += mm;
    max_deg = std::max(max_deg, deg), max_mm = std::max(max_mm, mm);
  }
};

int Main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: registration_benchmark DATASET_DIR" << std::endl;
    return 1;
  }
  const StationDataset dataset = ReadStationDataset(argv[1]);
  const auto cam_from_world = ReadNamedPoses(dataset.GroundTruthPath("cam_from_world.txt"));
  const colmap::Rigid3d cam_from_lidar =
      ReadPoseFile(dataset.GroundTruthPath("cam_from_lidar.txt"));
  const size_t n = dataset.stations.size();
  std::vector<Eigen::Isometry3d> world_from_lidar;
  std::vector<std::unique_ptr<StationCloud>> ours;
  std::vector<FpfhCloud> fpfh;
  Tally bsc, pcl_tally;
  for (size_t i = 0; i < n; ++i) {
    world_from_lidar.push_back(
        ToIsometry(colmap::Inverse(cam_from_world.at(dataset.stations[i])) * cam_from_lidar));
    const PointCloud raw = ReadPointCloud(dataset.cloud_paths[i]);
    auto start = Clock::now();
    ours.push_back(PrepareStationCloud(raw, StationCloudOptions()));
    bsc.seconds += Since(start);
    start = Clock::now();
    fpfh.push_back(PrepareFpfh(raw, 0.1, 0.5));
    pcl_tally.seconds += Since(start);
    std::cerr << "prepared station " << i + 1 << "/" << n << std::endl;
  }
  const PairRegistrationOptions options;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const Eigen::Isometry3d truth = world_from_lidar[i].inverse() * world_from_lidar[j];
      auto error = [&](const Eigen::Isometry3d& estimate, double* deg, double* mm) {
        const Eigen::Isometry3d e = estimate * truth.inverse();
        *deg = Eigen::AngleAxisd(e.linear()).angle() * 180 / M_PI;
        *mm = e.translation().norm() * 1000;
      };
      double deg, mm;
      auto start = Clock::now();
      const PairRegistration r = RegisterStationClouds(*ours[j], *ours[i], options);
      bsc.seconds += Since(start);
      error(r.target_from_source, &deg, &mm);
      // Success: within the bounds (0.1 deg, 1 cm).
      bsc.Add(r.accepted && deg < 0.1 && mm < 10, deg, mm);

      start = Clock::now();
      pcl::SampleConsensusPrerejective<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33>
          align;
      align.setInputSource(fpfh[j].points);
      align.setSourceFeatures(fpfh[j].features);
      align.setInputTarget(fpfh[i].points);
      align.setTargetFeatures(fpfh[i].features);
      align.setMaximumIterations(50000);
      align.setNumberOfSamples(3);
      align.setCorrespondenceRandomness(5);
      align.setSimilarityThreshold(0.9f);
      align.setMaxCorrespondenceDistance(0.25f);
      align.setInlierFraction(0.25f);
      pcl::PointCloud<pcl::PointNormal> aligned;
      align.align(aligned);
      Eigen::Isometry3d rough = Eigen::Isometry3d::Identity();
      rough.matrix() = align.getFinalTransformation().cast<double>();
      const IcpResult fine =
          PointToPlaneIcp(ours[j]->cloud, ours[i]->cloud, *ours[i]->tree, rough, options.icp);
      pcl_tally.seconds += Since(start);
      error(fine.target_from_source, &deg, &mm);
      pcl_tally.Add(align.hasConverged() && deg < 0.1 && mm < 10, deg, mm);
      std::cerr << "pair " << i << "-" << j << " done" << std::endl;
    }
  }
  std::cout << std::fixed << std::setprecision(3)
            << "| method | pairs registered (< 0.1 deg, < 1 cm) | mean / max "
               "rotation error [deg] | "
               "mean / max translation error [mm] | total time [s] "
               "|\n|---|---|---|---|---|\n";
  for (const auto& [name, t] : {std::pair<std::string, Tally>{"BSC + RANSAC + ICP (ours)", bsc},
                                {"PCL FPFH + SampleConsensusPrerejective + same ICP", pcl_tally}}) {
    std::cout << "| " << name << " | " << t.success << " / " << t.attempted << " | ";
    if (t.success == 0) {
      std::cout << "n/a | n/a";  // no registered pair to measure
    } else {
      std::cout << t.sum_deg / t.success << " / " << t.max_deg << " | " << std::setprecision(2)
                << t.sum_mm / t.success << " / " << t.max_mm;
    }
    std::cout << " | " << std::setprecision(1) << t.seconds << " |" << std::setprecision(3) << "\n";
  }
  return 0;
}

}  // namespace
}  // namespace colmap_lidar

int main(int argc, char** argv) { return colmap_lidar::Main(argc, argv); }
