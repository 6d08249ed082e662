// Two-view geometry of matched bearings for scene_rotation.cpp (private): the rotation-only model
// (homography at infinity) and the general model (essential matrix), each found by RANSAC, refined
// by Gauss-Newton on a first-order geometric (Sampson) distance in pixels, with the rotation's
// covariance; and Torr's GRIC to choose between them.
//
// Frames as in vision/scene_rotation.h: `from` and `to` camera optical frames, R_from_to maps
// `to` vectors into `from`; t_from is the unit direction of the `to` camera centre in `from`, so a
// scene point satisfies p_from = R_from_to p_to + depth_scale * t_from. Distances are in pixels of
// the undistorted image (normalised coordinates times fx, fy).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace camera_imu_alignment {
namespace scene_geometry {

/// Bearings matched across the views: from[i] ~ R_from_to to[i] (+ translation). Unit vectors
/// with z > 0 (in front of the camera).
struct BearingMatches {
  std::vector<Eigen::Vector3d> from, to;
  double fx = 1, fy = 1;  ///< pixels per normalised unit: distances are reported in pixels
};

/// One model's fit over all matches.
struct ModelFit {
  bool found = false;
  Eigen::Matrix3d R_from_to = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_from = Eigen::Vector3d::Zero();  ///< general model only (unit)
  std::vector<bool> inlier;                          ///< per match
  int inliers = 0;
  /// Of the inliers, those on a second motion sharing the rotation (fitNearRotation: an object
  /// slid between the views); 0 for a one-motion fit.
  int second_motion = 0;
  /// Per match: squared first-order geometric distance (px^2) of the match to the model; its
  /// expectation for an inlier is codimension * sigma^2 (2 for rotation-only, 1 for general).
  std::vector<double> distance2_px2;
  int codimension = 2;
  double sigma_px = 0;  ///< per-coordinate noise from the inliers' residuals over their dof
  Eigen::Matrix3d cov_rad2 = Eigen::Matrix3d::Zero();  ///< rotation, `to` axes, right perturbation
};

/// Rotation about the camera centre: RANSAC on 2-point rotations (and the prediction, when given)
/// with `threshold_px` on the transfer error, then refinement and re-selection of the inliers at
/// the chi-square 99.9 % bound of the estimated sigma.
ModelFit fitRotationOnly(const BearingMatches& matches, double threshold_px,
                         const std::optional<Eigen::Matrix3d>& R_prediction);

/// Rotation and translation: OpenCV's 5-point RANSAC and cheirality, then refinement over the
/// rotation and the translation direction; the rotation's covariance marginalises the
/// translation (Schur complement). With `screen`, the final inliers must also triangulate in
/// front of both cameras and pass a leave-one-out test when their leverage is high: for the
/// chosen model only (under a pure rotation the translation is arbitrary and so are the screens,
/// which would cost time and bias the model choice).
ModelFit fitGeneral(const BearingMatches& matches, double threshold_px, bool screen);

/// The general model refined from a given rotation and translation direction (e.g. a gyro
/// prediction: a near-planar view has two essential matrices that explain it about equally, and
/// RANSAC's may be the wrong one), with the screens.
ModelFit fitGeneralFrom(const BearingMatches& matches, double threshold_px,
                        const Eigen::Matrix3d& R_from_to, const Eigen::Vector3d& t_from);

/// Both models with the rotation held at a given one while their inliers are chosen (e.g. the
/// gyro's consensus, good to a few tenths of a degree): the rotation-only model from the matches
/// within `gate_px` of R_from_to's transfer; the general model's translation direction by RANSAC
/// over pairs of matches with R_from_to held (two epipolar planes' normals cross in it; scored by
/// the squared Sampson distance truncated at `gate_px`; its sign by cheirality). Each is then
/// refined (rotation free) at `gate_px`, with the screens. Two motions in view that share the
/// rotation (the room, and an object slid between the views: another translation) are then not
/// averaged into one compromise, as a free 5-point RANSAC at a loose gate can: the translation
/// found holds one of them. When the matches outside that
/// translation's gate hold a second one (R_from_to still held), the two are fitted together (one
/// rotation, two translation directions; each match belongs to the nearer): `two_motions` when
/// GRIC prefers them to the general model of one. The object's matches then measure the rotation
/// too (ModelFit::second_motion counts them; ModelFit::t_from is the first motion's).
struct HeldRotationFits {
  ModelFit rotation, general;
  /// The general model with a second motion, when found and preferred to `general` by GRIC
  /// (found = false otherwise). The choice between the rotation-only model and the general one
  /// is made with `general`: a second motion's matches are outliers of the rotation-only model,
  /// and counting them would take the general model for a pure rotation, which measures the
  /// rotation less well.
  ModelFit two_motions;
};
HeldRotationFits fitNearRotation(const BearingMatches& matches, const Eigen::Matrix3d& R_from_to,
                                 double gate_px);

/// The other general-model solutions a near-planar view allows: a homography fitted to the
/// matches `fit` holds (inliers), decomposed (up to four rotations with their translation and
/// plane), each refined over all matches like fitGeneralFrom. Solutions within `min_separation_rad`
/// of `fit` or of one another are dropped; those found are returned whatever their inlier counts
/// (the caller judges them against `fit`).
std::vector<ModelFit> planarAlternatives(const BearingMatches& matches, const ModelFit& fit,
                                         double threshold_px, double min_separation_rad);

/// Torr's GRIC of a fit (lower is better) over the matches flagged in `counted`, with the
/// common noise `sigma_px`: sum of min(d^2 / sigma^2, 2 codim) + n d ln 4 + k ln 4n, where
/// d = 4 - codim is the model manifold's dimension and k its parameter count (3 or 5).
double gric(const ModelFit& fit, const std::vector<bool>& counted, double sigma_px, int parameters);

}  // namespace scene_geometry
}  // namespace camera_imu_alignment
