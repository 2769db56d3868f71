#pragma once
// A bounded pose graph over submap frames, for loop closure in SDP-SLAM (beyond the
// paper: its top level only weights combinations by their ICP error; the correction ICP
// finds between two overlapping non-adjacent submaps is thrown away, so drift along a
// loop stays in the chain however well the loop matches). Here those corrections become
// constraints and the frames of the chosen chain are adjusted to agree with them, the
// way graph-based SLAM closes loops (Lu & Milios 1997; Grisetti et al., "A tutorial on
// graph-based SLAM", 2010, §IV for the SE(2) error and Jacobians used below).
//
// Nodes are the global frames X_k of consecutive submaps (k = 0 .. n-1); node 0 is held
// fixed (the gauge). Every node k >= 1 has a SEQUENTIAL constraint to node k-1 (Z = the
// chain's own transform T_(k-1)k, Fig. 3 (l)); LOOP constraints join any two nodes with
// the relative pose ICP found. The error of a constraint (i, j, Z, Ω) is
//   e = t2v(Z⁻¹ ⊕ (X_i⁻¹ ⊕ X_j)),  cost ½ eᵀ Ω e,  Ω = diag(1/σ_xy², 1/σ_xy², 1/σ_θ²).
// Loop constraints pass through Dynamic Covariance Scaling (Agarwal et al., "Robust Map
// Optimization using Dynamic Covariance Scaling", ICRA 2013): with χ² = eᵀΩe and Φ = c²,
// a loop keeps its information while χ² <= Φ and is scaled by s², s = 2Φ / (Φ + χ²),
// beyond (recomputed every Gauss-Newton step). Its pull falls off as 1/χ³, so a wrong
// match metres away from the rest pulls almost nothing (a Cauchy kernel's falls off only
// as 1/χ: a false loop kept most of an inlier's pull). A loop verified before it was
// added may go without a kernel (kNoKernel).
//
// Solver: Gauss-Newton on the poses (additive update of x, y, θ), with step acceptance:
// a step that raises the objective is halved until it does not, or refused (the poses
// stay and the solve ends), so a solve never leaves the graph worse than it found it.
// A solve takes `iterations` steps at most; one whose last step still lowered the
// objective by more than kConverged of it ended before convergence, and is counted
// (FrameGraphStats::capped). A graph far from its optimum with many loops behind the
// kernel can need tens of steps (every step re-weights the loops), and the correction
// of a solve cut short lies where its first steps put it.
// Each step solves H Δ = -b by preconditioned conjugate gradients; H is never formed,
// H·v is summed over the constraints. The preconditioner is H without the loop
// constraints' off-diagonal blocks: block-tridiagonal (the chain), factorised exactly
// in O(n) (block LDLᵀ), so CG only has to account for the loops and converges in a few
// iterations. Cost per step O(n + loops) per CG iteration, plus one evaluation of the
// objective per trial step; memory fixed at init. Deterministic (det:: trigonometry,
// fixed iteration counts and order).
#include <cstddef>
#include <cstdint>
#include <limits>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/state_io.h"

namespace sdpslam {

struct FrameGraphOptions {
  std::uint32_t max_nodes = 64U;   // frames per solve, >= 2
  std::uint32_t max_loops = 256U;  // loop constraints per solve, >= 1
  std::uint32_t iterations = 5U;   // Gauss-Newton steps, >= 1
  std::uint32_t cg_iterations = 30U;  // conjugate-gradient iterations per step, >= 1
  double robust_chi = 3.0;  // kernel scale c on sqrt(χ²) of loop constraints (Φ = c²), > 0
  bool valid() const {
    return max_nodes >= 2U && max_loops >= 1U && iterations >= 1U && cg_iterations >= 1U && robust_chi > 0.0;
  }
};

// Information of a constraint, in the frame of its error e (that of Z):
//   Ω = [ xx xy 0 ; xy yy 0 ; 0 0 theta ]
// The translation block may be anisotropic: a match along a corridor fixes the position
// across it far better than along it (Censi, "An accurate closed-form estimate of ICP's
// covariance", ICRA 2007), and a constraint that claims both equally pulls a whole
// chain along the corridor by whatever the match slid. It must be positive definite.
struct FrameInfo {
  double xx = 1.0;     // (1/m²)
  double xy = 0.0;     // (1/m²)
  double yy = 1.0;     // (1/m²)
  double theta = 1.0;  // 1/σ_θ² (1/rad²)
  static FrameInfo from_sigma(double sigma_xy_m, double sigma_theta_rad) {
    const double t = 1.0 / (sigma_xy_m * sigma_xy_m);
    return FrameInfo{t, 0.0, t, 1.0 / (sigma_theta_rad * sigma_theta_rad)};
  }
  // True iff every entry is finite and the matrix is positive definite.
  bool valid() const;
  // A constraint measured by a match that fixes some directions better than others:
  // `m` = [m_xx m_xy; m_xy m_yy] is the match's direction information in frame i
  // (symmetric, trace 1: ½ I when every direction is fixed; Icp2dInformation), z_heading
  // the heading of Z. Each eigenvector of m (eigenvalue λ) keeps
  // clamp(2 λ, floor, 1) / σ_xy² of translation information, so a well-constrained match
  // gives from_sigma() and a corridor keeps the across-corridor information only; the
  // result is rotated into the frame of the error (Ω = R_zᵀ Ω_i R_z). floor in (0, 1].
  static FrameInfo from_directions(double sigma_xy_m, double sigma_theta_rad, double m_xx, double m_xy, double m_yy,
                                   double floor, double z_heading_rad);
};


struct FrameGraphStats {
  std::uint64_t solves = 0U;
  std::uint64_t refused_nodes = 0U;  // add_node beyond max_nodes
  std::uint64_t refused_loops = 0U;  // add_loop beyond max_loops or with bad indices
  double last_chi2_before = 0.0;     // objective (chain χ² + the loops' kernel cost) before / after the last solve
  double last_chi2_after = 0.0;
  std::uint32_t last_downweighted = 0U;  // loops with kernel weight < 0.5 at the end
  std::uint64_t refused_steps = 0U;      // Gauss-Newton steps that raised the objective even when halved
  std::uint64_t capped = 0U;             // solves whose last step still lowered the objective by > kConverged of it
};

class FrameGraph {
 public:
  // Convergence: a step that lowers the objective by less than this share of it (well
  // above the rounding of its sums, ~1e-15 relative).
  static constexpr double kConverged = 1e-6;
  static std::size_t required_bytes(const FrameGraphOptions& o);
  // False iff the options are invalid or the arena is too small.
  bool init(const FrameGraphOptions& o, Arena& arena);

  // Starts a new graph (keeps the storage).
  void clear();
  // Appends node k with its current estimate; for k >= 1 also its sequential
  // constraint: `from_previous` is the pose of frame k in frame k-1. False when full or
  // the information is bad.
  bool add_node(const Pose2& estimate, const Pose2& from_previous, const FrameInfo& info);
  // Loop constraint: `z` is the pose of frame j in frame i (i != j, both added), behind
  // the robust kernel of scale robust_chi (0 = the options' scale; kNoKernel = plain least
  // squares, for a constraint verified before it was added: a kernel would leave a true
  // loop of metres only partly closed). False when full or the indices, the scale or
  // the information (FrameInfo::valid) are bad.
  static constexpr double kNoKernel = std::numeric_limits<double>::infinity();
  bool add_loop(std::uint32_t i, std::uint32_t j, const Pose2& z, const FrameInfo& info, double robust_chi = 0.0);
  // Gauss-Newton over nodes 1 .. n-1; node 0 stays where it is.
  void optimise();

  std::uint32_t node_count() const { return n_; }
  std::uint32_t loop_count() const { return loops_; }
  const Pose2& frame(std::uint32_t k) const { return pose_[k]; }
  // Kernel weight of loop constraint l after the last solve (1 = fully trusted).
  double loop_weight(std::uint32_t l) const { return loop_w_[l]; }
  const FrameGraphStats& stats() const { return stats_; }

  // The mutable state, for snapshots (core/state_io.h): what init() did not fix.
  void transfer_state(StateIo& io);

 private:
  struct Constraint {
    std::uint32_t i = 0U;
    std::uint32_t j = 0U;
    Pose2 z;
    FrameInfo info;
    double c2 = 0.0;  // loops: the kernel's Φ = c²
  };
  // Linearised constraint: e, A = ∂e/∂X_i, B = ∂e/∂X_j (row-major 3×3), weight.
  struct Linear {
    double e[3];
    double a[9];
    double b[9];
    double w;
  };
  void linearise(const Constraint& c, Linear& l) const;
  double chi2(const Constraint& c) const;
  void multiply(const double* v, double* out) const;      // out = H v
  void precondition(const double* r, double* out) const;  // out = M⁻¹ r
  bool factorise();                                       // M = LDLᵀ (chain)

  FrameGraphOptions options_{};
  FrameGraphStats stats_{};
  std::uint32_t n_ = 0U;
  std::uint32_t loops_ = 0U;
  Pose2* pose_ = nullptr;           // max_nodes
  Constraint* seq_ = nullptr;       // max_nodes (seq_[k] joins k-1 and k; seq_[0] unused)
  Constraint* loop_ = nullptr;      // max_loops
  double* loop_w_ = nullptr;        // max_loops
  Linear* lin_ = nullptr;           // max_nodes + max_loops (seq first)
  double* work_ = nullptr;          // 6 vectors of 3 × max_nodes
  double* diag_inv_ = nullptr;      // 9 × max_nodes: S_k⁻¹ of the block LDLᵀ
  double* upper_ = nullptr;         // 9 × max_nodes: U_k = block (k, k+1) of M
  bool initialised_ = false;
};

}  // namespace sdpslam
