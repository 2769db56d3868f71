#include "loops/frame_graph.h"

#include "sdpslam/core/det_math.h"

namespace sdpslam {
namespace {

// Row-major 3×3 helpers.
void mat_t_mul(const double* a, const double* b, double* out) {  // out = aᵀ b
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out[r * 3 + c] = a[0 * 3 + r] * b[0 * 3 + c] + a[1 * 3 + r] * b[1 * 3 + c] + a[2 * 3 + r] * b[2 * 3 + c];
  }
}
void mat_mul(const double* a, const double* b, double* out) {  // out = a b
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out[r * 3 + c] = a[r * 3 + 0] * b[0 * 3 + c] + a[r * 3 + 1] * b[1 * 3 + c] + a[r * 3 + 2] * b[2 * 3 + c];
  }
}
void mat_vec(const double* a, const double* v, double* out) {
  for (int r = 0; r < 3; ++r) out[r] = a[r * 3 + 0] * v[0] + a[r * 3 + 1] * v[1] + a[r * 3 + 2] * v[2];
}
void mat_t_vec(const double* a, const double* v, double* out) {
  for (int r = 0; r < 3; ++r) out[r] = a[0 * 3 + r] * v[0] + a[1 * 3 + r] * v[1] + a[2 * 3 + r] * v[2];
}
// out = w Ω v, Ω the constraint's information (FrameInfo), w the kernel weight.
void weighted(const FrameInfo& info, double w, const double* v, double* out) {
  out[0] = w * (info.xx * v[0] + info.xy * v[1]);
  out[1] = w * (info.xy * v[0] + info.yy * v[1]);
  out[2] = w * (info.theta * v[2]);
}
// aᵀ (w Ω) b added into out.
void add_at_w_b(const double* a, const FrameInfo& info, double w, const double* b, double* out) {
  double wb[9];  // w Ω b, column by column
  for (int c = 0; c < 3; ++c) {
    const double col[3] = {b[0 * 3 + c], b[1 * 3 + c], b[2 * 3 + c]};
    double t[3];
    weighted(info, w, col, t);
    for (int r = 0; r < 3; ++r) wb[r * 3 + c] = t[r];
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      out[r * 3 + c] += a[0 * 3 + r] * wb[0 * 3 + c] + a[1 * 3 + r] * wb[1 * 3 + c] + a[2 * 3 + r] * wb[2 * 3 + c];
    }
  }
}
// Inverse of a symmetric positive definite 3×3 (adjugate); false if singular.
bool inverse3(const double* m, double* out) {
  const double c00 = m[4] * m[8] - m[5] * m[7];
  const double c01 = m[5] * m[6] - m[3] * m[8];
  const double c02 = m[3] * m[7] - m[4] * m[6];
  const double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
  if (!(det > 0.0)) return false;
  const double inv = 1.0 / det;
  out[0] = c00 * inv;
  out[1] = (m[2] * m[7] - m[1] * m[8]) * inv;
  out[2] = (m[1] * m[5] - m[2] * m[4]) * inv;
  out[3] = c01 * inv;
  out[4] = (m[0] * m[8] - m[2] * m[6]) * inv;
  out[5] = (m[2] * m[3] - m[0] * m[5]) * inv;
  out[6] = c02 * inv;
  out[7] = (m[1] * m[6] - m[0] * m[7]) * inv;
  out[8] = (m[0] * m[4] - m[1] * m[3]) * inv;
  return true;
}
// eᵀ Ω e.
// The loops' robust kernel: Dynamic Covariance Scaling (Agarwal et al., ICRA 2013) with
// Φ = c². A loop keeps its full information while χ² <= Φ; beyond, its information is
// scaled by s² with s = 2Φ / (Φ + χ²), so the pull of a loop (w·sqrt(χ²)) falls off as
// 1/χ³ instead of the Cauchy kernel's 1/χ: a false loop metres away pulls nearly nothing,
// where under Cauchy it kept most of an inlier's pull. c² = kNoKernel: weight 1.
double kernel_weight(double x2, double c2) {
  if (!(c2 < FrameGraph::kNoKernel) || x2 <= c2) return 1.0;
  const double s = 2.0 * c2 / (c2 + x2);
  return s * s;
}
// The cost whose derivative in χ² is kernel_weight(): χ² up to Φ, 3Φ − 4Φ²/(Φ + χ²) beyond.
double kernel_cost(double x2, double c2) {
  if (!(c2 < FrameGraph::kNoKernel) || x2 <= c2) return x2;
  return 3.0 * c2 - 4.0 * c2 * c2 / (c2 + x2);
}

double weighted_sq(const FrameInfo& info, const double* e) {
  return info.xx * e[0] * e[0] + 2.0 * info.xy * e[0] * e[1] + info.yy * e[1] * e[1] + info.theta * e[2] * e[2];
}
double dot(const double* a, const double* b, std::size_t n) {
  double s = 0.0;
  for (std::size_t k = 0; k < n; ++k) s += a[k] * b[k];
  return s;
}

}  // namespace

FrameInfo FrameInfo::from_directions(double sigma_xy_m, double sigma_theta_rad, double m_xx, double m_xy,
                                     double m_yy, double floor, double z_heading_rad) {
  const FrameInfo iso = from_sigma(sigma_xy_m, sigma_theta_rad);
  double major = 0.0, minor = 0.0, ux = 1.0, uy = 0.0;
  det::symmetric2_eigen(m_xx, m_xy, m_yy, &major, &minor, &ux, &uy);
  auto share = [floor](double lambda) {
    const double k = 2.0 * lambda;
    if (!(k > floor)) return floor;  // NaN too
    return k > 1.0 ? 1.0 : k;
  };
  const double k_major = share(major) * iso.xx;
  const double k_minor = share(minor) * iso.xx;
  // Ω_i = k− I + (k+ − k−) u uᵀ, then R_zᵀ Ω_i R_z (R_z's columns: (c, s) and (−s, c)).
  const double d = k_major - k_minor;
  const double axx = k_minor + d * ux * ux;
  const double axy = d * ux * uy;
  const double ayy = k_minor + d * uy * uy;
  const double c = det::cos(z_heading_rad);
  const double s = det::sin(z_heading_rad);
  FrameInfo info = iso;
  info.xx = c * c * axx + 2.0 * c * s * axy + s * s * ayy;
  info.yy = s * s * axx - 2.0 * c * s * axy + c * c * ayy;
  info.xy = c * s * (ayy - axx) + (c * c - s * s) * axy;
  return info;
}

bool FrameInfo::valid() const {
  constexpr double kMax = 1.0e12;
  const bool finite = xx > -kMax && xx < kMax && xy > -kMax && xy < kMax && yy > -kMax && yy < kMax &&
                      theta > -kMax && theta < kMax;  // written so that NaN fails too
  return finite && xx > 0.0 && yy > 0.0 && theta > 0.0 && xx * yy - xy * xy > 0.0;
}

std::size_t FrameGraph::required_bytes(const FrameGraphOptions& o) {
  if (!o.valid()) return 0U;
  const std::size_t n = o.max_nodes;
  const std::size_t l = o.max_loops;
  return Arena::bytes_for<Pose2>(n) + Arena::bytes_for<Constraint>(n) + Arena::bytes_for<Constraint>(l) + Arena::bytes_for<double>(l) +
         Arena::bytes_for<Linear>(n + l) + Arena::bytes_for<double>(18U * n) + 2U * Arena::bytes_for<double>(9U * n);
}

bool FrameGraph::init(const FrameGraphOptions& o, Arena& arena) {
  if (!o.valid()) return false;
  options_ = o;
  const std::size_t n = o.max_nodes;
  const std::size_t l = o.max_loops;
  pose_ = arena.allocate_array<Pose2>(n);
  seq_ = arena.allocate_array<Constraint>(n);
  loop_ = arena.allocate_array<Constraint>(l);
  loop_w_ = arena.allocate_array<double>(l);
  lin_ = arena.allocate_array<Linear>(n + l);
  work_ = arena.allocate_array<double>(18U * n);
  diag_inv_ = arena.allocate_array<double>(9U * n);
  upper_ = arena.allocate_array<double>(9U * n);
  if (pose_ == nullptr || seq_ == nullptr || loop_ == nullptr || loop_w_ == nullptr || lin_ == nullptr ||
      work_ == nullptr || diag_inv_ == nullptr || upper_ == nullptr) {
    return false;
  }
  initialised_ = true;
  clear();
  return true;
}

void FrameGraph::clear() {
  n_ = 0U;
  loops_ = 0U;
}

bool FrameGraph::add_node(const Pose2& estimate, const Pose2& from_previous, const FrameInfo& info) {
  if (!initialised_ || n_ >= options_.max_nodes || !info.valid()) {
    ++stats_.refused_nodes;
    return false;
  }
  pose_[n_] = estimate;
  seq_[n_] = Constraint{n_ > 0U ? n_ - 1U : 0U, n_, from_previous, info, 0.0};
  ++n_;
  return true;
}

bool FrameGraph::add_loop(std::uint32_t i, std::uint32_t j, const Pose2& z, const FrameInfo& info, double robust_chi) {
  if (!initialised_ || loops_ >= options_.max_loops || i >= n_ || j >= n_ || i == j || robust_chi < 0.0 ||
      !(robust_chi == robust_chi) || !info.valid()) {
    ++stats_.refused_loops;
    return false;
  }
  const double c = robust_chi > 0.0 ? robust_chi : options_.robust_chi;
  loop_[loops_] = Constraint{i, j, z, info, c * c};  // c² = +inf: no kernel (weight 1, cost χ²)
  loop_w_[loops_] = 1.0;
  ++loops_;
  return true;
}

// e = t2v(Z⁻¹ ⊕ X_i⁻¹ ⊕ X_j):
//   e_t = R_zᵀ (R_iᵀ (t_j − t_i) − t_z),  e_θ = wrap(θ_j − θ_i − θ_z)
//   A = ∂e/∂(t_i, θ_i) = [ −R_zᵀR_iᵀ   R_zᵀ (∂R_iᵀ/∂θ)(t_j − t_i) ;  0 0 −1 ]
//   B = ∂e/∂(t_j, θ_j) = [  R_zᵀR_iᵀ   0 ;  0 0 1 ]
void FrameGraph::linearise(const Constraint& c, Linear& l) const {
  const Pose2& xi = pose_[c.i];
  const Pose2& xj = pose_[c.j];
  const double ci = det::cos(xi.heading_rad), si = det::sin(xi.heading_rad);
  const double cz = det::cos(c.z.heading_rad), sz = det::sin(c.z.heading_rad);
  const double dx = xj.x_m - xi.x_m, dy = xj.y_m - xi.y_m;
  // R_iᵀ d
  const double lx = ci * dx + si * dy, ly = -si * dx + ci * dy;
  const double ux = lx - c.z.x_m, uy = ly - c.z.y_m;
  l.e[0] = cz * ux + sz * uy;
  l.e[1] = -sz * ux + cz * uy;
  l.e[2] = normalize_angle_rad(xj.heading_rad - xi.heading_rad - c.z.heading_rad);
  // R_zᵀ R_iᵀ = rotation by −(θ_z + θ_i)
  const double cc = cz * ci - sz * si, ss = sz * ci + cz * si;  // cos, sin of θ_z + θ_i
  const double m00 = cc, m01 = ss, m10 = -ss, m11 = cc;
  // (∂R_iᵀ/∂θ) d = (−s dx + c dy, −c dx − s dy) = (ly, −lx)
  const double gx = cz * ly + sz * (-lx), gy = -sz * ly + cz * (-lx);
  const double a[9] = {-m00, -m01, gx, -m10, -m11, gy, 0.0, 0.0, -1.0};
  const double b[9] = {m00, m01, 0.0, m10, m11, 0.0, 0.0, 0.0, 1.0};
  for (int k = 0; k < 9; ++k) {
    l.a[k] = a[k];
    l.b[k] = b[k];
  }
  l.w = 1.0;
}

double FrameGraph::chi2(const Constraint& c) const {
  Linear l;
  linearise(c, l);
  return weighted_sq(c.info, l.e);
}

// H v over nodes 1..n-1 (node 0 is fixed: its entries of v are 0 and of out unused).
void FrameGraph::multiply(const double* v, double* out) const {
  for (std::uint32_t k = 0; k < 3U * n_; ++k) out[k] = 0.0;
  auto edge = [&](const Constraint& c, const Linear& l) {
    double jv[3] = {0.0, 0.0, 0.0};
    double t[3];
    if (c.i != 0U) {
      mat_vec(l.a, v + 3U * c.i, t);
      for (int r = 0; r < 3; ++r) jv[r] += t[r];
    }
    if (c.j != 0U) {
      mat_vec(l.b, v + 3U * c.j, t);
      for (int r = 0; r < 3; ++r) jv[r] += t[r];
    }
    double wjv[3];
    weighted(c.info, l.w, jv, wjv);
    if (c.i != 0U) {
      mat_t_vec(l.a, wjv, t);
      for (int r = 0; r < 3; ++r) out[3U * c.i + static_cast<std::uint32_t>(r)] += t[r];
    }
    if (c.j != 0U) {
      mat_t_vec(l.b, wjv, t);
      for (int r = 0; r < 3; ++r) out[3U * c.j + static_cast<std::uint32_t>(r)] += t[r];
    }
  };
  for (std::uint32_t k = 1; k < n_; ++k) edge(seq_[k], lin_[k]);
  for (std::uint32_t q = 0; q < loops_; ++q) edge(loop_[q], lin_[options_.max_nodes + q]);
}

// M: the diagonal blocks of H (all constraints) and the off-diagonal blocks of the
// sequential constraints; block LDLᵀ over nodes 1..n-1 (index k ↔ node k).
bool FrameGraph::factorise() {
  // Diagonal blocks into diag_inv_ (as plain blocks first), upper blocks into upper_.
  for (std::uint32_t k = 0; k < 9U * n_; ++k) {
    diag_inv_[k] = 0.0;
    upper_[k] = 0.0;
  }
  auto add_diag = [&](const Constraint& c, const Linear& l, bool with_upper) {
    if (c.i != 0U) add_at_w_b(l.a, c.info, l.w, l.a, diag_inv_ + 9U * c.i);
    if (c.j != 0U) add_at_w_b(l.b, c.info, l.w, l.b, diag_inv_ + 9U * c.j);
    if (with_upper && c.i != 0U) add_at_w_b(l.a, c.info, l.w, l.b, upper_ + 9U * c.i);  // block (i, i+1)
  };
  for (std::uint32_t k = 1; k < n_; ++k) add_diag(seq_[k], lin_[k], true);
  for (std::uint32_t q = 0; q < loops_; ++q) add_diag(loop_[q], lin_[options_.max_nodes + q], false);
  // S_1 = D_1; S_k = D_k − U_(k−1)ᵀ S_(k−1)⁻¹ U_(k−1). diag_inv_ ends up holding S_k⁻¹.
  double s[9], tmp[9], prod[9];
  for (std::uint32_t k = 1; k < n_; ++k) {
    for (int e = 0; e < 9; ++e) s[e] = diag_inv_[9U * k + static_cast<std::uint32_t>(e)];
    if (k > 1U) {
      mat_mul(diag_inv_ + 9U * (k - 1U), upper_ + 9U * (k - 1U), tmp);  // S⁻¹ U
      mat_t_mul(upper_ + 9U * (k - 1U), tmp, prod);                     // Uᵀ S⁻¹ U
      for (int e = 0; e < 9; ++e) s[e] -= prod[e];
    }
    if (!inverse3(s, diag_inv_ + 9U * k)) return false;
  }
  return true;
}

// z = M⁻¹ r: forward y_k = r_k − U_(k−1)ᵀ S_(k−1)⁻¹ y_(k−1), back z_k = S_k⁻¹ (y_k − U_k z_(k+1)).
void FrameGraph::precondition(const double* r, double* out) const {
  double* y = work_ + 15U * options_.max_nodes;
  double t[3], u[3];
  for (std::uint32_t k = 1; k < n_; ++k) {
    for (int e = 0; e < 3; ++e) y[3U * k + static_cast<std::uint32_t>(e)] = r[3U * k + static_cast<std::uint32_t>(e)];
    if (k > 1U) {
      mat_vec(diag_inv_ + 9U * (k - 1U), y + 3U * (k - 1U), t);
      mat_t_vec(upper_ + 9U * (k - 1U), t, u);
      for (int e = 0; e < 3; ++e) y[3U * k + static_cast<std::uint32_t>(e)] -= u[e];
    }
  }
  for (int e = 0; e < 3; ++e) out[e] = 0.0;
  for (std::uint32_t k = n_ - 1U; k >= 1U; --k) {
    for (int e = 0; e < 3; ++e) t[e] = y[3U * k + static_cast<std::uint32_t>(e)];
    if (k + 1U < n_) {
      mat_vec(upper_ + 9U * k, out + 3U * (k + 1U), u);
      for (int e = 0; e < 3; ++e) t[e] -= u[e];
    }
    mat_vec(diag_inv_ + 9U * k, t, out + 3U * k);
  }
}

void FrameGraph::optimise() {
  if (!initialised_ || n_ < 2U) return;
  ++stats_.solves;
  const std::size_t m = 3U * static_cast<std::size_t>(options_.max_nodes);
  double* x = work_;          // Δ
  double* r = work_ + m;      // residual of H Δ = −b
  double* z = work_ + 2U * m;
  double* p = work_ + 3U * m;
  double* hp = work_ + 4U * m;
  // work_ + 15·max_nodes .. 18·max_nodes: the preconditioner's y (see precondition()).
  const std::size_t dim = 3U * n_;
  // The objective: Σ χ² of the chain + Σ kernel_cost(χ²) of the loops (χ² for a loop
  // without a kernel).
  auto total_chi2 = [&]() {
    double s = 0.0;
    for (std::uint32_t k = 1; k < n_; ++k) s += chi2(seq_[k]);
    for (std::uint32_t q = 0; q < loops_; ++q) s += kernel_cost(chi2(loop_[q]), loop_[q].c2);
    return s;
  };
  stats_.last_chi2_before = total_chi2();
  double current = stats_.last_chi2_before;
  constexpr std::uint32_t kHalvings = 8U;
  constexpr double kRounding = 1e-9;  // relative; double rounding over the sums is ~1e-15
  bool capped = false;  // the last step was accepted and still making headway (kConverged)
  for (std::uint32_t it = 0; it < options_.iterations; ++it) {
    capped = false;
    for (std::uint32_t k = 1; k < n_; ++k) linearise(seq_[k], lin_[k]);
    for (std::uint32_t q = 0; q < loops_; ++q) {
      Linear& l = lin_[options_.max_nodes + q];
      linearise(loop_[q], l);
      l.w = kernel_weight(weighted_sq(loop_[q].info, l.e), loop_[q].c2);
      loop_w_[q] = l.w;
    }
    // b = Σ Jᵀ Ω e; r = −b (Δ = 0 to start).
    for (std::size_t k = 0; k < dim; ++k) {
      x[k] = 0.0;
      r[k] = 0.0;
    }
    auto add_b = [&](const Constraint& c, const Linear& l) {
      double we[3];
      weighted(c.info, l.w, l.e, we);
      double t[3];
      if (c.i != 0U) {
        mat_t_vec(l.a, we, t);
        for (int e = 0; e < 3; ++e) r[3U * c.i + static_cast<std::uint32_t>(e)] -= t[e];
      }
      if (c.j != 0U) {
        mat_t_vec(l.b, we, t);
        for (int e = 0; e < 3; ++e) r[3U * c.j + static_cast<std::uint32_t>(e)] -= t[e];
      }
    };
    for (std::uint32_t k = 1; k < n_; ++k) add_b(seq_[k], lin_[k]);
    for (std::uint32_t q = 0; q < loops_; ++q) add_b(loop_[q], lin_[options_.max_nodes + q]);
    if (!factorise()) return;
    precondition(r, z);
    for (std::size_t k = 0; k < dim; ++k) p[k] = z[k];
    double rz = dot(r, z, dim);
    const double r0 = dot(r, r, dim);
    if (!(r0 > 1e-24)) break;
    for (std::uint32_t cg = 0; cg < options_.cg_iterations; ++cg) {
      multiply(p, hp);
      for (int e = 0; e < 3; ++e) hp[e] = 0.0;
      const double php = dot(p, hp, dim);
      if (!(php > 0.0)) break;
      const double alpha = rz / php;
      for (std::size_t k = 3; k < dim; ++k) {
        x[k] += alpha * p[k];
        r[k] -= alpha * hp[k];
      }
      if (dot(r, r, dim) < 1e-20 * r0) break;
      precondition(r, z);
      const double rz_new = dot(r, z, dim);
      const double beta = rz_new / rz;
      rz = rz_new;
      for (std::size_t k = 3; k < dim; ++k) p[k] = z[k] + beta * p[k];
    }
    // Step acceptance (backtracking): Gauss-Newton's step minimises the linearised
    // objective, which far from the solution (headings wrong by radians) can raise the
    // true one. A step is taken only if the objective does not rise; otherwise it is
    // halved, up to kHalvings times, and if none helps the poses stay and the solve
    // stops (counted in stats_.refused_steps). At convergence the objective moves by
    // rounding only, either way: a rise within kRounding of it is no rise. The poses
    // before the step wait in z.
    double* saved = z;
    for (std::uint32_t k = 1; k < n_; ++k) {
      saved[3U * k] = pose_[k].x_m;
      saved[3U * k + 1U] = pose_[k].y_m;
      saved[3U * k + 2U] = pose_[k].heading_rad;
    }
    double scale = 1.0;
    double step = 0.0;
    bool accepted = false;
    bool converged = false;
    for (std::uint32_t h = 0; h <= kHalvings; ++h, scale *= 0.5) {
      step = 0.0;
      for (std::uint32_t k = 1; k < n_; ++k) {
        const double dx = scale * x[3U * k], dy = scale * x[3U * k + 1U], dt = scale * x[3U * k + 2U];
        pose_[k].x_m = saved[3U * k] + dx;
        pose_[k].y_m = saved[3U * k + 1U] + dy;
        pose_[k].heading_rad = normalize_angle_rad(saved[3U * k + 2U] + dt);
        step += dx * dx + dy * dy + dt * dt;
      }
      const double after = total_chi2();
      if (after <= current * (1.0 + kRounding)) {
        converged = current - after <= kConverged * current;
        current = after;
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      for (std::uint32_t k = 1; k < n_; ++k) {
        pose_[k].x_m = saved[3U * k];
        pose_[k].y_m = saved[3U * k + 1U];
        pose_[k].heading_rad = saved[3U * k + 2U];
      }
      ++stats_.refused_steps;
      break;
    }
    capped = !converged && !(step < 1e-14);
    if (step < 1e-14) break;
  }
  if (capped) ++stats_.capped;
  std::uint32_t down = 0U;
  for (std::uint32_t q = 0; q < loops_; ++q) {
    loop_w_[q] = kernel_weight(chi2(loop_[q]), loop_[q].c2);
    if (loop_w_[q] < 0.5) ++down;
  }
  stats_.last_chi2_after = total_chi2();
  stats_.last_downweighted = down;
}

void FrameGraph::transfer_state(StateIo& io) {
  io.section("frame_graph");
  io.value(stats_);
  io.value(n_);
  io.value(loops_);
}

}  // namespace sdpslam
