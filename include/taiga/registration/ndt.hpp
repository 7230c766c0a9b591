#pragma once
// Point-to-distribution NDT after Magnusson, "The Three-Dimensional Normal-Distributions
// Transform" (PhD thesis, Orebro 2009), chapter 6, and distribution-to-distribution NDT after
// Stoyanov et al., "Fast and accurate scan registration through minimization of the distance
// between compact 3D NDT representations" (IJRR 2012).
//
// Target: voxel cells with the mean and covariance of their points; a covariance's eigenvalues
// are clamped from below to min_eigenvalue_ratio times the largest (Magnusson 6.2); a cell whose
// points lie along a line (its middle eigenvalue below line_cell_ratio times the largest) is not
// used (docs/registration.md, "Line cells").
//
// Stem cells (`stem_cells`): a cell whose horizontal section is a circle's arc (a stem, seen
// from one side or many) scores a point by its distance to that circle instead of to the
// Gaussian: the point's mu is the circle's point nearest it (at the cell mean's height) and its
// Sigma^-1 = n n^T / sigma_r^2 + e_z e_z^T / sigma_z^2 with n the radial direction. A Gaussian of
// the arc a keyframe saw sits on that keyframe's side of the stem and pulls a scan that sees
// another arc toward the keyframe (docs/registration.md, "Bias"); the circle is the same from
// every side. The circle is Taubin's algebraic fit to the cell's horizontal moments, with the
// range noise's share taken out when the points were added with their beams (voxel_statistics.hpp,
// BeamNoise; docs/registration.md, "Range noise in the stem cells"). Coarser targets than
// resolution_m keep Gaussians (NdtConfig::cellsAt).
//
// Each source point x' = T x contributes the normal-plus-uniform mixture score
//     f = d1 * exp(-d2 / 2 * (x' - mu)^T Sigma^-1 (x' - mu))
// per neighbour cell (d1 < 0, so f is minimized; Magnusson Eq. 6.9-6.10). T = T_target_source is
// perturbed on the right, T * Exp(tau) with tau = [rho; theta] (lie/se3.hpp); the gradient and
// the Hessian are analytic (the point's second derivatives with respect to tau included) and
// Newton steps with a backtracking line search minimize the score.
//
// D2D: the source is voxelized too and each source cell (mean m, covariance C) scores against
// each target neighbour cell with Sigma replaced by R C R^T + Sigma_target. The derivative of
// R C R^T with respect to theta is neglected (the combined covariance is held fixed within an
// iteration, as GICP does), so the D2D Hessian is an approximation; Stoyanov's full derivatives
// are not implemented.
//
// Parallel with TBB over fixed blocks of source points whose partial sums are added in block
// order: the result is bit-identical for any number of threads.

#include <Eigen/Core>
#include <span>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/registration/result.hpp"
#include "taiga/registration/voxel_index.hpp"
#include "taiga/registration/voxel_statistics.hpp"

namespace taiga::registration {

/// Which target cells a source point is scored against (Magnusson 6.2.1; ndt_omp's names).
enum class NeighbourSearch {
  kDirect1,  ///< the cell that contains the point
  kDirect7,  ///< that cell and its six face neighbours
};

struct NdtConfig {
  double resolution_m = 1.0;  ///< cell edge, m
  /// Optional coarser resolutions (m, each larger than resolution_m) run first, coarsest first.
  std::vector<double> coarse_resolutions_m;
  NeighbourSearch search = NeighbourSearch::kDirect7;
  double outlier_ratio = 0.55;          ///< weight of the uniform part of the mixture, (0, 1)
  std::size_t min_points_per_cell = 6;  ///< fewer points: the cell is not used
  double min_eigenvalue_ratio = 0.01;   ///< eigenvalue clamp, relative to the largest, (0, 1]
  /// A cell whose middle eigenvalue is below this share of its largest holds a line of points
  /// (one scan's ring across the ground, which moves with the sensor): not used; 0 keeps them.
  double line_cell_ratio = 0.02;
  /// Score cells holding a stem's section against its circle (see above), at resolution_m
  /// only: the coarser passes are there for their wide basin. Off by default.
  bool stem_cells = false;
  /// Stem cells also where a stem is cut by cell borders: a cell whose own section fails takes
  /// the circle of a 2 x 2 block of cells around it (src/registration/ndt_target.cpp). Off by
  /// default (OdometryConfig::ndt_stem_cells_across_borders).
  bool stem_cells_across_borders = false;
  /// > 0: the range noise of the map's points (1-sigma: range_sigma_m + range_sigma_per_m x
  /// range), which a map built with their beams (LocalMap) takes out of its stem cells' circle
  /// fits (VoxelStatistics, BeamNoise). 0: the circles are fitted to the noisy points.
  double range_sigma_m = 0.0;
  double range_sigma_per_m = 0.0;
  int max_iterations = 35;         ///< per resolution
  double step_epsilon_m = 1e-3;    ///< converged when the translation step is below this...
  double step_epsilon_rad = 1e-4;  ///< ...and the rotation step below this
  /// A Newton step translating more than this many cell edges is scaled down (0.1 of a 1 m cell
  /// took 11 iterations from 0.5 m / 5 deg on the test pair, 0.5 took 19: the score is not
  /// convex far from the minimum, and long steps overshoot).
  double max_step_cells = 0.1;
  /// Planarity check of the source: degenerate when the smallest eigenvalue of the source
  /// covariance is below this fraction of the largest.
  double planar_eigenvalue_ratio = 1e-6;
  /// Degenerate result when the condition number of the Hessian's translation block exceeds
  /// this (see RegistrationResult::translation_condition).
  double max_translation_condition = 50.0;
  /// Throws std::invalid_argument naming the field when a value is out of range.
  void validate() const;
  /// The cell rules for a target at `resolution_m`: stem cells at the finest resolution only.
  NdtConfig cellsAt(double target_resolution_m) const {
    NdtConfig cells = *this;
    cells.stem_cells = stem_cells && target_resolution_m == resolution_m;
    return cells;
  }
};

/// One NDT cell of the target.
struct NdtCell {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();          ///< regularized, m^2
  Eigen::Matrix3d inverse_covariance = Eigen::Matrix3d::Identity();  ///< of the regularized one
  std::size_t count = 0;
  /// A stem cell (NdtConfig::stem_cells): the circle of its horizontal section in the target
  /// frame, and the inverse variances of a point's distance to it and of its height.
  bool stem = false;
  Eigen::Vector2d stem_centre = Eigen::Vector2d::Zero();
  double stem_radius_m = 0.0;
  double inverse_radial_variance = 0.0;    ///< 1 / m^2
  double inverse_vertical_variance = 0.0;  ///< 1 / m^2
};

/// The circle of a cell's horizontal section, when it is a stem's: radius within
/// [0.03 m, half the cell], an arc of about 80 deg or more, residuals small against the radius
/// and the section upright; the radial variance is at least min_variance_m2. `cell` keeps its
/// Gaussian either way.
bool fitStemSection(const CellMoments& m, double resolution_m, double min_variance_m2,
                    NdtCell& cell);
/// Which of fitStemSection's gates a cell's section fails first (kStem: none), for diagnosis
/// (bench/registration_bias --forces).
enum class StemGate { kStem, kFewPoints, kLeaning, kNoCircle, kRadius, kResidual, kShortArc };
StemGate stemGateOf(const CellMoments& m, double resolution_m);
/// A stem cut by cell borders: the circle of the section of a block of cells (`own` among them)
/// under the same gates, when `own`'s points lie on it as closely as the gates ask.
bool fitStemSectionAcross(const CellMoments& own, std::span<const CellMoments* const> block,
                          double resolution_m, double min_variance_m2, NdtCell& cell);

/// Target cells with a hash index; built once, read concurrently.
class NdtTarget {
 public:
  NdtTarget() = default;
  /// From the statistics of a (local) map, at their resolution, with the cell rules of `cells`
  /// (its resolutions are not used): cells with fewer than min_points_per_cell points, a zero
  /// covariance or points along a line (line_cell_ratio) are dropped, the others' eigenvalues
  /// clamped at min_eigenvalue_ratio.
  explicit NdtTarget(const VoxelStatistics& stats, const NdtConfig& cells = {});
  static NdtTarget fromPoints(std::span<const Eigen::Vector3d> points, double resolution_m,
                              const NdtConfig& cells = {});

  double resolution_m() const { return resolution_m_; }
  const std::vector<NdtCell>& cells() const { return cells_; }
  bool empty() const { return cells_.empty(); }
  /// Writes the cells near `p` into `out` (up to 7) and returns how many.
  int neighbours(const Eigen::Vector3d& p, NeighbourSearch search, const NdtCell** out) const {
    return neighboursOf(voxelOf(p), search, out);
  }
  /// The voxel of `p` in this target's cells (kInvalidVoxel far out or for NaN).
  VoxelKey voxelOf(const Eigen::Vector3d& p) const {
    return registration::voxelOf(p, inverse_resolution_);
  }
  /// The cells near the points of voxel `key`, as neighbours() gives them.
  int neighboursOf(VoxelKey key, NeighbourSearch search, const NdtCell** out) const;

 private:
  double resolution_m_ = 1.0;
  double inverse_resolution_ = 1.0;
  std::vector<NdtCell> cells_;
  std::vector<VoxelKey> keys_;
  VoxelIndex index_;
};

/// The mixture constants d1, d2 of Magnusson Eq. 6.8 for a cell size and outlier ratio.
struct NdtConstants {
  double d1 = 0.0;
  double d2 = 0.0;
};
NdtConstants ndtConstants(double resolution_m, double outlier_ratio);

/// Score, gradient and Hessian of the NDT cost at T * Exp(tau) for tau = 0.
struct NdtDerivatives {
  double score = 0.0;
  lie::Vector6 gradient = lie::Vector6::Zero();
  lie::Matrix6 hessian = lie::Matrix6::Zero();
  std::size_t num_inliers = 0;
};

/// The cells each source point was scored against, by the voxel it fell into, kept from one
/// evaluation of a registration to the next: a Newton step moves most points by less than a cell,
/// and the same voxel then gives the same cells without a hash lookup. One per source point, for
/// one target only.
struct NeighbourCache {
  struct Entry {
    VoxelKey key = kInvalidVoxel;  ///< no cell near an invalid voxel: a valid empty entry
    int count = 0;
    const NdtCell* cells[7] = {};
  };
  explicit NeighbourCache(std::size_t source_points) : entries(source_points) {}
  std::vector<Entry> entries;
};

/// P2D cost at T_target_source; without the Hessian when `with_hessian` is false. `cache`, when
/// given, has one entry per source point and was used with this target only.
NdtDerivatives ndtDerivatives(std::span<const Eigen::Vector3d> source, const NdtTarget& target,
                              const lie::SE3& T_target_source, const NdtConfig& config,
                              bool with_hessian = true, NeighbourCache* cache = nullptr);

/// Source cells for D2D-NDT (mean and regularized covariance).
struct D2dSource {
  std::vector<Eigen::Vector3d> means;
  std::vector<Eigen::Matrix3d> covariances;
};
D2dSource makeD2dSource(std::span<const Eigen::Vector3d> source, const NdtConfig& config,
                        double resolution_m);

/// D2D cost at T_target_source (see the header comment for the approximation in the Hessian).
NdtDerivatives d2dDerivatives(const D2dSource& source, const NdtTarget& target,
                              const lie::SE3& T_target_source, const NdtConfig& config,
                              bool with_hessian = true);

/// P2D-NDT against a prebuilt target (one resolution: the target's; coarse_resolutions_m unused).
RegistrationResult alignNdt(std::span<const Eigen::Vector3d> source, const NdtTarget& target,
                            const lie::SE3& guess_T_target_source, const NdtConfig& config);
/// P2D-NDT against target points, coarse to fine when config.coarse_resolutions_m is set.
RegistrationResult alignNdt(std::span<const Eigen::Vector3d> source,
                            std::span<const Eigen::Vector3d> target,
                            const lie::SE3& guess_T_target_source, const NdtConfig& config);

/// D2D-NDT against a prebuilt target; the source is voxelized at the target's resolution.
RegistrationResult alignD2dNdt(std::span<const Eigen::Vector3d> source, const NdtTarget& target,
                               const lie::SE3& guess_T_target_source, const NdtConfig& config);
/// D2D-NDT against target points, coarse to fine when config.coarse_resolutions_m is set.
RegistrationResult alignD2dNdt(std::span<const Eigen::Vector3d> source,
                               std::span<const Eigen::Vector3d> target,
                               const lie::SE3& guess_T_target_source, const NdtConfig& config);

}  // namespace taiga::registration
