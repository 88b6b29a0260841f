// The consistency score of seed Eq. (6)–(7) (§3.2, Algorithm 1 lines 13–26):
//
//   ε_i = (ω_R F_R(P_i) + ω_N F_N(P_i) + ω_S F_S(P_i)) · f(|P_i|)                     (6)
//   ρ   = Σ_i ω_i ε_i,   ω_i = |P_i| / Σ_j |P_j|                                      (7)
//
// P_i: the points projecting (Eq. (5), camera_model.h) into mask i; masks with |P_i| below
// `min_points` are skipped (Algorithm 1 line 16). With several frames the masks of all frames
// enter one sum (one ρ, the ω_i normalised over every mask of every frame).
//
// The seed names the statistics but not how they become "consistency" (higher is better); here:
// - F_R = max(0, 1 − Var_{P_i}(r) / Var_P(r)), reflectivity variance in the mask over that of the
//   whole cloud (line 20): 1 for a uniform surface, 0 for a mask as mixed as the scene; scale
//   free, so 0–1 and 0–255 intensities give the same score.
// - F_N = mean over pairs p ≠ p' of ⟨n_p, n_p'⟩ (line 21), computed in O(|P|) from the sum of the
//   normals: Σ_{p≠p'} ⟨n_p, n_p'⟩ = |Σ n|² − Σ|n|² = |Σ n|² − |P|, so
//   F_N = (|Σ n|² − |P|) / (|P| (|P| − 1)); 1 for a plane, ≈ 0 for random orientations.
// - F_S = 1 − H / ln(C), H = −Σ_k q_k ln q_k the entropy of the segment classes (cloud_features.h)
//   of the points, q_k their fractions, C the number of classes in the cloud (line 22): 1 when the
//   mask holds one object of the cloud. Points without a class (−1: a pile's foot, small
//   clusters) enter no histogram; a mask with none classified has F_S = 1.
//   `segmentation_entropy = false` uses the purity Σ_k q_k² instead (the prose's "weighted sum of
//   the number of points within each category"): linear in a small impurity where the entropy's
//   slope is infinite; measured no better on the simulated frames, so off.
// - f(n) = n / (n + n0), n0 = `size_scale`: a small set looks consistent by chance (three points
//   have tiny variance), a large one pays for every stray point across the mask's edge; f
//   discounts the former and saturates for the latter, so neither dominates.
// Weights ω_R, ω_N, ω_S = 0.20, 0.30, 0.50 (seed Table 1).
//
// Options left open by the seed, measured on simulated frames and off by default
// (docs/camera_lidar_calibration.md, "Limits"):
// - `zbuffer_block` r > 0: a point is hidden from the camera when a point within r px is nearer
//   by more than `zbuffer_margin` + `zbuffer_relative`·depth (LiDAR and camera are 11 cm
//   apart). It removes the background points next to every occluding edge but keeps the
//   foreground's, so edges penalise shifts one way only: it *biased* z and pitch (+2.5 cm).
// - `min_density_fraction` α, `count_skipped`: a mask is skipped below α·area·(points/pixel) too
//   (the sky collects wall-top spill-over and scores it as consistent), and the points of skipped
//   masks stay in Σ_j |P_j| (Eq. (7) read over all masks), so dropping points costs.
//
// Our extensions, on by default (measured in docs/camera_lidar_calibration.md, "Limits"):
// - `subpixel`: area lookup. Eq. (5) gives a real pixel position; instead of the nearest pixel's
//   mask, a point belongs to each of the (up to) four pixels its 1 px footprint overlaps, with
//   the overlap as weight (bilinear weights). |P_i|, the sums of F_R, the histogram of F_S and
//   f(|P_i|) use the summed weights; F_N the weighted mean over pairs,
//   (|Σ w n|² − Σ w²) / ((Σ w)² − Σ w²). With w = 1 everything is the seed's formula. Why: a
//   2 cm translation moves structure at 5 m by ≈ 1 px (f = 260 px), so with the nearest pixel ρ is
//   piecewise constant on the scale that matters and Nelder–Mead ended wherever its simplex
//   collapsed (20–53 mm from the truth depending on the start); with the area lookup ρ is
//   continuous and every start tried reaches the same maximum.
// - The sky term, `ScoreFrame::unsupported` (MarkUnsupportedMasks, set by AutoCalibrate at T0
//   with AutoCalibrationOptions::unsupported_density): a mask where the LiDAR returns (almost)
//   nothing — the sky — is not an object the cloud can be consistent with. The seed scores it
//   like any other mask, so wall tops spilling into it form a small "consistent" set; here its
//   points count in Σ_j |P_j| with ε = 0, i.e. as misplaced (a structure point landing on sky is
//   a plain error).
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

namespace autoshovel::identification {

struct ScoreOptions {
  double weight_reflectivity = 0.20;  ///< ω_R, Table 1
  double weight_normal = 0.30;        ///< ω_N, Table 1
  double weight_segmentation = 0.50;  ///< ω_S, Table 1
  int min_points = 10;                ///< Algorithm 1 line 16 threshold [-]
  double size_scale = 30;             ///< n0 of f(n) [-]
  bool segmentation_entropy = true;   ///< F_S = 1 − H/ln C (Algorithm 1), else Σ_k q_k²
  double min_density_fraction = 0;    ///< α: skip below α · mask area · points per pixel
  bool count_skipped = false;         ///< skipped masks' points stay in Σ_j |P_j|
  int zbuffer_block = 0;              ///< occlusion test radius [px]; 0 off
  double zbuffer_margin = 0.3;        ///< nearer by more than this (+ relative): hidden [m]
  double zbuffer_relative = 0.05;     ///< of the hidden point's neighbour's depth [-]
  bool subpixel = true;               ///< area (bilinear) mask lookup instead of nearest pixel
  /// Every mask containing a point's pixel gets the point (SAM's masks overlap: a part inside
  /// its whole), as CalibAnything scores; false: only the smallest mask at the pixel.
  bool overlapping_masks = false;
  /// F_N from squared cosines, sign-free: (‖Σ w n nᵀ‖²_F − Σ w²) / ((Σ w)² − Σ w²), 1 for a
  /// plane, 1/3 for random orientations; false: the oriented ⟨n_p, n_p'⟩ of the seed.
  bool unoriented_normals = true;
  /// The edge term (our extension, depth_edges.h): ρ = Eq. (7) + w_E J_E with
  /// J_E = Σ X_i E(u_i) / Σ X_i over the depth-edge points in the image, E(u) =
  /// exp(−d(u)² / 2σ²) and d the distance to the nearest mask boundary [px]. 0: the seed's ρ.
  double weight_edges = 0;
  double edge_sigma_px = 4;  ///< σ of E [px]
};

/// One frame prepared for scoring: masks undistorted into a label image, points with attributes.
struct ScoreFrame {
  Eigen::Matrix3f K = Eigen::Matrix3f::Identity();  ///< pinhole of the undistorted image [px]
  cv::Mat mask_labels;  ///< CV_32S, 0 outside every mask, k + 1 in mask k (MaskLabelImage)
  cv::Mat mask_layers;  ///< CV_32SC4: up to 4 masks per pixel (k + 1, smallest first), 0 none
  int num_masks = 0;
  std::vector<double> mask_area;             ///< pixels of each mask in mask_labels
  std::vector<double> mask_full_area;        ///< pixels of each mask itself (overlaps included)
  std::vector<Eigen::Vector3f> points;       ///< LiDAR frame [m]
  std::vector<float> reflectivity;           ///< as read (any scale)
  std::vector<Eigen::Vector3f> normals;      ///< unit, LiDAR frame
  std::vector<float> edge_weight;            ///< X_i of depth_edges.h (empty: no edge term)
  std::vector<Eigen::Vector3f> edge_points;  ///< the silhouette positions of those with X_i > 0
  cv::Mat boundary_distance;                 ///< CV_32F: distance to the nearest mask boundary [px]
  std::vector<int> segment;                  ///< class per point, in [0, num_segments)
  int num_segments = 2;
  double reflectivity_variance = 1;     ///< over the whole cloud
  double ground_noise = 0;              ///< floor height σ the classes were made with [m]
  int ground_smoothing_neighbours = 1;  ///< k of the ground smoothing (cloud_features.h) [-]
  /// Per mask: no LiDAR support (MarkUnsupportedMasks); empty: none flagged.
  std::vector<char> unsupported;
};

/// One mask's terms (frame index, mask index within the frame).
struct MaskScore {
  int frame = 0, mask = 0;
  long n = 0;
  double f_r = 0, f_n = 0, f_s = 0, epsilon = 0;
};

struct ScoreBreakdown {
  double rho = 0;          ///< the objective: Eq. (7) + w_E J_E
  double consistency = 0;  ///< Eq. (7) alone
  double edges = 0;        ///< J_E
  int masks_used = 0;      ///< with |P_i| ≥ min_points
  long points_in_masks = 0;
  double reflectivity = 0, normal = 0, segmentation = 0;  ///< ω_i-weighted means of F_R, F_N, F_S
  double size = 0;                                        ///< ω_i-weighted mean of f(|P_i|)
  double total_points = 0;  ///< Σ_j |P_j| of Eq. (7) (with misplaced and counted skipped points)
  std::vector<MaskScore> masks;  ///< the masks used
};

/// Flags the masks whose point density at T (points per pixel, area lookup) is below `fraction`
/// of the frame's mean over its masks (our extension, the sky term above).
void MarkUnsupportedMasks(std::vector<ScoreFrame>& frames, const Eigen::Isometry3d& T_lidar_camera,
                          double fraction);

/// How much `b` scores above `a`, and whether the scene agrees: the gain of Eq. (7) is a sum of
/// per-mask changes Δ_i = ω_i ε_i(b) − ω_i ε_i(a) (our extension); its standard error over masks,
/// sqrt(M/(M−1) Σ (Δ_i − Δ̄)²), is what a bootstrap resampling of the masks would give. A gain a
/// few standard errors large is carried by the scene; one that one or two masks make is not.
struct ScoreGain {
  double gain = 0;            ///< Σ Δ_i (Eq. (7) part of ρ_b − ρ_a)
  double standard_error = 0;  ///< over the masks
  int masks = 0;              ///< M: masks used at a or b
};
ScoreGain CompareScores(const ScoreBreakdown& a, const ScoreBreakdown& b);

ScoreBreakdown ConsistencyScore(const std::vector<ScoreFrame>& frames,
                                const Eigen::Isometry3d& T_lidar_camera,
                                const ScoreOptions& options = {});

}  // namespace autoshovel::identification
