// A complementarity problem with redundant rows, solved in body space by a primal–dual interior point
// (Mehrotra's predictor–corrector). README.md, "Redundant islands: an interior point in body space".
//
// The problem (island_solver.hpp) is the optimality condition of the QP min ½ pᵀA p − cᵀp, p ≥ 0, with
// A = G M⁻¹ Gᵀ. Its dual in the velocity change u = M⁻¹ Gᵀ p is
//     min ½ uᵀ M u   subject to   G u ≥ c,
// whose multipliers are p and whose slacks s = G u − c are w. In contact space A is singular wherever
// rows are redundant (a face's four corners carry three independent constraints); in body space the
// Newton system M + Gᵀ D G (D = P S⁻¹) is positive definite whatever the rows, and of the bodies' size.
#include "body_space.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace impetus::ledas {

namespace {
constexpr int kMaxSteps = 100;  // the wall of 200 bricks takes 9–20 steps per problem, of 1,000 bricks 27–50
constexpr double kStepFraction = 0.99;   // of the longest step that keeps s, p > 0
constexpr double kRegularization = 1e-10;  // δ = this · max A_kk (below)
// The stopping rule's bound on each row's p_k w_k, in units of tolerance · max p. Each factor 100 costs
// about one more step: on a wall of 80 cubes (tests/resolution/ledas/test_ledas_body_space.cpp) the
// velocities came within 2.6e-7 / 2.5e-9 / 2.5e-11 / 7.5e-13 m/s of the active-set search's at 1 /
// 1e-2 / 1e-4 / 1e-6, in 10 / 11 / 12 / 13 steps; at 1e-6 the knocked wall's hardest problems no
// longer get there before the regularization's floor and fall back to the search.
constexpr double kComplementarity = 1e-4;
constexpr int kStallSteps = 10;  // steps without a better iterate before the search takes over
// Creeping: kStallSteps steps have not halved the best excess. Then, or at a stall, the best iterate is
// taken if it is within SolverSettings::interior_point_stall_excess (100) of the rule with no row
// approaching (counted as loose): products p_k w_k up to 1e-2 · tolerance · max p. Such a stall is the
// regularization's floor, where rows that press move their impulse onto redundant neighbours by a
// little each step and separate at δ·dp while they do; the velocities have converged (primal and dual
// residuals 1e-11–1e-15 on the walls below).
// Measured on bench_step's knocked walls stepped from their start (one thread):
//  - 200 bricks, step 10: the impact problem crept at 2.1–2.4× the bound for 70 steps (a row pressing
//    with 20 N·s separated at 3.8e-12 m/s while its impulse moved at 0.08 N·s a step); the search then
//    took 1,721 iterations, the step 0.55–0.83 s against 25–45 ms for its neighbours.
//  - 1,000 bricks (11,500 rows): impact problems stalled at 4–11× and position corrections (tolerance
//    1e-12 m) at 19–29×, p_k w_k ~ 1e-17 m·N·s; each fell to the search, 9,700–10,100 iterations and
//    29–46 s for the step, against 0.5–1 s for the others.
// Gondzio's multiple centrality correctors (J. Gondzio, "Multiple centrality corrections in a primal-dual
// method for linear programming", Comput. Optim. Appl. 6, 1996): at most kCorrectors per step, each one
// more solve on the step's factorization, aimed at the trial step min(1, 1.5 α + 0.1) and kept only if it
// lengthens the step by 1%. On the 7 problems dumped from the knocked wall (a scratch driver) the steps
// fell from 162 in all to 134 with 2 correctors and 129 with 4.
constexpr int kCorrectors = 2;
constexpr double kTrialStretch = 1.5, kTrialReach = 0.1;
constexpr double kCentreLow = 0.1, kCentreHigh = 10.0;  // the products' band, in units of σμ
constexpr double kCorrectorGain = 1.01;

// The longest step α ≤ 1 with x + α dx ≥ 0.
double longest_step(const Vector& x, const Vector& dx) {
  double alpha = 1.0;
  for (Eigen::Index k = 0; k < x.size(); ++k)
    if (dx(k) < 0.0) alpha = std::min(alpha, -x(k) / dx(k));
  return alpha;
}

// The interior point's stopping rule on p ≥ 0 and w = A p − c, as the worst ratio to its bounds (≤ 1:
// met): no row approaches (w ≥ −tolerance), and every row's complementarity product is at most
// max(kComplementarity · tolerance, rounding) · max p, so a row that separates by w carries at most that
// over w of the largest impulse. `rounding` is the search's floor for w, 1e-14 (max A_kk · max p + max
// |c|): on the wall of 1,000 bricks (impulses up to ~100 N·s) the products stalled at 1e-11, where
// 1e-4 · tolerance · max p is 1e-11 too.
double excess(const Vector& p, const Vector& w, const Vector& c, double tolerance, double a_scale) {
  const double largest = p.lpNorm<Eigen::Infinity>();
  const double rounding = 1e-14 * (a_scale * largest + c.lpNorm<Eigen::Infinity>());
  const double bound = std::max(kComplementarity * tolerance, rounding) * largest;
  double worst = 0.0;
  for (Eigen::Index k = 0; k < p.size(); ++k) {
    if (!(p(k) >= 0.0) || !std::isfinite(w(k))) return std::numeric_limits<double>::infinity();
    worst = std::max({worst, -w(k) / tolerance, bound > 0.0 ? p(k) * w(k) / bound : 0.0});
  }
  return worst;
}

}  // namespace

// Products with G, Gᵀ and M from the blocks (BodySpace).
void multiply_g(const BodySpace& body, const Vector& u, Vector& out) {
  out.resize(static_cast<Eigen::Index>(body.blocks.size()));
  for (std::size_t k = 0; k < body.blocks.size(); ++k) {
    const auto& g = body.jacobian[k];
    double sum = 0.0;
    for (int side = 0; side < 2; ++side)
      if (const std::int32_t b = body.blocks[k][static_cast<std::size_t>(side)]; b >= 0)
        for (int d = 0; d < 6; ++d) sum += g[static_cast<std::size_t>(6 * side + d)] * u(6 * b + d);
    out(static_cast<Eigen::Index>(k)) = sum;
  }
}

void multiply_g_transpose(const BodySpace& body, const Vector& p, Vector& out) {
  out.setZero(static_cast<Eigen::Index>(6 * body.mass.size()));
  for (std::size_t k = 0; k < body.blocks.size(); ++k) {
    const auto& g = body.jacobian[k];
    const double pk = p(static_cast<Eigen::Index>(k));
    for (int side = 0; side < 2; ++side)
      if (const std::int32_t b = body.blocks[k][static_cast<std::size_t>(side)]; b >= 0)
        for (int d = 0; d < 6; ++d) out(6 * b + d) += g[static_cast<std::size_t>(6 * side + d)] * pk;
  }
}

namespace {

void multiply_m(const BodySpace& body, const Vector& u, Vector& out) {
  out.resize(u.size());
  for (std::size_t b = 0; b < body.mass.size(); ++b) {
    const auto at = static_cast<Eigen::Index>(6 * b);
    out.segment<3>(at) = body.mass[b] * u.segment<3>(at);
    out.segment<3>(at + 3).noalias() = body.inertia[b] * u.segment<3>(at + 3);
  }
}

}  // namespace

// The block pattern of M + Gᵀ D G: block column t holds a block for every body s sharing a row with t
// (and t itself), in increasing s. Records where each row's four blocks and each body's diagonal block
// are, so that system_values() (and cone_qp.cpp's body-space system) fill it in place.
void build_body_pattern(const BodySpace& body, BodySpaceWorkspace& work) {
  const auto blocks = static_cast<SparseIndex>(body.mass.size());
  std::vector<std::pair<SparseIndex, SparseIndex>>& pairs = work.pairs;  // (column block, row block)
  pairs.clear();
  for (SparseIndex b = 0; b < blocks; ++b) pairs.emplace_back(b, b);
  for (const auto& [a, b] : body.blocks)
    if (b >= 0) pairs.emplace_back(a, b), pairs.emplace_back(b, a);
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  work.neighbour_start.assign(static_cast<std::size_t>(blocks) + 1, 0);
  work.neighbours.resize(pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    ++work.neighbour_start[static_cast<std::size_t>(pairs[i].first) + 1];
    work.neighbours[i] = pairs[i].second;
  }
  for (SparseIndex b = 0; b < blocks; ++b)
    work.neighbour_start[static_cast<std::size_t>(b) + 1] += work.neighbour_start[static_cast<std::size_t>(b)];
  work.system.resize(pairs.size());
  // Block (s, t): column t's block at s's place among t's neighbours.
  const auto place = [&](SparseIndex s, SparseIndex t) {
    const auto first = work.neighbours.begin() + work.neighbour_start[static_cast<std::size_t>(t)];
    const auto last = work.neighbours.begin() + work.neighbour_start[static_cast<std::size_t>(t) + 1];
    return static_cast<SparseIndex>(std::lower_bound(first, last, s) - work.neighbours.begin());
  };
  work.diagonal_offsets.resize(static_cast<std::size_t>(blocks));
  for (SparseIndex b = 0; b < blocks; ++b) work.diagonal_offsets[static_cast<std::size_t>(b)] = place(b, b);
  work.offsets.resize(body.blocks.size());
  for (std::size_t r = 0; r < body.blocks.size(); ++r) {
    const auto [a, b] = body.blocks[r];
    work.offsets[r] = {place(a, a), b >= 0 ? place(a, b) : 0, b >= 0 ? place(b, a) : 0, b >= 0 ? place(b, b) : 0};
  }
}

void mass_blocks(const BodySpace& body, BodySpaceWorkspace& work) {
  using Block = BlockLdlt::Block;
  std::fill(work.system.begin(), work.system.end(), Block::Zero());
  for (std::size_t b = 0; b < body.mass.size(); ++b) {
    Block& diagonal = work.system[static_cast<std::size_t>(work.diagonal_offsets[b])];
    diagonal.topLeftCorner<3, 3>().diagonal().setConstant(body.mass[b]);
    diagonal.bottomRightCorner<3, 3>() = body.inertia[b];
  }
}

namespace {

// M + Gᵀ diag(d) G into `system`: per row, d_k g_s g_tᵀ added to its blocks (s, t).
void system_values(const BodySpace& body, const Vector& d, BodySpaceWorkspace& work) {
  using Block = BlockLdlt::Block;
  using Row = Eigen::Map<const Eigen::Matrix<double, 6, 1>>;
  mass_blocks(body, work);
  for (std::size_t k = 0; k < body.blocks.size(); ++k) {
    const std::int32_t b = body.blocks[k][1];
    const Row ga(body.jacobian[k].data()), gb(body.jacobian[k].data() + 6);
    const double dk = d(static_cast<Eigen::Index>(k));
    const auto& at = work.offsets[k];
    // Block (s, t) += (d_k g_s) g_tᵀ, written out: Eigen's outer product of an expression went through
    // its general kernel, 8% of the knocked wall's step (the same products, the same bits).
    const auto add_outer = [&work](SparseIndex i, const Eigen::Matrix<double, 6, 1>& s, const Row& g) {
      Block& block = work.system[static_cast<std::size_t>(i)];
      for (int column = 0; column < 6; ++column) block.col(column) += g(column) * s;
    };
    const Eigen::Matrix<double, 6, 1> da = dk * ga;
    add_outer(at[0], da, ga);
    if (b < 0) continue;
    const Eigen::Matrix<double, 6, 1> db = dk * gb;
    add_outer(at[1], da, gb);
    add_outer(at[2], db, ga);
    add_outer(at[3], db, gb);
  }
}

// An iterate p (w = A p − c in work.w) that meets the stopping rule into p_out: the rows that separate by
// more than the tolerance let go of their (small) impulses if the rule still holds without them.
void accept(const ComplementarityProblem& problem, double a_scale, const Vector& p, BodySpaceWorkspace& work,
            Vector& p_out) {
  work.candidate = p;
  for (Eigen::Index k = 0; k < p.size(); ++k)
    if (work.w(k) > problem.tolerance) work.candidate(k) = 0.0;
  work.check.noalias() = *problem.matrix * work.candidate;
  work.check -= problem.rhs;
  p_out = excess(work.candidate, work.check, problem.rhs, problem.tolerance, a_scale) <= 1.0 ? work.candidate : p;
}
}  // namespace

bool suits_body_space(const ComplementarityProblem& problem, const SolverSettings& settings) {
  const BodySpace* body = problem.body_space;
  if (body == nullptr || settings.interior_point_rows == 0) return false;
  const auto m = static_cast<std::size_t>(problem.rhs.size());
  if (m < settings.interior_point_rows || body->blocks.size() != m || body->jacobian.size() != m ||
      body->inertia.size() != body->mass.size() || 6 * body->mass.size() >= m)
    return false;
  const auto blocks = static_cast<std::int32_t>(body->mass.size());
  for (const auto& [a, b] : body->blocks)  // side a movable, side b movable or none (assemble_body_space)
    if (a < 0 || a >= blocks || b < -1 || b >= blocks) return false;
  return std::none_of(problem.equality.begin(), problem.equality.end(), [](char e) { return e != 0; });
}

bool solve_in_body_space(const ComplementarityProblem& problem, double stall_excess, BodySpaceWorkspace& work,
                         SolverStats& stats, Vector& p_out) {
  const BodySpace& body = *problem.body_space;
  const SparseMatrix& a = *problem.matrix;
  const Vector& c = problem.rhs;
  const auto m = static_cast<Eigen::Index>(body.blocks.size()), n = static_cast<Eigen::Index>(6 * body.mass.size());
  const double tolerance = problem.tolerance;
  const double c_scale = c.lpNorm<Eigen::Infinity>();
  if (!(c_scale > tolerance) || !std::isfinite(c_scale)) return false;  // p = 0 (or nothing sane): the search's
  double a_scale = 0.0;
  for (Eigen::Index k = 0; k < m; ++k) a_scale = std::max(a_scale, a.coeff(k, k));
  if (!(a_scale > 0.0)) return false;

  build_body_pattern(body, work);
  if (!work.analysed || !work.factor.same_pattern(work.neighbour_start, work.neighbours)) {
    work.factor.analyze(work.neighbour_start, work.neighbours);
    work.analysed = true;
  }
  Vector &u = work.u, &p = work.p, &s = work.s;
  u.setZero(n);
  s = ((-c).cwiseMax(0.0).array() + c_scale).matrix();  // strictly interior, of the problem's scale
  p.setConstant(m, c_scale / a_scale);
  const double delta = kRegularization * a_scale;
  double best = std::numeric_limits<double>::infinity(), mark = best;  // mark: the best kStallSteps steps ago
  int best_step = 0;
  bool best_usable = false;  // the best iterate is within stall_excess of the rule, no row approaching
  for (int step = 0; step < kMaxSteps; ++step) {
    // Residuals: dual M u − Gᵀ p, primal G u − c − s, and the mean complementarity μ.
    multiply_m(body, u, work.dual);
    multiply_g_transpose(body, p, work.rhs);
    work.dual -= work.rhs;
    multiply_g(body, u, work.primal);
    work.primal -= c + s;
    const double mu = p.dot(s) / static_cast<double>(m);

    // Judged on the impulses themselves: w = A p − c, which carries the dual residual's error.
    work.w.noalias() = a * p;
    work.w -= c;
    const double worst = excess(p, work.w, c, tolerance, a_scale);
    if (worst < best) {
      best = worst;
      best_step = step;
      // The best iterate a stall may take (below): kept while it is within reach of being taken.
      best_usable = worst <= stall_excess && work.w.minCoeff() >= -tolerance;
      if (best_usable) work.best = p;
    }
    if (worst <= 1.0) {
      accept(problem, a_scale, p, work, p_out);
      ++stats.interior_point_solved;
      return true;
    }
    const bool stalled = step - best_step > kStallSteps;  // at the regularization's or rounding's floor
    bool creeping = false;
    if (step > 0 && step % kStallSteps == 0) {
      creeping = best > 0.5 * mark;
      mark = best;
    }
    if ((stalled || creeping) && best_usable) {
      work.w.noalias() = a * work.best;
      work.w -= c;
      accept(problem, a_scale, work.best, work, p_out);
      ++stats.interior_point_solved;
      ++stats.interior_point_loose;
      return true;
    }
    if (stalled) return false;

    // The Newton system in body space, regularized (primal–dual regularization): the primal equation
    // G du − ds = −r_p gets + δ dp, which caps D = (S P⁻¹ + δ)⁻¹ at 1/δ. Without it D grows without bound
    // on the rows that end pushing, and the rounding of the solve shows up as a growing dual residual
    // (on the knocked wall, M u − Gᵀp grew from 1e-10 to 1e-6 while μ fell, and the iteration stalled).
    // The dual and complementarity equations hold exactly; the primal one is off by δ dp, which the
    // next step's residual takes up.
    //   (M + Gᵀ D G) du = −r_d − Gᵀ D (r_p − P⁻¹ r_c),  dp = −D (G du + r_p − P⁻¹ r_c),  ds = G du + r_p + δ dp.
    work.ratio = (s.cwiseQuotient(p).array() + delta).inverse().matrix();
    system_values(body, work.ratio, work);
    // Positive definite by construction (M > 0): a pivot block that is not means rounding has won.
    if (!work.factor.factorize(work.system)) return false;
    ++stats.interior_point_steps;
    // With `residuals` false, the direction that changes only the complementarity products (a corrector).
    const auto direction = [&](const Vector& complement, bool residuals, Vector& du, Vector& ds, Vector& dp) {
      work.target = -complement.cwiseQuotient(p);
      if (residuals) work.target += work.primal;
      work.target = work.ratio.cwiseProduct(work.target);
      multiply_g_transpose(body, work.target, work.rhs);
      du = -work.rhs;
      if (residuals) du -= work.dual;
      work.factor.solve(du);
      multiply_g(body, du, ds);
      if (residuals) ds += work.primal;
      dp = -work.ratio.cwiseProduct(ds - complement.cwiseQuotient(p));
      ds += delta * dp;
    };
    // Predictor (affine scaling), then the corrector with centring σ = (μ_aff / μ)³.
    work.complement = -p.cwiseProduct(s);
    direction(work.complement, true, work.du_aff, work.ds_aff, work.dp_aff);
    const double primal_aff = longest_step(s, work.ds_aff), dual_aff = longest_step(p, work.dp_aff);
    const double mu_aff =
        (s + primal_aff * work.ds_aff).dot(p + dual_aff * work.dp_aff) / static_cast<double>(m);
    const double sigma = std::pow(mu_aff / mu, 3);
    work.complement = (sigma * mu - p.cwiseProduct(s).array() - work.ds_aff.cwiseProduct(work.dp_aff).array()).matrix();
    direction(work.complement, true, work.du, work.ds, work.dp);
    double alpha = std::min(longest_step(s, work.ds), longest_step(p, work.dp));
    // Gondzio's centrality correctors: at a trial point past the step the direction allows, pull the
    // products p_k s_k that left [0.1, 10] · σμ back into it, kept while they lengthen the step.
    for (int corrector = 0; corrector < kCorrectors && alpha < 1.0; ++corrector) {
      const double trial = std::min(1.0, kTrialStretch * alpha + kTrialReach);
      const double centre = sigma * mu;
      for (Eigen::Index k = 0; k < m; ++k) {
        const double product = (s(k) + trial * work.ds(k)) * (p(k) + trial * work.dp(k));
        work.complement(k) = std::max(std::clamp(product, kCentreLow * centre, kCentreHigh * centre) - product,
                                      -kCentreHigh * centre);
      }
      direction(work.complement, false, work.du_aff, work.ds_aff, work.dp_aff);
      work.du_aff += work.du;
      work.ds_aff += work.ds;
      work.dp_aff += work.dp;
      const double longer = std::min(longest_step(s, work.ds_aff), longest_step(p, work.dp_aff));
      if (!(longer >= kCorrectorGain * alpha)) break;
      work.du.swap(work.du_aff);
      work.ds.swap(work.ds_aff);
      work.dp.swap(work.dp_aff);
      alpha = longer;
    }
    alpha *= kStepFraction;
    u += alpha * work.du;
    s += alpha * work.ds;
    p += alpha * work.dp;
    if (!u.allFinite() || !p.allFinite()) return false;
  }
  return false;
}

}  // namespace impetus::ledas
