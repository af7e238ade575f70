#include "bridge/initialization/pose_initializer.h"

#include "bridge/initialization/edge_consistency.h"
#include "bridge/initialization/lidar_registration_files.h"
#include "bridge/initialization/model_completion.h"
#include "bridge/initialization/pose_graph_checks.h"
#include "bridge/initialization/track_triangulation.h"
#include "colmap_ext/logging.h"
#include "colmap_ext/rigid3_isometry.h"
#include "lidar/pose_graph.h"
#include "lidar/util/statistics.h"

#include "colmap/estimators/cost_functions.h"
#include "colmap/scene/database.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>

namespace colmap_lidar {
namespace {

namespace fs = std::filesystem;

// The database's image of each station (by the file stem of its name).
struct StationImages {
  std::map<std::string, colmap::image_t> image_of_station;
  std::map<colmap::image_t, std::string> names;      // the station images
  std::map<colmap::image_t, std::string> all_names;  // every image of the database
};

StationImages ReadStationImages(const std::string& database_path, const StationDataset& dataset) {
  const colmap::Database database(database_path);
  const std::set<std::string> stations(dataset.stations.begin(), dataset.stations.end());
  StationImages images;
  for (const colmap::Image& image : database.ReadAllImages()) {
    images.all_names[image.ImageId()] = image.Name();
    const std::string station = fs::path(image.Name()).stem().string();
    if (!stations.count(station)) continue;
    images.image_of_station[station] = image.ImageId();
    images.names[image.ImageId()] = image.Name();
  }
  if (images.image_of_station.empty()) {
    throw std::runtime_error(database_path + " holds no image of the stations of " + dataset.root);
  }
  return images;
}

// COLMAP's two-view rotations and translation directions paired with the LiDAR motions between the
// same stations, from the LiDAR trajectory (its largest component): every image pair, not only the
// pairs the registration joined (an odometry joins consecutive frames, which hardly rotate).
// A monocular rig's hand-eye input.
std::vector<HandEyeMotion> PairDirectionMotions(const std::string& database_path,
                                                const StationDataset& dataset,
                                                const std::string& registration_path) {
  const StationImages images = ReadStationImages(database_path, dataset);
  const std::map<std::string, colmap::Rigid3d> world_from_lidar =
      LargestComponentLidarPoses(registration_path);
  const colmap::Database database(database_path);
  std::vector<HandEyeMotion> motions;
  for (const ImagePairPose& pair : EstimateImagePairDirections(database, 15)) {
    if (!images.names.count(pair.image_i) || !images.names.count(pair.image_j)) continue;
    const std::string target = fs::path(images.names.at(pair.image_i)).stem().string();
    const std::string source = fs::path(images.names.at(pair.image_j)).stem().string();
    if (!world_from_lidar.count(target) || !world_from_lidar.count(source)) continue;
    motions.push_back({pair.cam_i_from_cam_j,
                       colmap::Inverse(world_from_lidar.at(target)) * world_from_lidar.at(source)});
  }
  return motions;
}

// A driving platform (every rotation about one axis, turns of a few degrees): the planar variant of
// the similarity hand-eye on `motions` (COLMAP's two-view geometry), the rotation from the yaw axis
// and the driving direction, the translation 0 and the axis named. False if it cannot recover the
// rotation either.
bool PlanarHandEye(const std::vector<HandEyeMotion>& motions,
                   const PoseInitializerOptions& options,
                   PoseInitialization* init) {
  if (motions.empty()) return false;
  // One scale per motion, as for a monocular rig: with a common scale the forward translation would
  // be fitted from turns of a few degrees, metres off; all of t_X is then 0 (within decimetres of a
  // car's rig), and the joint adjustment finds it.
  const HandEyeResult planar = SolveSimilarityHandEye(
      motions, options.similarity_hand_eye, Eigen::Vector3d::Zero(), /*per_motion_scale=*/true);
  if (!planar.rotation_unique) return false;
  const std::string general = init->hand_eye.message;
  init->hand_eye = planar;
  init->hand_eye.message = "general hand-eye: " + general + "; " + planar.message;
  init->cam_from_lidar = planar.cam_from_lidar;
  init->extrinsic_source = "planar hand-eye (rotation; translation set to 0)";
  return true;
}

// `options` with the rig's LiDAR range noise in its alignment (rig.json is that quantity's one home).
template <typename AlignmentStepOptions>
AlignmentStepOptions WithRigLidarNoise(AlignmentStepOptions options, const StationRig& rig) {
  options.alignment.sigma_lidar_m = rig.LidarRangeNoiseM();
  return options;
}

// A drive that does not turn, without a guess: cam_from_lidar from the travel direction and the
// structure (bridge/initialization/travel_structure_extrinsic.h). Throws with the hand-eye's and
// its own reason when that fails too.
void InitializeFromTravel(const std::string& database_path,
                          const StationDataset& dataset,
                          const std::string& registration_path,
                          const PoseInitializerOptions& options,
                          PoseInitialization* init) {
  const std::string why_not_hand_eye = init->hand_eye.message;
  std::cout << "No rotation for a hand-eye (" << why_not_hand_eye
            << "): cam_from_lidar from the travel direction and the structure" << std::endl;
  if (registration_path.empty()) {
    throw std::runtime_error("cannot initialise cam_from_lidar: " + why_not_hand_eye +
                             "; add cam_from_lidar_guess to " + dataset.root + "/rig.json");
  }
  init->travel_structure = EstimateExtrinsicFromTravelAndStructure(
      colmap::Database(database_path),
      dataset,
      LargestComponentLidarPoses(registration_path),
      ReadStationImages(database_path, dataset).image_of_station,
      WithRigLidarNoise(options.travel_structure, dataset.rig));
  std::cout << "  " << init->travel_structure->message << std::endl;
  if (!init->travel_structure->valid) {
    throw std::runtime_error(
        "cannot initialise cam_from_lidar: " + why_not_hand_eye +
        "; travel direction and structure: " + init->travel_structure->message +
        "; add cam_from_lidar_guess to " + dataset.root + "/rig.json");
  }
  init->cam_from_lidar = init->travel_structure->cam_from_lidar;
  init->extrinsic_source = "travel direction and structure (hand-eye: " + why_not_hand_eye + ")";
}

// cam_from_lidar: rig.json's guess if allowed and present, else hand-eye, else (no guess) the planar
// hand-eye, else the guess anyway (with the hand-eye failure recorded), else `travel` (the travel
// direction and the structure, which throws when it fails). `planar_motions`: the motions for the
// planar fallback (COLMAP's two-view geometry), computed only when needed.
void ChooseExtrinsic(const std::vector<HandEyeMotion>& motions,
                     const StationDataset& dataset,
                     const PoseInitializerOptions& options,
                     const std::function<std::vector<HandEyeMotion>()>& planar_motions,
                     const std::function<void()>& travel,
                     PoseInitialization* init) {
  init->hand_eye = SolveHandEye(motions, options.hand_eye);
  if (options.use_guess && dataset.rig.cam_from_lidar_guess) {
    init->cam_from_lidar = *dataset.rig.cam_from_lidar_guess;
    init->extrinsic_source = "rig.json guess";
  } else if (init->hand_eye.unique) {
    init->cam_from_lidar = init->hand_eye.cam_from_lidar;
    init->extrinsic_source = "hand-eye";
  } else if (!dataset.rig.cam_from_lidar_guess && PlanarHandEye(planar_motions(), options, init)) {
    return;
  } else if (dataset.rig.cam_from_lidar_guess) {
    init->cam_from_lidar = *dataset.rig.cam_from_lidar_guess;
    init->extrinsic_source = "rig.json guess (hand-eye: " + init->hand_eye.message + ")";
  } else {
    travel();
  }
}

// cam_from_lidar from the chosen start to the stereo-LiDAR alignment's, when that had enough
// associations.
void RefineWithStereo(const StationDataset& dataset,
                      const std::string& depth_path,
                      const PoseInitializerOptions& options,
                      PoseInitialization* init) {
  init->stereo_alignment =
      AlignStereoWithLidar(dataset,
                           depth_path,
                           init->cam_from_lidar,
                           WithRigLidarNoise(options.stereo_alignment, dataset.rig));
  std::cout << "Stereo-LiDAR alignment: " << init->stereo_alignment->message << std::endl;
  if (!init->stereo_alignment->used) return;
  init->cam_from_lidar = init->stereo_alignment->cam_from_lidar;
  init->extrinsic_source += " + stereo-LiDAR alignment";
}

// The camera pose graph A_c v A_l (lidar/pose_graph.h): nodes are the stations in name order, the
// first one is the world frame; stations outside its component are unreachable.
void SolveCameraPoseGraph(const std::map<std::string, colmap::image_t>& image_of_station,
                          const std::map<colmap::image_t, std::string>& names,
                          const PoseInitializerOptions& options,
                          PoseInitialization* init) {
  std::map<colmap::image_t, size_t> node;
  std::vector<colmap::image_t> image_of_node;
  for (const auto& [station, image_id] : image_of_station) {
    node[image_id] = image_of_node.size();
    image_of_node.push_back(image_id);
  }
  const Eigen::Matrix<double, 6, 6> sqrt_information =
      DiagonalSqrtInformation(options.sigma_rotation_deg * M_PI / 180, options.sigma_translation_m);
  std::vector<RelativePoseEdge> edges;
  for (const PoseGraphEdge& edge : init->edges) {
    edges.push_back({node.at(edge.image_i),
                     node.at(edge.image_j),
                     ToIsometry(edge.cam_i_from_cam_j),
                     edge.weight,
                     sqrt_information});
  }
  PoseGraphOptions pose_graph;
  pose_graph.loss = RobustLoss::kCauchy;
  pose_graph.loss_scale = 3.0;
  const PoseGraphSolution solution = SolvePoseGraph(image_of_node.size(), edges, pose_graph);
  std::vector<std::string> node_names;
  for (colmap::image_t image_id : image_of_node) node_names.push_back(names.at(image_id));
  ListDisagreeingEdges(edges, solution, node_names, options.mixed_cycles, init);
  for (size_t k = 0; k < image_of_node.size(); ++k) {
    if (solution.component[k] != solution.component[0]) {
      init->unreachable.push_back(names.at(image_of_node[k]));
      continue;
    }
    init->cam_from_world[image_of_node[k]] = ToRigid3d(solution.world_from_node[k].inverse());
  }
}

// The LiDAR edges of lidar_registrator's pairs.txt (none when `registration_path` is empty) between
// stations that have an image. Degenerate edges (a weakly constrained direction) are left out unless
// `use_degenerate`, and described in `left_out`.
std::vector<LidarStationEdge> ReadLidarEdges(
    const std::string& registration_path,
    const std::map<std::string, colmap::image_t>& image_of_station,
    bool use_degenerate,
    std::vector<LidarPairRecord>* left_out) {
  std::vector<LidarStationEdge> lidar_edges;
  if (registration_path.empty()) return lidar_edges;
  for (const LidarPairRecord& pair :
       ReadLidarPairs((fs::path(registration_path) / "pairs.txt").string())) {
    if (!image_of_station.count(pair.target) || !image_of_station.count(pair.source)) continue;
    if (pair.degenerate && !use_degenerate) {
      left_out->push_back(pair);
      std::cout << "pose_initializer: LiDAR edge " << DescribeDegenerateEdge(pair) << ", left out"
                << std::endl;
      continue;
    }
    lidar_edges.push_back({image_of_station.at(pair.target),
                           image_of_station.at(pair.source),
                           pair.target_from_source,
                           static_cast<double>(pair.num_inliers)});
  }
  return lidar_edges;
}

}  // namespace

std::string DescribeDegenerateEdge(const LidarPairRecord& pair) {
  return pair.target + " " + pair.source + ": degenerate (weakest direction " + pair.weakest_axis +
         ")";
}

bool PoseInitializerOptions::Check() const {
  CHECK_OPTION(image_pairs.Check());
  CHECK_OPTION(hand_eye.Check());
  CHECK_OPTION(mixed_cycles.Check());
  CHECK_OPTION(similarity_hand_eye.Check());
  CHECK_OPTION_GT(max_lidar_image_angle_deg, 0);
  CHECK_OPTION(stereo_alignment.Check());
  CHECK_OPTION(travel_structure.Check());
  CHECK_OPTION_GT(sigma_rotation_deg, 0);
  CHECK_OPTION_GT(sigma_translation_m, 0);
  return true;
}

namespace {

// The motions with an image and a LiDAR edge of the same station pair (the hand-eye's input).
std::vector<HandEyeMotion> PairedMotions(const ImageEdges& image_edge,
                                         const std::vector<LidarStationEdge>& lidar_edges) {
  std::vector<HandEyeMotion> motions;
  for (const auto& [i, j, lidar_i_from_lidar_j, weight] : lidar_edges) {
    if (image_edge.count({i, j})) {
      motions.push_back({image_edge.at({i, j}), lidar_i_from_lidar_j});
    } else if (image_edge.count({j, i})) {
      motions.push_back({colmap::Inverse(image_edge.at({j, i})), lidar_i_from_lidar_j});
    }
  }
  return motions;
}

// A_c: the image pairs' relative poses (with the depth priors' scale), added to init->edges.
ImageEdges AddImageEdges(const std::string& database_path,
                         const StationImages& images,
                         const PoseInitializerOptions& options,
                         PoseInitialization* init) {
  const ExtensionDatabase extension(database_path, ExtensionDatabase::Mode::kReadOnly);
  const colmap::Database database(database_path);
  DepthPriorsByImage priors;
  for (const auto& [image_id, name] : images.names) {
    for (const DepthPrior& prior : extension.ReadDepthPriors(image_id)) {
      priors[image_id][prior.point2D_idx] = prior;
    }
  }
  const std::vector<ImagePairPose> image_pairs =
      EstimateImagePairPoses(database, priors, options.image_pairs);
  ImageEdges image_edge;
  for (const ImagePairPose& pair : image_pairs) {
    init->edges.push_back({pair.image_i,
                           pair.image_j,
                           pair.cam_i_from_cam_j,
                           static_cast<double>(pair.num_inliers),
                           false});
    image_edge[{pair.image_i, pair.image_j}] = pair.cam_i_from_cam_j;
  }
  init->num_image_edges = static_cast<int>(image_pairs.size());
  return image_edge;
}

}  // namespace

PoseInitialization InitializePoses(const std::string& database_path,
                                   const StationDataset& dataset,
                                   const std::string& registration_path,
                                   const PoseInitializerOptions& options,
                                   const std::string& depth_path) {
  THROW_CHECK(options.Check());
  THROW_CHECK(fs::is_regular_file(database_path))
      << "Database file does not exist: " << database_path;
  PoseInitialization init;
  const StationImages images = ReadStationImages(database_path, dataset);
  const std::map<std::string, colmap::image_t>& image_of_station = images.image_of_station;
  const ImageEdges image_edge = AddImageEdges(database_path, images, options, &init);

  // A_l, without the edges the images contradict.
  const std::vector<LidarStationEdge> lidar_edges =
      DropContradictedLidarEdges(image_edge,
                                 ReadLidarEdges(registration_path,
                                                image_of_station,
                                                options.use_degenerate_lidar_edges,
                                                &init.degenerate_lidar_edges),
                                 images.names,
                                 options.max_lidar_image_angle_deg,
                                 &init.contradicted_lidar_edges);
  init.num_lidar_edges = static_cast<int>(lidar_edges.size());

  // cam_from_lidar.
  ChooseExtrinsic(
      PairedMotions(image_edge, lidar_edges),
      dataset,
      options,
      [&] {
        return registration_path.empty()
                   ? std::vector<HandEyeMotion>()
                   : PairDirectionMotions(database_path, dataset, registration_path);
      },
      [&] { InitializeFromTravel(database_path, dataset, registration_path, options, &init); },
      &init);
  if (!depth_path.empty() && options.align_stereo_with_lidar)
    RefineWithStereo(dataset, depth_path, options, &init);
  for (const auto& [i, j, lidar_i_from_lidar_j, weight] : lidar_edges) {
    init.edges.push_back(
        {i,
         j,
         init.cam_from_lidar * lidar_i_from_lidar_j * colmap::Inverse(init.cam_from_lidar),
         weight,
         true});
  }
  RemoveInconsistentEdges(images.names, options.mixed_cycles, &init);

  SolveCameraPoseGraph(image_of_station, images.names, options, &init);
  ExplainDegenerateOnly(image_of_station, images.names, &init);
  return init;
}

namespace {

// Metres per model unit: the median of prior depth / model depth over every landmark observation with a
// depth prior.
double DepthPriorScale(const std::string& database_path, const colmap::Reconstruction& model) {
  const ExtensionDatabase extension(database_path, ExtensionDatabase::Mode::kReadOnly);
  std::vector<double> ratios;
  for (const colmap::image_t image_id : model.RegImageIds()) {
    const colmap::Image& image = model.Image(image_id);
    for (const DepthPrior& prior : extension.ReadDepthPriors(image_id)) {
      if (prior.point2D_idx >= image.NumPoints2D()) {
        throw std::runtime_error("the model's image " + image.Name() +
                                 " does not match the database's keypoints");
      }
      const colmap::Point2D& point2D = image.Point2D(prior.point2D_idx);
      if (!point2D.HasPoint3D()) continue;
      const double depth = (image.CamFromWorld() * model.Point3D(point2D.point3D_id).xyz).z();
      if (depth > 0) ratios.push_back(prior.depth / depth);
    }
  }
  if (ratios.size() < 10) {
    throw std::runtime_error("cannot rescale the model to metres: only " +
                             std::to_string(ratios.size()) +
                             " landmark observations carry a depth prior (run "
                             "depth_prior_extractor on the model's database)");
  }
  return Median(std::move(ratios));
}

// The model's relative motions paired with the LiDAR's over lidar_registrator's pairs (by station:
// the stem of the image name).
std::vector<HandEyeMotion> ModelMotions(const colmap::Reconstruction& model,
                                        const std::vector<LidarPairRecord>& lidar_pairs) {
  std::map<std::string, colmap::image_t> image_of_station;
  for (const colmap::image_t image_id : model.RegImageIds()) {
    image_of_station[fs::path(model.Image(image_id).Name()).stem().string()] = image_id;
  }
  std::vector<HandEyeMotion> motions;
  for (const LidarPairRecord& pair : lidar_pairs) {
    if (!image_of_station.count(pair.target) || !image_of_station.count(pair.source)) continue;
    const colmap::image_t i = image_of_station.at(pair.target);
    const colmap::image_t j = image_of_station.at(pair.source);
    motions.push_back(
        {model.Image(i).CamFromWorld() * colmap::Inverse(model.Image(j).CamFromWorld()),
         pair.target_from_source});
  }
  return motions;
}

// Monocular: the scale and cam_from_lidar from the similarity hand-eye, or from rig.json's guess with
// the scale fitted to the LiDAR motions through it; planar motion keeps the guess's (or zero)
// translation along the unobservable axis; no rotation and no guess: `travel` (scale 1: metric).
double ChooseSimilarityExtrinsic(const std::vector<HandEyeMotion>& motions,
                                 const StationDataset& dataset,
                                 const PoseInitializerOptions& options,
                                 const std::function<void()>& travel,
                                 PoseInitialization* init,
                                 bool per_motion_scale = false) {
  const std::optional<colmap::Rigid3d>& guess = dataset.rig.cam_from_lidar_guess;
  init->hand_eye = SolveSimilarityHandEye(motions,
                                          options.similarity_hand_eye,
                                          guess ? guess->translation : Eigen::Vector3d::Zero(),
                                          per_motion_scale);
  if ((options.use_guess && guess) || (!init->hand_eye.rotation_unique && guess)) {
    init->cam_from_lidar = *guess;
    init->extrinsic_source = "rig.json guess";
    if (!init->hand_eye.rotation_unique) {
      init->extrinsic_source += " (hand-eye: " + init->hand_eye.message + ")";
    }
    // Translation directions (one scale per motion) have no common scale to fit.
    if (per_motion_scale) return 1.0;
    init->extrinsic_source += ", scale from the LiDAR motions";
    return HandEyeScale(motions, *guess);
  }
  if (!init->hand_eye.rotation_unique) {
    travel();
    return per_motion_scale ? 1.0 : HandEyeScale(motions, init->cam_from_lidar);
  }
  init->cam_from_lidar = init->hand_eye.cam_from_lidar;
  init->extrinsic_source = "similarity hand-eye";
  if (!init->hand_eye.unique) {
    init->extrinsic_source += guess ? " (translation along the unobservable axis from the guess)"
                                    : " (translation along the unobservable axis set to 0)";
  }
  return init->hand_eye.scale;
}

// Each registered model image must be the database's image of the same id and name.
void CheckModelImages(const colmap::Reconstruction& model, const StationImages& images) {
  for (const colmap::image_t image_id : model.RegImageIds()) {
    const colmap::Image& image = model.Image(image_id);
    const auto name = images.names.find(image_id);
    if (name == images.names.end()) {
      if (images.all_names.count(image_id) && images.all_names.at(image_id) == image.Name()) {
        continue;  // not a station image (e.g. an extra photo): joins no station
      }
      throw std::runtime_error("the model's image " + image.Name() + " (image_id " +
                               std::to_string(image_id) +
                               ") is not in the database under that id: the model must come from "
                               "the same database");
    }
    if (name->second != image.Name()) {
      throw std::runtime_error("the model's image_id " + std::to_string(image_id) + " is " +
                               image.Name() + " but the database's is " + name->second +
                               ": the model must come from the same database");
    }
  }
}

// Every model to metres and cam_from_lidar. Stereo: each model by its own depth priors, cam_from_lidar
// by hand-eye over every model's motions (or the guess). Monocular: the first model's similarity
// hand-eye gives cam_from_lidar and its scale; the other models are scaled to the LiDAR motions through it.
void ChooseModelScalesAndExtrinsic(const std::string& database_path,
                                   const StationDataset& dataset,
                                   const std::vector<LidarPairRecord>& lidar_pairs,
                                   const PoseInitializerOptions& options,
                                   ExistingModels* existing,
                                   PoseInitialization* init) {
  std::vector<colmap::Reconstruction>* models = &existing->models;
  std::vector<double>* scales = &existing->scales;
  scales->clear();
  // An existing model of a drive that does not turn needs a guess.
  const auto travel = [&] {
    throw std::runtime_error("cannot initialise cam_from_lidar: " + init->hand_eye.message +
                             "; add cam_from_lidar_guess to " + dataset.root + "/rig.json");
  };
  std::vector<HandEyeMotion> motions;
  for (size_t k = 0; k < models->size(); ++k) {
    colmap::Reconstruction& model = (*models)[k];
    double scale = 1;
    if (dataset.rig.IsStereo()) {
      scale = DepthPriorScale(database_path, model);
    } else if (k == 0) {
      scale = ChooseSimilarityExtrinsic(
          ModelMotions(model, lidar_pairs), dataset, options, travel, init);
    } else {
      scale = HandEyeScale(ModelMotions(model, lidar_pairs), init->cam_from_lidar);
    }
    model.Transform(colmap::Sim3d(scale, Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero()));
    scales->push_back(scale);
    const std::vector<HandEyeMotion> metric = ModelMotions(model, lidar_pairs);
    motions.insert(motions.end(), metric.begin(), metric.end());
  }
  if (dataset.rig.IsStereo()) {
    ChooseExtrinsic(
        motions, dataset, options, [&] { return motions; }, travel, init);
  }
}

}  // namespace

PoseInitialization InitializeFromModels(const std::string& database_path,
                                        const StationDataset& dataset,
                                        const std::string& registration_path,
                                        const PoseInitializerOptions& options,
                                        ExistingModels* existing,
                                        const std::string& depth_path) {
  THROW_CHECK(options.Check());
  THROW_CHECK(existing != nullptr);
  const std::vector<colmap::Reconstruction>* models = &existing->models;
  THROW_CHECK(!models->empty()) << "no COLMAP model given";
  const StationImages images = ReadStationImages(database_path, dataset);
  for (const colmap::Reconstruction& model : *models) CheckModelImages(model, images);
  const std::vector<LidarPairRecord> lidar_pairs =
      registration_path.empty()
          ? std::vector<LidarPairRecord>()
          : ReadLidarPairs((fs::path(registration_path) / "pairs.txt").string());
  PoseInitialization init;
  ChooseModelScalesAndExtrinsic(database_path, dataset, lidar_pairs, options, existing, &init);
  if (!depth_path.empty() && options.align_stereo_with_lidar) {
    RefineWithStereo(dataset, depth_path, options, &init);
  }
  std::vector<const colmap::Reconstruction*> metric;
  for (const colmap::Reconstruction& model : *models) metric.push_back(&model);
  ModelCompletionOptions completion;
  completion.sigma_rotation_deg = options.sigma_rotation_deg;
  completion.sigma_translation_m = options.sigma_translation_m;
  const CompletedPoses completed = CompleteThroughLidar(
      metric, images.image_of_station, images.names, lidar_pairs, init.cam_from_lidar, completion);
  init.cam_from_world = completed.cam_from_world;
  init.num_lidar_edges = completed.num_lidar_edges;
  init.num_image_edges = completed.num_model_edges;
  for (const auto& [name, reason] : completed.unreachable) {
    init.unreachable.push_back(name);
    init.unreachable_reason[name] = reason;
  }
  // The models' cameras (the mapper may have refined them); the first model's win.
  for (auto model = models->rbegin(); model != models->rend(); ++model) {
    for (const auto& [camera_id, camera] : model->Cameras()) init.cameras[camera_id] = camera;
  }
  return init;
}

PoseInitialization InitializeMonocular(const std::string& database_path,
                                       const StationDataset& dataset,
                                       const std::string& registration_path,
                                       const PoseInitializerOptions& options) {
  THROW_CHECK(options.Check());
  THROW_CHECK(!registration_path.empty())
      << "a monocular dataset needs lidar_registrator's output (--registration_path)";
  const std::map<std::string, colmap::Rigid3d> world_from_lidar =
      LargestComponentLidarPoses(registration_path);
  PoseInitialization init;
  if (options.use_guess && dataset.rig.cam_from_lidar_guess) {
    init.cam_from_lidar = *dataset.rig.cam_from_lidar_guess;
    init.extrinsic_source = "rig.json guess";
  } else {
    ChooseSimilarityExtrinsic(
        PairDirectionMotions(database_path, dataset, registration_path),
        dataset,
        options,
        [&] { InitializeFromTravel(database_path, dataset, registration_path, options, &init); },
        &init,
        true);
  }
  const colmap::Database database(database_path);
  for (const colmap::Image& image : database.ReadAllImages()) {
    const std::string station = fs::path(image.Name()).stem().string();
    const auto pose = world_from_lidar.find(station);
    if (pose == world_from_lidar.end()) {
      init.unreachable.push_back(image.Name());
      continue;
    }
    init.cam_from_world[image.ImageId()] = init.cam_from_lidar * colmap::Inverse(pose->second);
  }
  init.num_lidar_edges =
      static_cast<int>(ReadLidarPairs((fs::path(registration_path) / "pairs.txt").string()).size());
  return init;
}

void TriangulateInitialModel(const std::string& database_path,
                             const PoseInitialization& initialization,
                             const std::string& output_path) {
  std::map<colmap::camera_t, colmap::Camera> cameras;
  for (const colmap::Camera& camera : colmap::Database(database_path).ReadAllCameras()) {
    const auto given = initialization.cameras.find(camera.camera_id);
    cameras[camera.camera_id] = given == initialization.cameras.end() ? camera : given->second;
  }
  fs::create_directories(output_path);
  TriangulateAtPoses(database_path, cameras, initialization.cam_from_world)
      ->WriteBinary(output_path);
}

}  // namespace colmap_lidar
