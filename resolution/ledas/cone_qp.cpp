// A frictional problem by a primal–dual interior-point method (cone_qp.hpp): its convex relaxation, or
// Coulomb's problem as a nonlinear complementarity problem.
//
// Variables are scaled to standard cones: x = D r with D = μ on a frictional contact's normal row and 1
// elsewhere, so ‖r_t‖ ≤ μ r_n becomes the second-order cone Q = {x₀ ≥ ‖(x₁, x₂)‖}, which is self-dual;
// the problem becomes min ½ xᵀP x + cᵀx, x ∈ Q × … × ℝ₊ × … × ℝ (free joint rows), P = D⁻¹WD⁻¹,
// c = D⁻¹q, with the multiplier z = P x + c (= D⁻¹u) in the same cones and x ∘ z = 0 (Jordan product:
// x ∘ z = (xᵀz, x₀ z₁ + z₀ x₁)). Each step scales both by Nesterov–Todd's T (T x = T⁻¹ z = λ) and solves
// (P + T²) Δx = rhs, symmetric positive definite (T² is, on every row but the joint rows), by the sparse
// LDLᵀ of the frictionless solver (MaskedLdlt: one analysis while W's pattern holds, parallel subtrees);
// or, where the problem brings W = G M⁻¹ Gᵀ's factors and has more rows than body coordinates, through
// the bodies: P = B M⁻¹ Bᵀ with B = D⁻¹ G, and by Woodbury's identity (P + T²)⁻¹ b = H (b − B Δy) with
// (M + Bᵀ H B) Δy = Bᵀ H b and H = T⁻² (regularized below), a system of 6 × 6 blocks per body
// (BlockLdlt), smaller than the contacts' (README.md, "Friction": "The interior point in body space").
#include "cone_qp.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

namespace impetus::ledas {

namespace {

// The fraction of the way to the cones' boundary a step goes at most.
constexpr double kStepToBoundary = 0.99;
// The shift of the joint rows' diagonal (× max P_ii): they have no barrier term, and redundant joints
// would leave P + T² singular there.
constexpr double kFreeShift = 1e-12;
// Gondzio's centrality correctors (as in body_space.cpp): at most kCorrectors per step, aimed at the trial
// step min(1, kTrialStretch · α + kTrialReach), the products' band [kCentreLow, kCentreHigh] · σμ, kept
// if the step grows by the factor kCorrectorGain.
constexpr int kCorrectors = 2;
constexpr double kTrialStretch = 1.5, kTrialReach = 0.1;
constexpr double kCentreLow = 0.1, kCentreHigh = 10.0;
constexpr double kCorrectorGain = 1.01;
// In body space: H = (T² + δ I)⁻¹ with δ = kBodyRegularization · max P_ii, a primal–dual regularization
// as body_space.cpp's (without it H, and S = M + Bᵀ H B with it, grow without bound on the cones that
// end pressed, where T² goes to 0); and the iteration ends when kBodyStall steps have not lowered the
// best residual (the regularization's floor: the caller's Newton steps polish from there).
constexpr double kBodyRegularization = 1e-10;
constexpr std::uint64_t kBodyStall = 5;
// Coulomb's problem: the iteration ends when kCoulombStall steps have not halved its best residual (on
// the dropped pyramid K = 10 at μ = 0.7 without contact 137, the longest plateau of a problem it solves
// lasts 11 steps before the residual falls from 0.18 to 2e-11 in 14).
constexpr std::uint64_t kCoulombStall = 16;

using Cone = ConeQpWorkspace::Cone;
using Scaling = ConeQpWorkspace::Scaling;
using Vec3d = Eigen::Vector3d;

Vec3d block(const Vector& v, const Cone& k) {
  Vec3d b = Vec3d::Zero();
  for (int j = 0; j < k.size; ++j) b(j) = v(k.first + j);
  return b;
}

// a ∘ b on the cone (the Jordan product; on ℝ₊ the plain product).
Vec3d jordan(const Vec3d& a, const Vec3d& b, int size) {
  if (size == 1) return Vec3d(a(0) * b(0), 0.0, 0.0);
  return Vec3d(a.dot(b), a(0) * b(1) + b(0) * a(1), a(0) * b(2) + b(0) * a(2));
}

// v with λ ∘ v = ξ.
Vec3d jordan_divide(const Vec3d& lambda, const Vec3d& xi, int size) {
  if (size == 1) return Vec3d(xi(0) / lambda(0), 0.0, 0.0);
  const double det = lambda(0) * lambda(0) - lambda(1) * lambda(1) - lambda(2) * lambda(2);
  const double v0 = (lambda(0) * xi(0) - lambda(1) * xi(1) - lambda(2) * xi(2)) / det;
  return Vec3d(v0, (xi(1) - v0 * lambda(1)) / lambda(0), (xi(2) - v0 * lambda(2)) / lambda(0));
}

// √(v₀² − ‖v₁‖²), as (v₀ − ‖v₁‖)(v₀ + ‖v₁‖) to keep its precision near the cone's boundary.
double hyperbolic_norm(const Vec3d& v) {
  const double t = std::hypot(v(1), v(2));
  return std::sqrt(std::max(0.0, (v(0) - t) * (v(0) + t)));
}

// Nesterov–Todd's scaling of x, z in the interior of Q (or ℝ₊): w = (z̄ + J x̄)/(2γ) with x̄ = x/√det x,
// z̄ = z/√det z, γ = √((1 + x̄ᵀz̄)/2), J = diag(1, −1, −1); its square root v = (w + e)/√(2(w₀ + 1)); then
// T = θ (2 v vᵀ − J), θ = (det z / det x)^¼, and T⁻¹ = (2 J v vᵀ J − J)/θ.
Scaling nesterov_todd(const Vec3d& x, const Vec3d& z, int size) {
  Scaling s;
  if (size == 1) {
    const double t = std::sqrt(z(0) / x(0));
    s.t = Eigen::Matrix3d::Zero();
    s.t(0, 0) = t;
    s.t2 = s.t * s.t;
    s.inverse = Eigen::Matrix3d::Zero();
    s.inverse(0, 0) = 1.0 / t;
    s.lambda = Vec3d(std::sqrt(x(0) * z(0)), 0.0, 0.0);
    return s;
  }
  const Eigen::Matrix3d j = Vec3d(1.0, -1.0, -1.0).asDiagonal();
  const double dx = hyperbolic_norm(x), dz = hyperbolic_norm(z);
  const Vec3d xb = x / dx, zb = z / dz;
  const double gamma = std::sqrt(0.5 * (1.0 + xb.dot(zb)));
  Vec3d v = (zb + j * xb) / (2.0 * gamma);
  v(0) += 1.0;
  v /= std::sqrt(2.0 * v(0));
  const double theta = std::sqrt(dz / dx);
  s.t = theta * (2.0 * v * v.transpose() - j);
  const Vec3d jv = j * v;
  s.inverse = (2.0 * jv * jv.transpose() - j) / theta;
  s.t2 = s.t * s.t;
  s.lambda = s.t * x;
  return s;
}

// The largest α with x + α d in the cone (∞ if every α is), x in its interior. The half-space x₀ ≥ 0
// bounds it too: the quadratic below is also positive on −Q, and for a line through the apex (or next to
// it) its discriminant rounds below 0, which alone would let the step cross into −Q.
double step_to_boundary(const Vec3d& x, const Vec3d& d, int size) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  const double apex = d(0) < 0.0 ? -x(0) / d(0) : kInfinity;
  if (size == 1) return apex;
  // (x₀ + α d₀)² − ‖x₁ + α d₁‖² = a α² + b α + c, c > 0: the first positive root, if any.
  const double a = d(0) * d(0) - d(1) * d(1) - d(2) * d(2);
  const double b = 2.0 * (x(0) * d(0) - x(1) * d(1) - x(2) * d(2));
  const double c = x(0) * x(0) - x(1) * x(1) - x(2) * x(2);
  if (a == 0.0) return std::min(apex, b < 0.0 ? -c / b : kInfinity);
  const double discriminant = b * b - 4.0 * a * c;
  if (discriminant < 0.0) return apex;  // a > 0 here: the quadratic stays positive
  const double h = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
  double best = apex;
  for (const double root : {h / a, h != 0.0 ? c / h : kInfinity})
    if (root > 0.0) best = std::min(best, root);
  return best;
}

double max_step(const std::vector<Cone>& cones, const Vector& x, const Vector& dx, const Vector& z,
                const Vector& dz) {
  double alpha = std::numeric_limits<double>::infinity();
  for (const Cone& k : cones) {
    if (k.free) continue;
    alpha = std::min({alpha, step_to_boundary(block(x, k), block(dx, k), k.size),
                      step_to_boundary(block(z, k), block(dz, k), k.size)});
  }
  return alpha;
}

// h's pattern (W's, with every cone's diagonal block) and where W's entries and the blocks are stored in
// it; rebuilt (allocating) only when W's pattern changed or a cone's block is not in h, and from
// triplets only when a cone's block is not in W's pattern.
void prepare_pattern(const SparseMatrix& w, ConeQpWorkspace& ws) {
  const Eigen::Index m = w.rows();
  const auto position = [&ws](Eigen::Index row, Eigen::Index col) -> SparseIndex {
    const SparseIndex* inner = ws.h.innerIndexPtr();
    const SparseIndex *begin = inner + ws.h.outerIndexPtr()[col], *end = inner + ws.h.outerIndexPtr()[col + 1];
    const SparseIndex* it = std::lower_bound(begin, end, static_cast<SparseIndex>(row));
    return it != end && *it == row ? static_cast<SparseIndex>(it - inner) : -1;
  };
  const auto locate_blocks = [&] {
    ws.block.clear();
    for (const Cone& k : ws.cones)
      for (int a = 0; a < k.size; ++a)
        for (int b = 0; b < k.size; ++b) {
          const SparseIndex at = position(k.first + a, k.first + b);
          if (at < 0) return false;
          ws.block.push_back(at);
        }
    return true;
  };
  const bool same_w = w.isCompressed() && ws.h.rows() == m && ws.outer.size() == static_cast<std::size_t>(m) + 1 &&
                      std::equal(ws.outer.begin(), ws.outer.end(), w.outerIndexPtr()) &&
                      ws.inner.size() == static_cast<std::size_t>(w.nonZeros()) &&
                      std::equal(ws.inner.begin(), ws.inner.end(), w.innerIndexPtr());
  ws.every_row.assign(static_cast<std::size_t>(m), 1);
  if (same_w && locate_blocks()) return;
  // Usually every cone's block is in W's pattern already (a contact's three rows have the same bodies,
  // so the same columns): then h's pattern is W's, entry for entry, and no triplets are needed.
  ws.coulomb_analysed = false;
  ws.h = w;
  ws.h.makeCompressed();
  if (locate_blocks()) {
    ws.from_w.resize(static_cast<std::size_t>(w.nonZeros()));
    std::iota(ws.from_w.begin(), ws.from_w.end(), SparseIndex{0});
  } else {
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(static_cast<std::size_t>(w.nonZeros()) + 9 * ws.cones.size());
    for (Eigen::Index col = 0; col < m; ++col)
      for (SparseMatrix::InnerIterator it(w, col); it; ++it) entries.emplace_back(it.row(), col, 0.0);
    for (const Cone& k : ws.cones)
      for (int a = 0; a < k.size; ++a)
        for (int b = 0; b < k.size; ++b) entries.emplace_back(k.first + a, k.first + b, 0.0);
    ws.h.resize(m, m);
    ws.h.setFromTriplets(entries.begin(), entries.end());
    ws.h.makeCompressed();
    ws.from_w.clear();
    for (Eigen::Index col = 0; col < m; ++col)
      for (SparseMatrix::InnerIterator it(w, col); it; ++it) ws.from_w.push_back(position(it.row(), col));
    locate_blocks();
  }
  ws.outer.clear();  // the key: W's compressed pattern (an uncompressed W is laid out afresh every time)
  ws.inner.clear();
  if (w.isCompressed()) {
    ws.outer.assign(w.outerIndexPtr(), w.outerIndexPtr() + m + 1);
    ws.inner.assign(w.innerIndexPtr(), w.innerIndexPtr() + w.nonZeros());
  }
}

// The problem's body-space form if the interior point can use it: it matches the rows, has fewer
// coordinates than rows, and every cone is a contact's (no joint row) whose rows share their bodies.
const BodySpace* usable_body_space(const FrictionalProblem& problem, const std::vector<Cone>& cones) {
  if (problem.body_space == nullptr) return nullptr;
  const BodySpace* body = &problem.body_space->body_space();
  const auto m = static_cast<std::size_t>(problem.q.size());
  if (body->blocks.size() != m || body->jacobian.size() != m ||
      body->inertia.size() != body->mass.size() || 6 * body->mass.size() >= m)
    return nullptr;
  const auto blocks = static_cast<std::int32_t>(body->mass.size());
  for (const Cone& k : cones) {
    if (k.free) return nullptr;
    const auto [a, b] = body->blocks[static_cast<std::size_t>(k.first)];
    if (a < 0 || a >= blocks || b < -1 || b >= blocks) return nullptr;
    for (int j = 1; j < k.size; ++j)
      if (body->blocks[static_cast<std::size_t>(k.first + j)] != body->blocks[static_cast<std::size_t>(k.first)])
        return nullptr;
  }
  return body;
}

// S = M + Bᵀ H B into ws.body.system (B = D⁻¹ G): per cone, B_sᵀ H B_t added to its blocks (s, t).
void body_system_values(const BodySpace& body, const std::vector<Cone>& cones, const Vector& d, ConeQpWorkspace& ws) {
  using Block = BlockLdlt::Block;
  using Rows = Eigen::Matrix<double, 3, 6>;
  BodySpaceWorkspace& work = ws.body;
  mass_blocks(body, work);
  const auto block = [&work](SparseIndex i) -> Block& { return work.system[static_cast<std::size_t>(i)]; };
  for (std::size_t n = 0; n < cones.size(); ++n) {
    const Cone& k = cones[n];
    Rows ga = Rows::Zero(), gb = Rows::Zero();
    for (int j = 0; j < k.size; ++j) {
      const auto& g = body.jacobian[static_cast<std::size_t>(k.first + j)];
      const double scale = 1.0 / d(k.first + j);
      ga.row(j) = scale * Eigen::Map<const Eigen::Matrix<double, 1, 6>>(g.data());
      gb.row(j) = scale * Eigen::Map<const Eigen::Matrix<double, 1, 6>>(g.data() + 6);
    }
    const Eigen::Matrix3d& h = ws.h_cone[n];
    const Rows hga = h * ga;
    const auto& at = work.offsets[static_cast<std::size_t>(k.first)];
    block(at[0]).noalias() += ga.transpose() * hga;
    if (body.blocks[static_cast<std::size_t>(k.first)][1] < 0) continue;
    const Rows hgb = h * gb;
    block(at[1]).noalias() += ga.transpose() * hgb;
    block(at[2]).noalias() += gb.transpose() * hga;
    block(at[3]).noalias() += gb.transpose() * hgb;
  }
}

// Whether Coulomb's step matrix can live on h's pattern by rows: h's pattern is W's, entry for entry,
// and each contact's three columns of W list the same rows (so the shift's derivative, a combination
// of the tangent rows, falls on the normal row's pattern).
bool coulomb_pattern(const SparseMatrix& w, const std::vector<Cone>& cones, const ConeQpWorkspace& ws) {
  if (ws.h.nonZeros() != w.nonZeros() || !w.isCompressed()) return false;
  const SparseIndex* outer = w.outerIndexPtr();
  const SparseIndex* inner = w.innerIndexPtr();
  for (const Cone& k : cones) {
    if (k.size != 3) continue;
    const SparseIndex n = outer[k.first], length = outer[k.first + 1] - n;
    for (int t = 1; t < 3; ++t) {
      const SparseIndex at = outer[k.first + t];
      if (outer[k.first + t + 1] - at != length || !std::equal(inner + n, inner + n + length, inner + at)) return false;
    }
  }
  return true;
}

// Coulomb's step matrix by rows into ws.coulomb_matrix: h's values (P + T², symmetric, so h's
// column-major arrays read as rows are the same matrix) plus E, the derivative of c_n = (q_n +
// μ‖u_t‖)/μ (x scaled: d_n = μ, d_t = 1) in x: row n gets ê₁ P_{t₁,·} + ê₂ P_{t₂,·}, ê = u_t/‖u_t‖, with
// P_{t,j} = W_{jt}/d_j read from W's tangent columns, whose k-th entries are the normal column's
// (coulomb_pattern). A contact with u_t = 0 gets no derivative (the shift is not differentiable there).
void coulomb_values(const SparseMatrix& w, const std::vector<Cone>& cones, const Vector& d, const Vector& u,
                    ConeQpWorkspace& ws) {
  RowMajorMatrix& a = ws.coulomb_matrix;
  if (!ws.coulomb_analysed) a = ws.h;  // h's pattern, new since the last analysis: the same arrays by rows
  std::copy(ws.h.valuePtr(), ws.h.valuePtr() + ws.h.nonZeros(), a.valuePtr());
  const SparseIndex* outer = w.outerIndexPtr();
  const SparseIndex* inner = w.innerIndexPtr();
  const double* value = w.valuePtr();
  double* row = a.valuePtr();
  for (const Cone& k : cones) {
    if (k.size != 3) continue;
    const double t = std::hypot(u(k.first + 1), u(k.first + 2));
    if (!(t > 0.0)) continue;
    const double e1 = u(k.first + 1) / t, e2 = u(k.first + 2) / t;
    const SparseIndex n = outer[k.first], t1 = outer[k.first + 1], t2 = outer[k.first + 2];
    for (SparseIndex e = 0; e < outer[k.first + 1] - n; ++e)
      row[n + e] += (e1 * value[t1 + e] + e2 * value[t2 + e]) / d(inner[n + e]);
  }
}

}  // namespace

void solve_cone_qp(const FrictionalProblem& problem, double target, std::uint64_t max_iterations,
                   ConeQpWorkspace& ws, MaskedLdlt& ldlt, Vector& result, ConeQpReport& report) {
  const SparseMatrix& w = *problem.w;
  const Eigen::Index m = problem.q.size();
  report = {};
  result.setZero(m);
  if (m == 0) return;

  // The cones and the scaling D.
  std::vector<Cone>& cones = ws.cones;
  cones.clear();
  Vector& d = ws.d;
  d.setOnes(m);
  std::size_t degree = 0;  // ν: the number of cones (the barrier's degree)
  for (Eigen::Index i = 0; i < m;) {
    const auto row = static_cast<std::size_t>(i);
    Cone k;
    k.first = i;
    k.free = problem.role[row] == RowRole::equality;
    if (problem.role[row] == RowRole::normal && problem.mu[row] > 0.0) {
      k.size = 3;
      d(i) = problem.mu[row];
    }
    if (!k.free) ++degree;
    cones.push_back(k);
    i += k.size;
  }
  // In body space where the problem brings its factored form and has more rows than coordinates: the
  // blocks' pattern (one analysis while it holds); else P + T² on W's pattern.
  const bool coulomb = !problem.convex;
  const BodySpace* body = coulomb ? nullptr : usable_body_space(problem, cones);
  const auto to_contact_space = [&] {
    body = nullptr;
    prepare_pattern(w, ws);
    if (!coulomb && !ldlt.same_pattern(ws.h)) ldlt.analyze(ws.h);
  };
  if (body != nullptr) {
    build_body_pattern(*body, ws.body);
    if (!ws.body.analysed || !ws.body.factor.same_pattern(ws.body.neighbour_start, ws.body.neighbours)) {
      ws.body.factor.analyze(ws.body.neighbour_start, ws.body.neighbours);
      ws.body.analysed = true;
    }
    ws.h_cone.resize(cones.size());
  } else {
    to_contact_space();
    if (coulomb) {
      if (!coulomb_pattern(w, cones, ws)) return;
      if (!ws.coulomb_analysed) {
        coulomb_values(w, cones, d, problem.q, ws);  // the pattern is what KLU analyses
        if (!ws.coulomb_lu.analyze(ws.coulomb_matrix)) return;
        ws.coulomb_analysed = true;
      }
    }
  }
  // P = D⁻¹ W D⁻¹ is not formed: its values go into h, and P x = D⁻¹ W (D⁻¹ x).
  double p_scale = std::numeric_limits<double>::min();
  for (Eigen::Index i = 0; i < m; ++i) p_scale = std::max(p_scale, w.coeff(i, i) / (d(i) * d(i)));
  Vector& c = ws.c;
  c = problem.q.cwiseQuotient(d);
  const double c_scale = std::max(c.lpNorm<Eigen::Infinity>(), std::numeric_limits<double>::min());

  // Start at the cones' centres e = (1, 0, 0), sized to the problem: x ~ impulses, z ~ velocities.
  Vector &x = ws.x, &z = ws.z, &r = ws.r, &best = ws.best, &rd = ws.rd, &u = ws.u;
  x.setZero(m);
  z.setZero(m);
  for (const Cone& k : cones)
    if (!k.free) {
      x(k.first) = c_scale / p_scale;
      z(k.first) = c_scale;
    }

  std::vector<Scaling>& scaling = ws.scaling;
  scaling.resize(cones.size());
  std::vector<Vec3d>& eta = ws.eta;
  best.setZero(m);
  double best_residual = std::numeric_limits<double>::infinity();
  std::uint64_t best_iteration = 0;
  double mark_residual = best_residual;  // Coulomb's stall rule: the last residual that halved the one before
  std::uint64_t mark_iteration = 0;

  // (P + T²) Δx = b in place: by `ldlt`, or in body space by Woodbury's identity,
  // Δx = H (b − B S⁻¹ Bᵀ H b).
  const auto solve = [&](Vector& v) {
    if (coulomb) {
      ws.coulomb_lu.solve(v);
      return;
    }
    if (body == nullptr) {
      ldlt.solve(v);
      return;
    }
    ws.hb.resize(m);
    for (std::size_t n = 0; n < cones.size(); ++n) {
      const Cone& k = cones[n];
      if (k.size == 1) ws.hb(k.first) = ws.h_cone[n](0, 0) * v(k.first);
      else ws.hb.segment<3>(k.first).noalias() = ws.h_cone[n] * v.segment<3>(k.first);
    }
    ws.gy = ws.hb.cwiseQuotient(d);
    multiply_g_transpose(*body, ws.gy, ws.y);
    ws.body.factor.solve(ws.y);
    multiply_g(*body, ws.y, ws.gy);
    ws.gy.array() /= d.array();
    v -= ws.gy;
    for (std::size_t n = 0; n < cones.size(); ++n) {
      const Cone& k = cones[n];
      if (k.size == 1) v(k.first) *= ws.h_cone[n](0, 0);
      else v.segment<3>(k.first) = ws.h_cone[n] * v.segment<3>(k.first).eval();
    }
  };
  // P + T² for the current scaling, factorized: in body space (S = M + Bᵀ H B) or by `ldlt`; for
  // Coulomb's problem P + T² + E by KLU. False if KLU finds it singular.
  const auto factorize = [&] {
    if (body != nullptr) {
      // S = M + Bᵀ H B, positive definite (M is); a pivot block that is not means rounding has won: the
      // contact-space system from here on.
      const double delta = kBodyRegularization * p_scale;
      for (std::size_t n = 0; n < cones.size(); ++n) {
        Eigen::Matrix3d& hn = ws.h_cone[n];
        if (cones[n].size == 1) {
          hn.setZero();
          hn(0, 0) = 1.0 / (scaling[n].t2(0, 0) + delta);
        } else {
          hn = (scaling[n].t2 + delta * Eigen::Matrix3d::Identity()).inverse();
        }
      }
      body_system_values(*body, cones, d, ws);
      if (ws.body.factor.factorize(ws.body.system)) ++report.body_space_steps;
      else to_contact_space();
    }
    if (body == nullptr) {
      // h = P + T² (and the joint rows' shift) on its kept pattern.
      double* const h = ws.h.valuePtr();
      std::fill(h, h + ws.h.nonZeros(), 0.0);
      for (Eigen::Index col = 0, e = 0; col < m; ++col)
        for (SparseMatrix::InnerIterator it(w, col); it; ++it, ++e)
          h[ws.from_w[static_cast<std::size_t>(e)]] = it.value() / (d(it.row()) * d(col));
      std::size_t entry = 0;
      for (std::size_t n = 0; n < cones.size(); ++n) {
        const Cone& k = cones[n];
        if (k.free) {
          h[ws.block[entry++]] += kFreeShift * p_scale;
          continue;
        }
        for (int a = 0; a < k.size; ++a)
          for (int b = 0; b < k.size; ++b) h[ws.block[entry++]] += scaling[n].t2(a, b);
      }
      if (!coulomb) {
        ldlt.factorize(ws.h, ws.every_row, 0.0, 0.0);
        return true;
      }
      coulomb_values(w, cones, d, u, ws);
      return ws.coulomb_lu.factorize(ws.coulomb_matrix, false);
    }
    return true;
  };

  for (; report.iterations < max_iterations; ++report.iterations) {
    r = x.cwiseQuotient(d);
    rd.noalias() = w.transpose() * r;  // = W r (symmetric), as a gather
    u = rd + problem.q;
    const double residual = natural_map_residual(problem, r, u);  // Coulomb's if the problem is
    if (coulomb && residual < 0.5 * mark_residual) {
      mark_residual = residual;
      mark_iteration = report.iterations;
    }
    if (residual < best_residual) {
      best_residual = residual;
      best_iteration = report.iterations;
      best = r;
    }
    if (residual <= target) {
      report.converged = true;
      break;
    }
    if (body != nullptr && report.iterations - best_iteration >= kBodyStall) break;
    if (coulomb && report.iterations - mark_iteration >= kCoulombStall) break;
    if (coulomb)  // De Saxcé's shift at the iterate: c_n = (q_n + μ‖u_t‖)/μ
      for (const Cone& k : cones)
        if (k.size == 3) c(k.first) = (problem.q(k.first) + d(k.first) * std::hypot(u(k.first + 1), u(k.first + 2))) / d(k.first);
    rd = rd.cwiseQuotient(d) + c - z;  // the dual residual P x + c − z (z = 0 on joint rows)
    double gap = 0.0;
    for (const Cone& k : cones)
      if (!k.free) gap += block(x, k).dot(block(z, k));
    const double mu = degree > 0 ? gap / static_cast<double>(degree) : 0.0;

    bool numerical_end = false;
    for (std::size_t n = 0; n < cones.size(); ++n) {
      const Cone& k = cones[n];
      if (k.free) continue;
      scaling[n] = nesterov_todd(block(x, k), block(z, k), k.size);
      if (!scaling[n].t2.allFinite()) {  // an iterate on a boundary to rounding: as far as it goes
        numerical_end = true;
        break;
      }
    }
    if (numerical_end || !factorize()) break;

    // (P + T²) Δx = −r_d + T η,  Δz = T η − T² Δx,  with λ ∘ η = ξ per cone (without −r_d: a corrector).
    const auto direction = [&](Vector& dx, Vector& dz, bool residual = true) {
      if (residual) dx = -rd;
      else dx.setZero(m);
      for (std::size_t n = 0; n < cones.size(); ++n) {
        const Cone& k = cones[n];
        if (k.free) continue;
        const Vec3d te = scaling[n].t * eta[n];
        for (int a = 0; a < k.size; ++a) dx(k.first + a) += te(a);
      }
      solve(dx);
      dz.setZero(m);
      for (std::size_t n = 0; n < cones.size(); ++n) {
        const Cone& k = cones[n];
        if (k.free) continue;
        const Vec3d v = scaling[n].t * eta[n] - scaling[n].t2 * block(dx, k);
        for (int a = 0; a < k.size; ++a) dz(k.first + a) = v(a);
      }
    };
    // Predictor (affine scaling): ξ = −λ ∘ λ, so η = −λ.
    eta.assign(cones.size(), Vec3d::Zero());
    for (std::size_t n = 0; n < cones.size(); ++n)
      if (!cones[n].free) eta[n] = -scaling[n].lambda;
    Vector &dx_aff = ws.dx_aff, &dz_aff = ws.dz_aff;
    direction(dx_aff, dz_aff);
    if (!dx_aff.allFinite()) break;
    const double alpha_aff = std::min(1.0, max_step(cones, x, dx_aff, z, dz_aff));
    double gap_aff = 0.0;
    for (const Cone& k : cones)
      if (!k.free) gap_aff += (block(x, k) + alpha_aff * block(dx_aff, k)).dot(block(z, k) + alpha_aff * block(dz_aff, k));
    const double sigma = mu > 0.0 ? std::pow(std::clamp(gap_aff / gap, 0.0, 1.0), 3) : 0.0;

    // Corrector (Mehrotra): ξ = σ μ e − λ ∘ λ − (T Δx_aff) ∘ (T⁻¹ Δz_aff).
    for (std::size_t n = 0; n < cones.size(); ++n) {
      const Cone& k = cones[n];
      if (k.free) continue;
      const Scaling& s = scaling[n];
      Vec3d xi = -jordan(s.lambda, s.lambda, k.size) -
                 jordan(s.t * block(dx_aff, k), s.inverse * block(dz_aff, k), k.size);
      xi(0) += sigma * mu;
      eta[n] = jordan_divide(s.lambda, xi, k.size);
    }
    Vector &dx = ws.dx, &dz = ws.dz;
    direction(dx, dz);
    if (!dx.allFinite() || !dz.allFinite()) break;
    double reach = max_step(cones, x, dx, z, dz);
    // Gondzio's centrality correctors, per cone on the products x_kᵀz_k (the first component of x ∘ z,
    // μ on the central path): at the trial step min(1, 1.5 α + 0.1), those outside [0.1, 10] · σμ are
    // pulled back into the band along e, by one more solve each; kept while the step grows by 1%.
    for (int corrector = 0; corrector < kCorrectors && reach < 1.0; ++corrector) {
      const double trial = std::min(1.0, kTrialStretch * reach + kTrialReach), centre = sigma * mu;
      for (std::size_t n = 0; n < cones.size(); ++n) {
        const Cone& k = cones[n];
        if (k.free) continue;
        const double product = (block(x, k) + trial * block(dx, k)).dot(block(z, k) + trial * block(dz, k));
        const double pull =
            std::max(std::clamp(product, kCentreLow * centre, kCentreHigh * centre) - product, -kCentreHigh * centre);
        eta[n] = jordan_divide(scaling[n].lambda, Vec3(pull, 0.0, 0.0), k.size);
      }
      direction(dx_aff, dz_aff, false);
      dx_aff += dx;
      dz_aff += dz;
      const double longer = max_step(cones, x, dx_aff, z, dz_aff);
      if (!dx_aff.allFinite() || !dz_aff.allFinite() || !(longer >= kCorrectorGain * reach)) break;
      dx.swap(dx_aff);
      dz.swap(dz_aff);
      reach = longer;
    }
    const double alpha = std::min(1.0, kStepToBoundary * reach);
    x += alpha * dx;
    z += alpha * dz;
  }
  if (!report.converged) {
    r = x.cwiseQuotient(d);
    if (natural_map_residual(problem, r) < best_residual) best = r;
  }
  result = best;
}

}  // namespace impetus::ledas
