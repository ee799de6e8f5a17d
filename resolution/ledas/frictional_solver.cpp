// The frictional contact problem of one island (frictional_solver.hpp): semismooth Newton on the
// Alart–Curnier function with a line search, a projected Gauss–Seidel fallback, nonsmooth Gauss–Seidel
// sweeps as the last stage, fclib's natural-map residual as the error.
#include "impetus/resolution/ledas/frictional_solver.hpp"

#include "cone_qp.hpp"
#include "sparse_lu.hpp"
#include "impetus/resolution/ledas/masked_ldlt.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace impetus::ledas {

// One contact (or joint row) of the problem: its rows first .. first + size − 1.
struct FrictionalSolver::Block {
  Eigen::Index first = 0;
  int size = 1;  // 1 (joint row, frictionless contact) or 3 (normal, t1, t2)
  RowRole role = RowRole::normal;
  double mu = 0.0;
  // The weights: Alart–Curnier's 1/W_nn and 2/(W_t1t1 + W_t2t2) for Coulomb's problem; for the convex
  // relaxation one weight for the contact's three rows, 1/λ_max of its 3 × 3 block of W (the cone is
  // projected on as a whole, so the weight must be the same along n and t).
  double rho_n = 1.0, rho_t = 1.0;
  bool convex = false;  // the relaxation's cone complementarity r ∈ K, u ∈ K*, r ⊥ u (no De Saxcé shift)
};

namespace {

// Armijo's constant and the shortest step tried by the line search.
constexpr double kArmijo = 1e-4;
constexpr double kShortestStep = 1e-10;
// Newton steps of a contact's local problem at most (contact_solve): a 3 × 3 problem converges in a few.
constexpr int kContactNewtonSteps = 30;
// The nonsmooth Gauss–Seidel stage (FrictionalSolver::nonsmooth_gauss_seidel): the residual is checked
// every kSweepCheck sweeps, and the stage ends when kSweepStall sweeps have not halved the best one.
constexpr std::uint64_t kSweepCheck = 32;
constexpr std::uint64_t kSweepStall = 128;
// It hands its iterate to Newton once within this factor of the tolerance (Newton converges fast from
// there, the sweeps only linearly), or when it stalls, with this many Newton steps at most.
constexpr double kSweepHandoff = 1e4;
constexpr std::uint64_t kSweepNewtonSteps = 30;
// The projection stage (FrictionalSolver::projection): its step is kProjectionStep / λ, λ the largest
// eigenvalue of D^½ W D^½ (D the contacts' weights 1/W_nn), estimated by kPowerIterations steps of the
// power method. On a quadratic, r ← r − ρ D ∇ converges for ρ λ < 2: on the dropped sphere pyramid K = 10
// at μ = 0.5 (λ = 14.3) ρ λ = 1.95 reached 1e-4 in 3,300 iterations, 1.0 in 6,100, and 2.9 diverged.
// A residual above kProjectionDiverged × the best met halves the step and restarts from the best
// iterate. The residual is checked every kProjectionCheck iterations; the stage ends when
// kProjectionStall iterations have not halved the best one (the iterates do not decrease it
// monotonically), or when kProjectionEntry have not brought it within kProjectionEntryFactor of the best
// of the stages before (on the pyramid K = 20 dropped at μ = 0.2 it is 3.9× above that best after 4,096
// iterations and solves the problem after 25,000; on a 1,119-row island of the frictional pile it creeps
// 170× above). Newton (kSweepNewtonSteps) is tried from the iterate when the best residual first falls
// below kProjectionNewton × the tolerance, then each time it has fallen kProjectionNewtonFactor lower.
constexpr double kProjectionStep = 1.8;
constexpr int kPowerIterations = 30;
constexpr double kProjectionDiverged = 1e3;
constexpr std::uint64_t kProjectionCheck = 64;
constexpr std::uint64_t kProjectionStall = 16384;
constexpr std::uint64_t kProjectionEntry = 4096;
constexpr double kProjectionEntryFactor = 10.0;
constexpr double kProjectionNewton = 1e7;
constexpr double kProjectionNewtonFactor = 0.1;
// The sticking guess (FrictionalSolver::sticking_guess): its answer counts as in the cones within this
// fraction of its largest normal impulse, and gets at most this many Newton steps.
constexpr double kGuessConeSlack = 1e-9;
constexpr std::uint64_t kGuessNewtonSteps = 3;

// Cadoux's fixed point (FrictionalSolver::solve, 2 and 4) stops when this many steps have not halved the
// best residual of its iterates, or when twice as many have not brought it below the best before it.
constexpr std::uint64_t kFixedPointStall = 3;
// The check of a slipping warm answer (FrictionalSettings::slip_check): the interior point's target, ×
// the tolerance, and how far above that target Coulomb's residual of its iterate must lie to show that
// no static equilibrium exists (10⁷ × the tolerance: 1e-3 ‖q‖).
constexpr double kSlipCheckTarget = 1e4;
constexpr double kSlipCheckMargin = 1e3;
// A warm-started problem that its warm Newton steps leave unsolved or slipping: Newton on the relaxation
// first, at most this many steps, from the slipping answer or the warm start (FrictionalSolver::
// warm_relaxation). On the frictional pile and heap (islands of 2–1,500 rows) 12 steps solved ~85% of
// these relaxations, in 4–7 steps on average; most of the rest stall at once (no step is accepted).
constexpr std::uint64_t kWarmRelaxationSteps = 12;

using Block = FrictionalSolver::Block;


// How the Alart–Curnier function (or, for the relaxation, the natural map) is linearized at the current
// iterate, per block.
enum class Piece : std::uint8_t {
  open,    // z_n ≤ 0 (separating), or z in the cone's polar: F = r
  active,  // F = ρ u on every row (a joint row, a pressed frictionless contact, a sticking contact)
  slide,   // normal row ρ_n u_n, tangent rows r_t − μ z_n ẑ_t
  surface  // relaxation: F = r − P_K(z) with z projected on the cone's surface
};

struct Linearization {
  Piece piece = Piece::open;
  double dir1 = 0.0, dir2 = 0.0;  // slide, surface: ẑ_t
  double ratio = 0.0;             // slide: c = μ z_n / ‖z_t‖ (< 1); surface: μ s / ‖z_t‖
};

// W by its blocks of a contact's rows (1 or 3 rows each), block row after block row, for the projection
// stage's product with W at every iteration: a contact's rows share their columns, so one index is read
// per block instead of one per entry, and a 3 × 3 block's nine products run on three rows at once. Each
// row's sum runs over the same entries in the same order as W's own product (W symmetric, a row read as
// its column, entries by increasing row): the same bits as `w.transpose() * x`, with +0 for an entry
// one row of a block lacks and another has. On the dropped pyramid K = 20 (1,770 rows, 53,874 entries),
// a product took 12.7 µs against 22.5 µs (a scratch loop of 5,000).
class BlockedW {
 public:
  void assign(const SparseMatrix& w, const std::vector<Block>& blocks);
  void multiply(const Vector& x, Vector& y) const;  ///< y = W x

 private:
  std::vector<Eigen::Index> first_;    // per block: its first row
  std::vector<int> size_;              // its rows, 1 or 3
  std::vector<std::size_t> start_;     // per block row: its first entry in column_ and value_at_
  std::vector<int> column_;            // per stored block: its block column
  std::vector<std::size_t> value_at_;  // its first value in value_ (rows × columns, by rows)
  std::vector<double> value_;
  std::vector<int> block_of_row_;            // assign's scratch: each row's block
  std::vector<std::size_t> slot_, seen_;     // a block column's place in the current block row, and
                                             // the block row that last saw it (+1; 0: none)
};

void BlockedW::assign(const SparseMatrix& w, const std::vector<Block>& blocks) {
  const std::size_t n = blocks.size();
  block_of_row_.resize(static_cast<std::size_t>(w.rows()));
  first_.resize(n);
  size_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    first_[k] = blocks[k].first;
    size_[k] = blocks[k].size;
    for (int i = 0; i < blocks[k].size; ++i) block_of_row_[static_cast<std::size_t>(blocks[k].first + i)] = static_cast<int>(k);
  }
  slot_.resize(n);
  seen_.assign(n, 0);
  start_.assign(1, 0);
  column_.clear();
  value_at_.clear();
  value_.clear();
  for (std::size_t b = 0; b < n; ++b) {
    const std::size_t begin = column_.size();
    for (int i = 0; i < size_[b]; ++i)
      for (SparseMatrix::InnerIterator it(w, first_[b] + i); it; ++it)
        if (const int c = block_of_row_[static_cast<std::size_t>(it.row())]; seen_[static_cast<std::size_t>(c)] != b + 1) {
          seen_[static_cast<std::size_t>(c)] = b + 1;
          column_.push_back(c);
        }
    std::sort(column_.begin() + static_cast<std::ptrdiff_t>(begin), column_.end());
    for (std::size_t p = begin; p < column_.size(); ++p) {
      const auto c = static_cast<std::size_t>(column_[p]);
      slot_[c] = p;
      value_at_.push_back(value_.size());
      value_.resize(value_.size() + static_cast<std::size_t>(size_[b] * size_[c]), 0.0);
    }
    for (int i = 0; i < size_[b]; ++i)  // W(first_b + i, first_c + j) = column first_b + i at row first_c + j
      for (SparseMatrix::InnerIterator it(w, first_[b] + i); it; ++it) {
        const auto c = static_cast<std::size_t>(block_of_row_[static_cast<std::size_t>(it.row())]);
        value_[value_at_[slot_[c]] + static_cast<std::size_t>(i * size_[c]) + static_cast<std::size_t>(it.row() - first_[c])] = it.value();
      }
    start_.push_back(column_.size());
  }
}

void BlockedW::multiply(const Vector& x, Vector& y) const {
  y.resize(x.size());
  for (std::size_t b = 0; b + 1 < start_.size(); ++b) {
    const Eigen::Index row = first_[b];
    if (size_[b] == 3) {
      double s0 = 0.0, s1 = 0.0, s2 = 0.0;
      for (std::size_t p = start_[b]; p < start_[b + 1]; ++p) {
        const auto c = static_cast<std::size_t>(column_[p]);
        const double* v = value_.data() + value_at_[p];
        const double* xc = x.data() + first_[c];
        if (size_[c] == 3) {
          s0 += v[0] * xc[0];
          s0 += v[1] * xc[1];
          s0 += v[2] * xc[2];
          s1 += v[3] * xc[0];
          s1 += v[4] * xc[1];
          s1 += v[5] * xc[2];
          s2 += v[6] * xc[0];
          s2 += v[7] * xc[1];
          s2 += v[8] * xc[2];
        } else {
          s0 += v[0] * xc[0];
          s1 += v[1] * xc[0];
          s2 += v[2] * xc[0];
        }
      }
      y(row) = s0;
      y(row + 1) = s1;
      y(row + 2) = s2;
    } else {
      double sum = 0.0;
      for (std::size_t p = start_[b]; p < start_[b + 1]; ++p) {
        const auto c = static_cast<std::size_t>(column_[p]);
        const double* v = value_.data() + value_at_[p];
        const double* xc = x.data() + first_[c];
        for (int j = 0; j < size_[c]; ++j) sum += v[j] * xc[j];
      }
      y(row) = sum;
    }
  }
}

}  // namespace

// Newton's buffers (sized on first use, reused while the problem's size does not change).
struct FrictionalWorkspace::Newton {
  std::vector<Block> blocks;
  Vector diagonal;
  Vector best, u, f, trial, u_trial, f_trial, d, wd;
  std::vector<Linearization> lin, lin_trial;
  Eigen::MatrixXd jacobian;  // the dense path's
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
  // The sparse path's: the Jacobian on a pattern every linearization's entries lie in (jacobian_pattern),
  // and its LU (KLU), whose ordering and symbolic analysis are kept while W's pattern (`analysed_outer`,
  // `analysed_inner`) and the blocks' sizes do not change; `check` holds J d + F of a refactorization.
  std::vector<Eigen::Triplet<double>> entries;
  RowMajorMatrix sparse_jacobian;
  std::vector<int> slot;  // assembly: a column's place in the current block's rows
  SparseLu sparse_lu;
  Vector check;
  std::vector<SparseMatrix::StorageIndex> analysed_outer, analysed_inner;
  std::vector<int> analysed_blocks;
  // The symmetric path's (no block slides): LDLᵀ of (W + shift I) on the active rows, W's analysis kept
  // while its pattern does not change (and shared with the interior point's P + T², whose pattern is W's);
  // the active rows and the right-hand side.
  MaskedLdlt ldlt;
  std::vector<char> active;
  Vector rhs;
  // What ldlt's last factorization by symmetric_direction was of (which W, the active rows, the shift)
  // and its number (MaskedLdlt::factorizations): a step with the same matrix reuses it. Forgotten
  // (factored_number = 0) whenever a W it may have been may change: at each solve() and when the
  // proximal stage shifts its copy of W.
  const SparseMatrix* factored_w = nullptr;
  std::vector<char> factored_active;
  double factored_shift = 0.0;
  std::uint64_t factored_number = 0;
  bool reused = false;  // whether the last direction reused that factorization
  // The cold path's (solve, solve_stages, proximal_newton): kept so that a cold solve of a problem with
  // the last one's pattern allocates nothing either (where no contact slides above `dense_limit`).
  ConeQpWorkspace cone_qp;
  std::vector<Block> stage_blocks;
  Vector stage_diagonal, stage_best, cold_best, polished, velocity, next, over, warm_answer, warm_copy;
  FrictionalProblem relaxed, sub, exact;
  SparseMatrix shifted;
  // The nonsmooth Gauss–Seidel stage's: each block's own 3 × 3 block of W, its iterate and velocities.
  std::vector<Eigen::Matrix3d> block_w;
  Vector sweep_r, sweep_u, sweep_best;
  // The projection stage's: its iterate, velocities and modified velocities, the rows' weights, the
  // power method's vectors and the stage's answer.
  Vector projection_r, projection_u, projection_f, projection_weight, projection_power, projection_image,
      projection_best;
  BlockedW projection_w;  // W by blocks, for its products
  Vector relaxation_answer;  // Cadoux's fixed point: the last relaxation's answer
  Vector relaxation_first;   // the first relaxation's answer (the projection stage starts from it)
  Vector coulomb_answer;     // the interior point's on Coulomb's problem
};

void FrictionalWorkspace::forget_analyses() {
  if (!newton) return;
  newton->ldlt.forget_pattern();
  newton->analysed_outer.clear();  // KLU's ordering and the Jacobian's pattern
  newton->analysed_inner.clear();
  newton->cone_qp.outer.clear();  // the interior point's pattern
  newton->cone_qp.inner.clear();
  newton->factored_number = 0;
}

FrictionalWorkspace::FrictionalWorkspace() = default;
FrictionalWorkspace::~FrictionalWorkspace() = default;
FrictionalWorkspace::FrictionalWorkspace(FrictionalWorkspace&&) noexcept = default;
FrictionalWorkspace& FrictionalWorkspace::operator=(FrictionalWorkspace&&) noexcept = default;

namespace {

// The largest eigenvalue of the symmetric 3 × 3 block of W at rows first .. first + 2.
double block_largest_eigenvalue(const SparseMatrix& w, Eigen::Index first) {
  Eigen::Matrix3d block = Eigen::Matrix3d::Zero();
  for (int c = 0; c < 3; ++c)
    for (SparseMatrix::InnerIterator it(w, first + c); it; ++it)
      if (it.row() >= first && it.row() < first + 3) block(it.row() - first, c) = it.value();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(block, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
}

// The problem's blocks into `blocks` (its storage reused), with W's diagonal `diagonal`.
void make_blocks(const FrictionalProblem& problem, const Vector& diagonal, std::vector<Block>& blocks) {
  const auto m = problem.q.size();
  if (problem.role.size() != static_cast<std::size_t>(m) || problem.mu.size() != static_cast<std::size_t>(m))
    throw std::invalid_argument("frictional problem: role and mu must have one entry per row");
  blocks.clear();
  for (Eigen::Index i = 0; i < m;) {
    Block b;
    b.first = i;
    b.role = problem.role[static_cast<std::size_t>(i)];
    if (b.role == RowRole::tangent) throw std::invalid_argument("frictional problem: a tangent row without its normal row");
    const double mu = problem.mu[static_cast<std::size_t>(i)];
    if (b.role == RowRole::normal && mu > 0.0) {
      if (i + 2 >= m || problem.role[static_cast<std::size_t>(i + 1)] != RowRole::tangent ||
          problem.role[static_cast<std::size_t>(i + 2)] != RowRole::tangent)
        throw std::invalid_argument("frictional problem: a frictional normal row must be followed by two tangent rows");
      b.size = 3;
      b.mu = mu;
    }
    b.rho_n = diagonal(i) > 0.0 ? 1.0 / diagonal(i) : 1.0;
    if (b.size == 3 && problem.convex) {
      b.convex = true;
      const double largest = block_largest_eigenvalue(*problem.w, i);
      b.rho_n = b.rho_t = largest > 0.0 ? 1.0 / largest : 1.0;
    } else if (b.size == 3) {
      const double trace = diagonal(i + 1) + diagonal(i + 2);
      b.rho_t = trace > 0.0 ? 2.0 / trace : b.rho_n;
    }
    blocks.push_back(b);
    i += b.size;
  }
}

// The relaxation's block of F = r − P_K(z), z = r − ρ u, and its piece.
void evaluate_cone(const Block& b, const Vector& r, const Vector& u, Vector& f, Linearization& l) {
  const Eigen::Index n = b.first;
  const double zn = r(n) - b.rho_n * u(n), z1 = r(n + 1) - b.rho_t * u(n + 1), z2 = r(n + 2) - b.rho_t * u(n + 2);
  const double norm = std::hypot(z1, z2);
  if (norm <= b.mu * zn) {  // inside: F = ρ u
    l.piece = Piece::active;
    for (int j = 0; j < 3; ++j) f(n + j) = b.rho_n * u(n + j);
    return;
  }
  if (b.mu * norm <= -zn) {  // in the polar cone: P_K(z) = 0
    l.piece = Piece::open;
    for (int j = 0; j < 3; ++j) f(n + j) = r(n + j);
    return;
  }
  // On the surface: P_K(z) = (s, μ s ẑ_t), s = (z_n + μ‖z_t‖)/(1 + μ²).
  const double s = (zn + b.mu * norm) / (1.0 + b.mu * b.mu);
  l.piece = Piece::surface;
  l.dir1 = z1 / norm;
  l.dir2 = z2 / norm;
  l.ratio = b.mu * s / norm;
  f(n) = r(n) - s;
  f(n + 1) = r(n + 1) - b.mu * s * l.dir1;
  f(n + 2) = r(n + 2) - b.mu * s * l.dir2;
}

// F (the Alart–Curnier function, or the relaxation's natural map) at r with u = W r + q, and how each
// block is linearized there.
void evaluate(const std::vector<Block>& blocks, const Vector& r, const Vector& u, Vector& f,
              std::vector<Linearization>& lin) {
  lin.resize(blocks.size());
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const Block& b = blocks[k];
    const Eigen::Index n = b.first;
    Linearization& l = lin[k];
    if (b.role == RowRole::equality) {
      l.piece = Piece::active;
      f(n) = b.rho_n * u(n);
      continue;
    }
    if (b.convex) {
      evaluate_cone(b, r, u, f, l);
      continue;
    }
    const double zn = r(n) - b.rho_n * u(n);
    if (zn <= 0.0) {
      l.piece = Piece::open;
      for (int j = 0; j < b.size; ++j) f(n + j) = r(n + j);
      continue;
    }
    f(n) = b.rho_n * u(n);
    l.piece = Piece::active;
    if (b.size == 1) continue;
    const double z1 = r(n + 1) - b.rho_t * u(n + 1), z2 = r(n + 2) - b.rho_t * u(n + 2);
    const double radius = b.mu * zn, norm = std::hypot(z1, z2);
    if (norm <= radius) {  // inside the disk: F_t = r_t − z_t = ρ_t u_t (stick)
      f(n + 1) = b.rho_t * u(n + 1);
      f(n + 2) = b.rho_t * u(n + 2);
      continue;
    }
    l.piece = Piece::slide;
    l.dir1 = z1 / norm;
    l.dir2 = z2 / norm;
    l.ratio = radius / norm;
    f(n + 1) = r(n + 1) - radius * l.dir1;
    f(n + 2) = r(n + 2) - radius * l.dir2;
  }
}

// The generalized Jacobian of F, built through `add(row, col, value)` (duplicates add up). W is taken
// with its diagonal shifted by `shift`.
template <typename Add>
void assemble_jacobian(const std::vector<Block>& blocks, const std::vector<Linearization>& lin,
                       const SparseMatrix& w, double shift, Add&& add) {
  // add(row, ·) += scale × (W + shift I)(source, ·); W is symmetric, so its row is its column.
  const auto add_w_row = [&](Eigen::Index row, Eigen::Index source, double scale) {
    if (scale == 0.0) return;
    for (SparseMatrix::InnerIterator it(w, source); it; ++it) add(row, it.row(), scale * it.value());
    add(row, source, scale * shift);
  };
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const Block& b = blocks[k];
    const Linearization& l = lin[k];
    const Eigen::Index n = b.first;
    if (l.piece == Piece::open) {
      for (int j = 0; j < b.size; ++j) add(n + j, n + j, 1.0);
      continue;
    }
    if (l.piece == Piece::surface) {
      // dF = (I − J) dr + ρ J W dr, J = P_K's derivative on the surface (symmetric):
      //   J_nn = 1/(1 + μ²), J_nt = μ ẑᵀ/(1 + μ²), J_tt = μ² ẑẑᵀ/(1 + μ²) + (μ s/‖z_t‖)(I − ẑẑᵀ).
      const double dir[3] = {1.0, l.dir1, l.dir2}, scale = 1.0 / (1.0 + b.mu * b.mu);
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) {
          const double along = (a == 0 ? 1.0 : b.mu) * (c == 0 ? 1.0 : b.mu) * dir[a] * dir[c] * scale;
          const double across = a > 0 && c > 0 ? l.ratio * ((a == c ? 1.0 : 0.0) - dir[a] * dir[c]) : 0.0;
          const double j = along + across;
          add(n + a, n + c, (a == c ? 1.0 : 0.0) - j);
          add_w_row(n + a, n + c, b.rho_n * j);
        }
      continue;
    }
    add_w_row(n, n, b.rho_n);
    if (b.size == 1) continue;
    if (l.piece == Piece::active) {
      add_w_row(n + 1, n + 1, b.rho_t);
      add_w_row(n + 2, n + 2, b.rho_t);
      continue;
    }
    // Slide: dF_t = dr_t − μ ẑ dz_n − c (I − ẑẑᵀ) dz_t with dz_n = dr_n − ρ_n du_n, dz_t = dr_t − ρ_t du_t.
    const double dir[2] = {l.dir1, l.dir2};
    for (int a = 0; a < 2; ++a) {
      const Eigen::Index row = n + 1 + a;
      add(row, n, -b.mu * dir[a]);
      add_w_row(row, n, b.mu * b.rho_n * dir[a]);
      for (int c = 0; c < 2; ++c) {
        const double projector = (a == c ? 1.0 : 0.0) - dir[a] * dir[c];
        add(row, n + 1 + c, (a == c ? 1.0 : 0.0) - l.ratio * projector);
        add_w_row(row, n + 1 + c, l.ratio * b.rho_t * projector);
      }
    }
  }
}

// Whether the Jacobian is symmetric up to its rows' weights: every block open (J = I) or active
// (J = diag(ρ)(W + shift I)), none sliding or on the relaxation's cone surface.
bool symmetric_pieces(const std::vector<Linearization>& lin) {
  return std::all_of(lin.begin(), lin.end(),
                     [](const Linearization& l) { return l.piece == Piece::open || l.piece == Piece::active; });
}

// Whether a pressed contact slips at r (a block on the slide piece of the Alart–Curnier function), with
// Newton's buffers as scratch.
bool slips(const FrictionalProblem& problem, const std::vector<Block>& blocks, const Vector& r,
           FrictionalWorkspace::Newton& buffers) {
  buffers.u.noalias() = problem.w->transpose() * r;  // = W r (symmetric), as a gather
  buffers.u += problem.q;
  buffers.f.resize(r.size());
  evaluate(blocks, r, buffers.u, buffers.f, buffers.lin);
  return std::any_of(buffers.lin.begin(), buffers.lin.end(), [](const Linearization& l) { return l.piece == Piece::slide; });
}

// The Newton direction when symmetric_pieces(lin): on the open rows O, d_O = −F_O; on the active rows A,
// (W + shift I)_AA d_A = −F_A/ρ − W_AO d_O, symmetric positive definite (shift > 0), by sparse LDLᵀ on
// W's pattern restricted to A: less work than J's LU (symmetric, no pivoting), and it splits across
// threads (MaskedLdlt). With shift = 0 a redundant row of A is dropped (the basic solution, which gives
// the same W d).
bool symmetric_direction(const std::vector<Block>& blocks, const std::vector<Linearization>& lin, const SparseMatrix& w,
                         double shift, const Vector& f, FrictionalWorkspace::Newton& buffers, Vector& d) {
  constexpr double kRankTolerance = 1e-12;  // only used without a shift
  const Eigen::Index m = f.size();
  std::vector<char>& active = buffers.active;
  active.assign(static_cast<std::size_t>(m), 0);
  Vector& rhs = buffers.rhs;
  rhs.setZero(m);
  d.resize(m);
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const Block& b = blocks[k];
    for (int j = 0; j < b.size; ++j) {
      const Eigen::Index row = b.first + j;
      if (lin[k].piece == Piece::open) {
        d(row) = -f(row);
        continue;
      }
      active[static_cast<std::size_t>(row)] = 1;
      d(row) = 0.0;
      rhs(row) = -f(row) / (j == 0 ? b.rho_n : b.rho_t);
    }
  }
  for (Eigen::Index c = 0; c < m; ++c) {  // − W_AO d_O
    if (active[static_cast<std::size_t>(c)] || d(c) == 0.0) continue;
    for (SparseMatrix::InnerIterator it(w, c); it; ++it)
      if (active[static_cast<std::size_t>(it.row())]) rhs(it.row()) -= it.value() * d(c);
  }
  MaskedLdlt& ldlt = buffers.ldlt;
  if (!ldlt.same_pattern(w)) ldlt.analyze(w);
  // The same matrix as the last step's (a step that keeps the active set, as Newton's last steps near a
  // solution do, and nothing factorized in between): its factorization, bit for bit the one a new
  // factorization would give, is reused.
  const bool same_matrix = buffers.factored_number != 0 && ldlt.factorizations() == buffers.factored_number &&
                           buffers.factored_w == &w && buffers.factored_shift == shift &&
                           buffers.factored_active == active;
  buffers.reused = same_matrix;
  if (!same_matrix) {
    ldlt.factorize(w, active, shift > 0.0 ? 0.0 : kRankTolerance, 0.0, shift);
    buffers.factored_w = &w;
    buffers.factored_active = active;
    buffers.factored_shift = shift;
    buffers.factored_number = ldlt.factorizations();
  }
  ldlt.solve(rhs);
  for (Eigen::Index row = 0; row < m; ++row)
    if (active[static_cast<std::size_t>(row)]) d(row) = rhs(row);
  return d.allFinite();
}

// The pattern of every Jacobian assemble_jacobian() can build on W's pattern, into `j` (by rows, values
// zero): a row of a block takes W's column of every row of its block (add_w_row) and the block's own
// 3 × 3 block, so the rows of a block share one pattern. Built once per pattern of W.
void jacobian_pattern(const std::vector<Block>& blocks, const SparseMatrix& w,
                      std::vector<Eigen::Triplet<double>>& entries, RowMajorMatrix& j) {
  entries.clear();
  for (const Block& b : blocks)
    for (int a = 0; a < b.size; ++a)
      for (int c = 0; c < b.size; ++c) {
        entries.emplace_back(b.first + a, b.first + c, 0.0);
        for (SparseMatrix::InnerIterator it(w, b.first + c); it; ++it) entries.emplace_back(b.first + a, it.row(), 0.0);
      }
  j.resize(w.rows(), w.cols());
  j.setFromTriplets(entries.begin(), entries.end());
  j.makeCompressed();
}

// The Newton direction: J d = −F, into d (the dense path in `buffers`, without allocating when the
// size did not change; the symmetric path when no block slides). False if the system could not be
// solved to finite values.
bool newton_direction(const std::vector<Block>& blocks, const std::vector<Linearization>& lin, const SparseMatrix& w,
                      double shift, const Vector& f, std::size_t dense_limit, FrictionalWorkspace::Newton& buffers,
                      Vector& d) {
  const Eigen::Index m = f.size();
  buffers.reused = false;
  if (static_cast<std::size_t>(m) <= dense_limit) {
    Eigen::MatrixXd& j = buffers.jacobian;
    j.setZero(m, m);
    assemble_jacobian(blocks, lin, w, shift, [&j](Eigen::Index r, Eigen::Index c, double v) { j(r, c) += v; });
    buffers.lu.compute(j);
    // J d = −F solved as −(J⁻¹ F): the same bits (every operation of the solve is odd in its right-hand
    // side), without a temporary for −F.
    d.noalias() = buffers.lu.solve(f);
    d = -d;
  } else if (w.isCompressed() && symmetric_pieces(lin)) {
    return symmetric_direction(blocks, lin, w, shift, f, buffers, d);
  } else {
    RowMajorMatrix& j = buffers.sparse_jacobian;
    SparseLu& lu = buffers.sparse_lu;
    const bool same_pattern =
        w.isCompressed() && buffers.analysed_outer.size() == static_cast<std::size_t>(m) + 1 &&
        std::equal(buffers.analysed_outer.begin(), buffers.analysed_outer.end(), w.outerIndexPtr()) &&
        buffers.analysed_inner.size() == static_cast<std::size_t>(w.nonZeros()) &&
        std::equal(buffers.analysed_inner.begin(), buffers.analysed_inner.end(), w.innerIndexPtr()) &&
        std::equal(blocks.begin(), blocks.end(), buffers.analysed_blocks.begin(), buffers.analysed_blocks.end(),
                   [](const Block& b, int size) { return b.size == size; });
    if (!same_pattern) {
      jacobian_pattern(blocks, w, buffers.entries, j);
      if (!lu.analyze(j)) return false;
      buffers.analysed_outer.assign(w.outerIndexPtr(), w.outerIndexPtr() + m + 1);
      buffers.analysed_inner.assign(w.innerIndexPtr(), w.innerIndexPtr() + w.nonZeros());
      buffers.analysed_blocks.clear();
      for (const Block& b : blocks) buffers.analysed_blocks.push_back(b.size);
    }
    // The entries in place. assemble_jacobian() adds to the rows of one block after another, and a
    // block's rows share their pattern: `slot` maps a column to its place in the current block's rows.
    std::fill(j.valuePtr(), j.valuePtr() + j.nonZeros(), 0.0);
    const SparseMatrix::StorageIndex* outer = j.outerIndexPtr();
    const SparseMatrix::StorageIndex* inner = j.innerIndexPtr();
    double* value = j.valuePtr();
    std::vector<int>& slot = buffers.slot;
    slot.assign(static_cast<std::size_t>(m), -1);
    Eigen::Index block_first = 0, block_end = 0;
    std::size_t next_block = 0;
    assemble_jacobian(blocks, lin, w, shift, [&](Eigen::Index r, Eigen::Index c, double v) {
      if (r >= block_end) {
        while (r >= blocks[next_block].first + blocks[next_block].size) ++next_block;
        block_first = blocks[next_block].first;
        block_end = block_first + blocks[next_block].size;
        for (auto p = outer[block_first]; p < outer[block_first + 1]; ++p)
          slot[static_cast<std::size_t>(inner[p])] = static_cast<int>(p - outer[block_first]);
      }
      const int place = slot[static_cast<std::size_t>(c)];
      assert(r >= block_first && place >= 0 && inner[outer[block_first] + place] == c &&
             "an entry outside jacobian_pattern()");
      value[outer[r] + place] += v;
    });
    // J d = −F as −(J⁻¹ F). The last pivot sequence first (no allocation); kept if the direction it
    // gives solves J d = −F to a backward error of 1e-12, else a factorization with partial pivoting.
    const auto direction = [&](bool reuse_pivots) {
      if (!lu.factorize(j, reuse_pivots)) return false;
      d = f;
      if (!lu.solve(d)) return false;
      d = -d;
      return true;
    };
    bool solved = direction(true);
    if (solved) {
      Vector& check = buffers.check;
      check.noalias() = j * d;
      check += f;
      double norm = 0.0;  // ‖J‖∞, each row's sum in a local (a store per entry was 2% of a large island's solve)
      for (Eigen::Index row = 0; row < m; ++row) {
        double sum = 0.0;
        for (auto p = outer[row]; p < outer[row + 1]; ++p) sum += std::abs(value[p]);
        norm = std::max(norm, sum);
      }
      solved = check.lpNorm<Eigen::Infinity>() <=
               1e-12 * (norm * d.lpNorm<Eigen::Infinity>() + f.lpNorm<Eigen::Infinity>());
    }
    if (!solved && !direction(false)) {
      buffers.analysed_outer.clear();  // analysed afresh next time
      return false;
    }
  }
  return d.allFinite();
}

// One projected Gauss–Seidel sweep over the blocks, each block's u from the current r.
void gauss_seidel_sweep(const std::vector<Block>& blocks, const SparseMatrix& w, const Vector& q,
                        const Vector& diagonal, Vector& r) {
  const auto velocity = [&](Eigen::Index i) {
    double u = q(i);
    for (SparseMatrix::InnerIterator it(w, i); it; ++it) u += it.value() * r(it.row());
    return u;
  };
  for (const Block& b : blocks) {
    const Eigen::Index n = b.first;
    if (!(diagonal(n) > 0.0)) continue;  // nothing movable behind the row
    if (b.role == RowRole::equality) {
      r(n) -= velocity(n) / diagonal(n);
      continue;
    }
    if (b.size == 1) {
      r(n) = std::max(0.0, r(n) - velocity(n) / diagonal(n));
      continue;
    }
    const double un = velocity(n), u1 = velocity(n + 1), u2 = velocity(n + 2);
    if (b.convex) {  // a projected gradient step on the block: r ← P_K(r − ρ u), ρ = 1/λ_max
      double zn = r(n) - b.rho_n * un, z1 = r(n + 1) - b.rho_n * u1, z2 = r(n + 2) - b.rho_n * u2;
      project_on_cone(b.mu, zn, z1, z2);
      r(n) = zn;
      r(n + 1) = z1;
      r(n + 2) = z2;
      continue;
    }
    r(n) = std::max(0.0, r(n) - b.rho_n * un);
    double t1 = r(n + 1) - b.rho_t * u1, t2 = r(n + 2) - b.rho_t * u2;
    const double radius = b.mu * r(n), norm = std::hypot(t1, t2);
    if (norm > radius) {
      const double scale = norm > 0.0 ? radius / norm : 0.0;
      t1 *= scale;
      t2 *= scale;
    }
    r(n + 1) = t1;
    r(n + 2) = t2;
  }
}

// Coulomb's law at one contact with the others' impulses held (the local problem of a nonsmooth
// Gauss–Seidel sweep): find r with u = a r + b, a the contact's 3 × 3 block of W (symmetric positive
// definite) and b the velocity the rest of the problem gives it. Its three cases in turn: taking off
// (b_n ≥ 0: r = 0), sticking (r = −a⁻¹ b inside the cone), else sliding, which the semismooth Newton
// method on the contact's Alart–Curnier function finds (from `r`, or the sticking impulse projected on
// the cone), with an Armijo line search. Returns the impulse, or `r` unchanged if a is not positive
// definite (the contact then keeps its impulse this sweep).
Eigen::Vector3d contact_solve(const Eigen::Matrix3d& a, const Eigen::Vector3d& b, double mu, Eigen::Vector3d r) {
  using V3 = Eigen::Vector3d;
  if (b(0) >= 0.0) return V3::Zero();
  const Eigen::LLT<Eigen::Matrix3d> llt(a);
  if (llt.info() != Eigen::Success) return r;
  const V3 stick = -llt.solve(b);
  if (stick(0) >= 0.0 && std::hypot(stick(1), stick(2)) <= mu * stick(0)) return stick;
  const double rho_n = 1.0 / a(0, 0), rho_t = 2.0 / (a(1, 1) + a(2, 2));
  // F (the Alart–Curnier function of this contact) at x, and its generalized Jacobian into j if given.
  const auto evaluate_local = [&](const V3& x, Eigen::Matrix3d* j) {
    const V3 u = a * x + b;
    const double zn = x(0) - rho_n * u(0);
    const Eigen::Vector2d zt = x.tail<2>() - rho_t * u.tail<2>();
    const double radius = mu * std::max(0.0, zn), norm = zt.norm();
    V3 f;
    f(0) = zn > 0.0 ? rho_n * u(0) : x(0);
    if (j != nullptr) {
      j->setZero();
      if (zn > 0.0) j->row(0) = rho_n * a.row(0);
      else (*j)(0, 0) = 1.0;
    }
    if (norm <= radius) {
      f.tail<2>() = rho_t * u.tail<2>();
      if (j != nullptr) j->bottomRows<2>() = rho_t * a.bottomRows<2>();
    } else {
      const Eigen::Vector2d hat = zt / norm;
      f.tail<2>() = x.tail<2>() - radius * hat;
      if (j != nullptr) {
        // d(radius ẑ)/dx = ẑ d radius/dx + (radius/‖z_t‖)(I − ẑẑᵀ) dz_t/dx, dz_t/dx = [0 I] − ρ_t a_t.
        Eigen::Matrix<double, 2, 3> dzt = -rho_t * a.bottomRows<2>();
        dzt(0, 1) += 1.0;
        dzt(1, 2) += 1.0;
        Eigen::Matrix<double, 2, 3> dp = (radius / norm) * (Eigen::Matrix2d::Identity() - hat * hat.transpose()) * dzt;
        if (zn > 0.0) {
          Eigen::RowVector3d dradius = -mu * rho_n * a.row(0);
          dradius(0) += mu;
          dp += hat * dradius;
        }
        j->bottomRows<2>() = -dp;
        (*j)(1, 1) += 1.0;
        (*j)(2, 2) += 1.0;
      }
    }
    return f;
  };
  if (!(r(0) > 0.0)) {
    r = stick;
    project_on_cone(mu, r(0), r(1), r(2));
    if (!(r(0) > 0.0)) r = V3(-b(0) / a(0, 0), 0.0, 0.0);
  }
  Eigen::Matrix3d j;
  V3 f = evaluate_local(r, &j);
  double merit = f.squaredNorm();
  const double floor = 1e-32 * (r.squaredNorm() + 1e-300);
  for (int it = 0; it < kContactNewtonSteps && merit > floor; ++it) {
    const V3 d = j.fullPivLu().solve(-f);
    if (!d.allFinite()) break;
    double step = 1.0;
    bool accepted = false;
    for (; step >= kShortestStep; step *= 0.5) {
      const V3 trial = r + step * d;
      const V3 f_trial = evaluate_local(trial, nullptr);
      if (const double trial_merit = f_trial.squaredNorm(); trial_merit <= (1.0 - 2.0 * kArmijo * step) * merit) {
        r = trial;
        f = evaluate_local(r, &j);
        merit = f.squaredNorm();
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
  }
  return r;
}

// More rows than degrees of freedom behind them: W is singular for sure (a box on four corners, a
// stack), and Newton on the problem itself would only stall.
bool likely_redundant(const FrictionalProblem& problem) {
  return problem.dofs > 0 && static_cast<std::size_t>(problem.q.size()) > problem.dofs;
}

}  // namespace

void add(FrictionalStats& into, const FrictionalStats& part) {
  into.problems += part.problems;
  into.warm_started += part.warm_started;
  into.sticking_guessed += part.sticking_guessed;
  into.warm_relaxed += part.warm_relaxed;
  into.relaxed += part.relaxed;
  into.slips_taken += part.slips_taken;
  into.releases += part.releases;
  into.fixed_point_steps += part.fixed_point_steps;
  into.newton_steps += part.newton_steps;
  into.newton_reused += part.newton_reused;
  into.interior_point_steps += part.interior_point_steps;
  into.interior_point_body_steps += part.interior_point_body_steps;
  into.proximal += part.proximal;
  into.proximal_steps += part.proximal_steps;
  into.nonsmooth_sweeps += part.nonsmooth_sweeps;
  into.nonsmooth_solved += part.nonsmooth_solved;
  into.projection_iterations += part.projection_iterations;
  into.projection_solved += part.projection_solved;
  into.coulomb_interior_point_steps += part.coulomb_interior_point_steps;
  into.coulomb_interior_point_solved += part.coulomb_interior_point_solved;
  into.fallbacks += part.fallbacks;
  into.fallback_sweeps += part.fallback_sweeps;
  into.non_converged += part.non_converged;
  into.nan_caught += part.nan_caught;
  into.residual = std::max(into.residual, part.residual);
}

void project_on_cone(double mu, double& yn, double& yt1, double& yt2) {
  const double norm = std::hypot(yt1, yt2);
  if (norm <= mu * yn) return;          // inside the cone
  if (mu * norm <= -yn) {               // inside the polar cone: the apex
    yn = yt1 = yt2 = 0.0;
    return;
  }
  const double s = (yn + mu * norm) / (1.0 + mu * mu);  // onto the cone's surface
  yn = s;
  const double scale = mu * s / norm;
  yt1 *= scale;
  yt2 *= scale;
}

double natural_map_residual(const FrictionalProblem& problem, const Vector& r, const Vector& u) {
  double sum = 0.0;
  const auto m = r.size();
  for (Eigen::Index i = 0; i < m;) {
    const auto k = static_cast<std::size_t>(i);
    if (problem.role[k] == RowRole::equality) {
      sum += u(i) * u(i);
      ++i;
      continue;
    }
    const double mu = problem.mu[k];
    if (!(mu > 0.0)) {
      const double e = r(i) - std::max(0.0, r(i) - u(i));
      sum += e * e;
      ++i;
      continue;
    }
    // y = r − (u + μ‖u_t‖ e_n) (De Saxcé's modified velocity; the relaxation has no shift), then r − P_K(y).
    const double shift = problem.convex ? 0.0 : mu * std::hypot(u(i + 1), u(i + 2));
    double yn = r(i) - u(i) - shift;
    double y1 = r(i + 1) - u(i + 1), y2 = r(i + 2) - u(i + 2);
    project_on_cone(mu, yn, y1, y2);
    const double en = r(i) - yn, e1 = r(i + 1) - y1, e2 = r(i + 2) - y2;
    sum += en * en + e1 * e1 + e2 * e2;
    i += 3;
  }
  return std::sqrt(sum);
}

namespace {

// natural_map_residual with u = W r + q computed into `u` (as every caller computes it: its bits).
double natural_map_residual_in(const FrictionalProblem& problem, const Vector& r, Vector& u) {
  u.noalias() = problem.w->transpose() * r;  // = W r (symmetric), as a gather
  u += problem.q;
  return natural_map_residual(problem, r, u);
}

}  // namespace

double natural_map_residual(const FrictionalProblem& problem, const Vector& r) {
  if (problem.workspace != nullptr) return natural_map_residual_in(problem, r, problem.workspace->u);
  Vector u;
  return natural_map_residual_in(problem, r, u);
}

// Newton's method on `problem` from r (which it overwrites with the best iterate it met, by the
// natural-map residual of `problem`); at most `iterations` steps. Returns that residual.
double FrictionalSolver::newton(const FrictionalProblem& problem, const std::vector<Block>& blocks, Vector& r,
                                std::uint64_t iterations, FrictionalStats& stats) {
  const SparseMatrix& w = *problem.w;
  const Eigen::Index m = problem.q.size();
  const double shift = m > 0 ? settings_.regularization * w.diagonal().maxCoeff() : 0.0;
  FrictionalWorkspace::Newton& buffers = *buffers_;
  Vector &best = buffers.best, &u = buffers.u, &f = buffers.f, &trial = buffers.trial, &u_trial = buffers.u_trial,
         &f_trial = buffers.f_trial, &d = buffers.d;
  std::vector<Linearization>&lin = buffers.lin, &lin_trial = buffers.lin_trial;
  best = r;
  double best_residual = natural_map_residual_in(problem, r, u);  // and u = W r + q
  f.resize(m);
  trial.resize(m);
  u_trial.resize(m);
  f_trial.resize(m);
  evaluate(blocks, r, u, f, lin);
  double merit = 0.5 * f.squaredNorm();
  for (std::uint64_t it = 0; it < iterations && best_residual > problem.tolerance && steps_left_ > 0; ++it) {
    ++stats.newton_steps;
    --steps_left_;
    if (!newton_direction(blocks, lin, w, shift, f, settings_.dense_limit, buffers, d)) {
      ++stats.nan_caught;
      break;
    }
    stats.newton_reused += buffers.reused ? 1 : 0;
    // Armijo on ½‖F‖²: its derivative along the Newton direction is −‖F‖² = −2 merit. u is affine in r:
    // after the full step's u = W (r + d) + q, a shorter trial's is u + step W d, with W d the full
    // step's u minus the current one, and only the step taken gets its u from W again (then F too): at
    // most two products with W per step. With one per trial, Newton's own time, nearly all of it those
    // products, was 14% of a profile of the frictional pile's first 440 steps (sliding islands backtrack
    // often).
    Vector& wd = buffers.wd;
    double step = 1.0, trial_merit = merit;
    bool accepted = false;
    for (; step >= kShortestStep; step *= 0.5) {
      trial = r + step * d;
      if (step == 1.0) {
        u_trial.noalias() = w.transpose() * trial;  // = W trial (symmetric), as a gather
        u_trial += problem.q;
      } else {
        u_trial = u + step * wd;
      }
      evaluate(blocks, trial, u_trial, f_trial, lin_trial);
      trial_merit = 0.5 * f_trial.squaredNorm();
      if (trial_merit <= (1.0 - 2.0 * kArmijo * step) * merit) {
        accepted = true;
        break;
      }
      if (step == 1.0) wd = u_trial - u;
    }
    if (!accepted) break;
    if (step < 1.0) {
      u_trial.noalias() = w.transpose() * trial;
      u_trial += problem.q;
      evaluate(blocks, trial, u_trial, f_trial, lin_trial);
      trial_merit = 0.5 * f_trial.squaredNorm();
    }
    r.swap(trial);
    u.swap(u_trial);
    f.swap(f_trial);
    lin.swap(lin_trial);
    merit = trial_merit;
    // u is W r + q already (computed as natural_map_residual computes it).
    if (const double residual = natural_map_residual(problem, r, u); residual < best_residual) {
      best_residual = residual;
      best = r;
    }
  }
  r = best;
  return best_residual;
}

// Proximal points from r: Newton on u = (W + εI) r + q − ε r̄, r̄ moved to each subproblem's solution. A
// fixed point solves the problem itself; along W's null space (redundant contacts) the impulses stay near
// where they started instead of running off. ε adapts: ×0.1 after a subproblem Newton solved (down to
// the Jacobian's own shift), ×10 after one it could not (up to 0.1 max W_ii: a better conditioned
// subproblem, a slower but surer outer iteration). Each subproblem is solved only to a fraction of the
// current error (an inexact proximal point method), the last ones to the tolerance. Each solved point is
// over-relaxed, r̄ ← r̄ + ω (p − r̄) with ω = `proximal_relaxation` (Eckstein and Bertsekas's relaxed
// proximal point method, which converges for ω in (0, 2) on monotone problems), unless the point solves
// the problem or the relaxed point's residual is more than twice the point's own: where ε's shift makes
// the points creep, it moves r̄ further per solve.
void FrictionalSolver::proximal_newton(const FrictionalProblem& problem, const std::vector<Block>& blocks, Vector& r,
                                       FrictionalStats& stats) {
  const double scale = problem.w->diagonal().maxCoeff();
  const double floor = settings_.regularization * scale, ceiling = 0.1 * scale;
  double epsilon = settings_.proximal * scale;
  double residual = natural_map_residual(problem, r);
  SparseMatrix& shifted = buffers_->shifted;
  double shifted_by = -1.0;
  // The subproblems are of the problem's kind (Coulomb's or the relaxation, `convex`) and judged by its
  // residual: w, q and the tolerance are set per point, the rest copied (the vectors' storage reused).
  FrictionalProblem& sub = buffers_->sub;
  sub = problem;
  Vector& next = buffers_->next;
  for (std::uint64_t outer = 0; outer < settings_.proximal_iterations && residual > problem.tolerance && steps_left_ > 0;
       ++outer) {
    ++stats.proximal_steps;
    if (epsilon != shifted_by) {
      shifted = *problem.w;
      shifted.diagonal().array() += epsilon;
      buffers_->factored_number = 0;  // a factorization of `shifted` is of its old values
      shifted_by = epsilon;
    }
    sub.w = &shifted;
    sub.q = problem.q - epsilon * r;
    sub.tolerance = std::max(0.5 * problem.tolerance, 1e-3 * residual);
    next = r;
    if (newton(sub, blocks, next, settings_.proximal_newton_iterations, stats) <= sub.tolerance) {
      // Over-relaxed (r̄ + ω (p − r̄)), unless p solves the problem or the relaxed point's residual is more
      // than twice p's.
      residual = natural_map_residual(problem, next);
      if (settings_.proximal_relaxation != 1.0 && residual > problem.tolerance) {
        Vector& over = buffers_->over;
        over = r + settings_.proximal_relaxation * (next - r);
        if (const double now = natural_map_residual(problem, over); now <= 2.0 * residual) {
          next.swap(over);
          residual = now;
        }
      }
      r = next;
      epsilon = std::max(0.1 * epsilon, floor);
    } else {
      epsilon = std::min(10.0 * epsilon, ceiling);
    }
  }
}

Vector FrictionalSolver::solve(const FrictionalProblem& problem, FrictionalStats& stats) {
  Vector r;
  solve(problem, stats, r);
  return r;
}

void FrictionalSolver::solve(const FrictionalProblem& problem, FrictionalStats& stats, Vector& r) {
  FrictionalWorkspace own;  // without the problem's workspace (sized here, freed on return)
  FrictionalWorkspace& workspace = problem.workspace != nullptr ? *problem.workspace : own;
  if (!workspace.newton) workspace.newton = std::make_unique<FrictionalWorkspace::Newton>();
  buffers_ = workspace.newton.get();
  buffers_->factored_number = 0;  // this problem's W may sit where the last one's did
  const Eigen::Index m = problem.q.size();
  ++stats.problems;
  const bool warm = problem.start != nullptr && problem.start->size() == m && problem.start->allFinite();
  if (!(warm && problem.start == &r)) r.setZero(m);  // r may be the warm start itself
  double residual = 0.0;
  bool warm_slips = false;  // the warm start's Newton steps reached a slipping answer, kept in warm_answer
  if (warm && !problem.convex) {
    // 0. The warm start (e.g. the last step's impulses): a resting body's usually solve the problem as
    //    they are; otherwise a few Newton steps from them. If those do not reach the tolerance, more
    //    Newton steps; a sticking answer they reach is taken, a slipping one only if the relaxation
    //    below shows that no static equilibrium exists (Newton from a warm start can find a Coulomb
    //    solution that slips where the bodies could stick). Else the cold path below.
    if (problem.start == &r) buffers_->warm_copy = r;  // kept for the relaxation below
    r = *problem.start;
    residual = natural_map_residual(problem, r);
    if (residual > problem.tolerance && settings_.warm_newton_iterations > 0) {
      steps_left_ = settings_.warm_newton_iterations;
      buffers_->diagonal = problem.w->diagonal();
      make_blocks(problem, buffers_->diagonal, buffers_->blocks);
      residual = newton(problem, buffers_->blocks, r, settings_.warm_newton_iterations, stats);
      if (residual > problem.tolerance && settings_.warm_checked_iterations > 0) {
        steps_left_ = settings_.warm_checked_iterations;
        residual = newton(problem, buffers_->blocks, r, settings_.warm_checked_iterations, stats);
        if (residual <= problem.tolerance && slips(problem, buffers_->blocks, r, *buffers_)) {
          warm_slips = true;
          buffers_->warm_answer = r;
        }
      }
    }
    if (residual <= problem.tolerance && !warm_slips) {
      ++stats.warm_started;
      stats.residual = std::max(stats.residual, residual);
      return;
    }
    r.setZero();
  }
  // 0b. A cold solve (no warm start): every contact sticking, W r = −q on every row at once (one
  //     factorization, whose analysis the relaxation's interior point then shares). Where that answer
  //     lies in the cones (a tower of planks, a stack of boxes standing), a few Newton steps finish it;
  //     it is taken only if it solves the relaxation too, i.e. is the relaxation's answer.
  if (!warm && !problem.convex && settings_.sticking_guess && sticking_guess(problem, r, stats)) {
    ++stats.sticking_guessed;
    residual = refine(problem, buffers_->blocks, r, natural_map_residual(problem, r), stats);
    stats.residual = std::max(stats.residual, residual);
    return;
  }
  if (problem.convex) {
    if (warm) r = *problem.start;
    residual = solve_stages(problem, r, warm, stats, settings_.max_newton_steps);
  } else {
    // 1. The convex relaxation: among Coulomb's solutions of a redundant problem it picks the one a
    //    static equilibrium gives, whenever one exists (velocities 0 where the relaxation's are, see
    //    the header), and its answer is Coulomb's wherever no pressed contact slips.
    FrictionalWorkspace::Newton& buffers = *buffers_;
    FrictionalProblem& relaxed = buffers.relaxed;
    relaxed = problem;  // the vectors' storage reused
    relaxed.convex = true;
    relaxed.start = nullptr;
    ++stats.relaxed;
    // The relaxation's answer is a static equilibrium, Coulomb's residual 0, whenever one exists. Where
    // the problem had a warm start (unsolved by it, or reached a slipping answer from it): Newton on the
    // relaxation from the slipping answer or the warm start, a few steps. Where they solve it, its
    // answer is exact (it slips: no static equilibrium exists, and the slipping answer is taken; or it
    // is Coulomb's answer), and no interior point is needed, neither to check a slip nor to start the
    // stages below from.
    double relaxed_residual = 0.0;
    bool slip_taken = false;
    bool relaxation_solved = false;
    if (warm && settings_.warm_relaxation) {
      r = warm_slips ? buffers_->warm_answer : problem.start == &r ? buffers_->warm_copy : *problem.start;
      relaxed_residual = warm_relaxation(relaxed, r, stats);
      relaxation_solved = relaxed_residual <= relaxed.tolerance;
      if (relaxation_solved) ++stats.warm_relaxed;
      else r.setZero();
    }
    // Where they do not and the warm start reached a slipping answer, an interior point to a loose
    // target: when its iterate is still far from Coulomb's (a pressed contact separating at μ‖u_t‖), no
    // static equilibrium exists and the slipping answer is taken without solving the relaxation to the
    // tolerance (about 10 steps of ~20, and no polish). Else the relaxation is solved in full, as for a
    // cold start.
    if (warm_slips && settings_.slip_check && !relaxation_solved) {
      ConeQpReport report;
      const double loose = kSlipCheckTarget * relaxed.tolerance;
      solve_cone_qp(relaxed, loose, settings_.interior_point_iterations, buffers.cone_qp, buffers.ldlt, r, report);
      stats.interior_point_steps += report.iterations;
      stats.interior_point_body_steps += report.body_space_steps;
      slip_taken = report.converged && natural_map_residual(problem, r) > kSlipCheckMargin * loose;
    }
    bool warm_answer_taken = slip_taken;
    if (slip_taken) {
      ++stats.slips_taken;
      r = buffers_->warm_answer;
      residual = natural_map_residual(problem, r);
    } else {
      if (!relaxation_solved) relaxed_residual = solve_stages(relaxed, r, false, stats, settings_.max_newton_steps);
      residual = natural_map_residual(problem, r);
      if (residual > problem.tolerance && warm_slips) {  // no static equilibrium: the warm start's answer
        if (relaxation_solved) ++stats.slips_taken;  // (counted as the loose check's are)
        r = buffers_->warm_answer;
        residual = natural_map_residual(problem, r);
        warm_answer_taken = residual <= problem.tolerance;
      }
    }
    // 2. Where a pressed contact slips, the relaxation separates it at μ‖u_t‖ instead. Newton on
    //    Coulomb's problem from its answer (fast near a solution), then Cadoux's fixed point: the
    //    relaxation again with q_n raised by s = μ‖u_t‖ of the last answer (a fixed point is a Coulomb
    //    solution), each answer again a start for Newton. One step here; more only after the stages (3)
    //    fail, since on most problems the stages finish sooner, and on the collapsing sphere pyramid the
    //    steps oscillate.
    buffers.diagonal = problem.w->diagonal();
    make_blocks(problem, buffers.diagonal, buffers.blocks);
    const std::vector<Block>& blocks = buffers.blocks;
    Vector &best = buffers.cold_best, &polished = buffers.polished, &u = buffers.velocity;
    best = r;
    double best_residual = residual;
    // At most `steps` fixed-point steps from the relaxation's answer `from` (which becomes the last one),
    // improving `best`; they end when kFixedPointStall steps have not halved the best residual of their
    // own iterates, or 2 kFixedPointStall steps have not beaten the best before them (`entry`). Returns
    // whether more steps may follow (none failed, solved the problem or stalled).
    const auto fixed_point = [&](Vector& from, std::uint64_t steps) {
      double own = std::numeric_limits<double>::infinity(), mark = own;  // their best, now and kFixedPointStall steps ago
      const double entry = best_residual;
      for (std::uint64_t k = 0; k < steps; ++k) {
        if (k > 0 && k % kFixedPointStall == 0) {
          if (own > 0.5 * mark || (k >= 2 * kFixedPointStall && own > entry)) return false;
          mark = own;
        }
        ++stats.fixed_point_steps;
        steps_left_ = settings_.polish_newton_iterations;
        polished = from;
        const double now = newton(problem, blocks, polished, settings_.polish_newton_iterations, stats);
        own = std::min(own, now);
        if (now < best_residual) {
          best_residual = now;
          best = polished;
        }
        if (best_residual <= problem.tolerance) return false;
        u.noalias() = problem.w->transpose() * from;  // = W r (symmetric), as a gather
        u += problem.q;
        relaxed.q = problem.q;
        for (const Block& block : blocks)
          if (block.size == 3) relaxed.q(block.first) += block.mu * std::hypot(u(block.first + 1), u(block.first + 2));
        if (solve_stages(relaxed, from, false, stats, settings_.max_newton_steps) > relaxed.tolerance) return false;
        const double relaxed_now = natural_map_residual(problem, from);
        own = std::min(own, relaxed_now);
        if (relaxed_now < best_residual) {
          best_residual = relaxed_now;
          best = from;
        }
      }
      return true;
    };
    Vector& relaxation = buffers.relaxation_answer;
    relaxation = r;
    buffers.relaxation_first = r;  // kept for the projection stage (5b): Cadoux's steps overwrite `relaxation`
    // Not on a warm-started problem above `fixed_point_rows` rows, where the steps after the stages (4) do
    // not follow either: on 79 large islands dumped from the frictional pile (500–3,700 rows) the step
    // was a quarter of their time, and the stages solved as many of them without it (18 of 79).
    const auto rows = static_cast<std::size_t>(problem.q.size());
    const bool first_fixed_point = !warm || rows <= settings_.fixed_point_rows;
    const bool more = best_residual > problem.tolerance && relaxed_residual <= relaxed.tolerance &&
                      settings_.fixed_point_iterations > 0 && first_fixed_point && fixed_point(relaxation, 1);
    r = best;
    residual = best_residual;
    // 3. Still not solved: the stages on Coulomb's problem from the best answer.
    //    On a problem that had a warm start (an island of a running scene), at most
    //    `warm_stage_newton_steps` there: the stages after this one, or the next step, go on. On a cold
    //    one that the projection stage (5b) would take next, at most `projection_stage_newton_steps`
    //    (none by default) first, the rest of `max_newton_steps` after the projection if it fails too: on
    //    the dropped sphere pyramids K = 20 (1,770 rows) these stages spent their 300 steps, 1.3–1.5 s,
    //    and then 50, for nothing before the projection solved them (at μ = 0.5 1.8 → 0.83 s for the
    //    whole solve, then 0.63 → 0.43 s, the same answer).
    const bool projection_follows = settings_.projection_iterations > 0 && !warm &&
                                    (rows > settings_.nonsmooth_rows || settings_.nonsmooth_sweeps == 0) &&
                                    rows <= settings_.projection_rows;
    std::uint64_t stage_steps = warm ? settings_.warm_stage_newton_steps : settings_.max_newton_steps;
    if (projection_follows) stage_steps = std::min(stage_steps, settings_.projection_stage_newton_steps);
    if (residual > problem.tolerance)
      residual = solve_stages(problem, r, true, stats, stage_steps,
                              !warm && rows <= settings_.coulomb_interior_point_rows);
    // 4. Still not solved, on a problem of at most `fixed_point_rows` rows: Cadoux's fixed point goes on
    //    from the relaxation's last answer. Of 135 island problems of the frictional pile that the stages
    //    left unsolved (dumped from a run), it solves 114.
    if (residual > problem.tolerance && more && rows <= settings_.fixed_point_rows) {
      best = r;
      best_residual = residual;
      fixed_point(relaxation, settings_.fixed_point_iterations - 1);
      r = best;
      residual = best_residual;
    }
    // 5. Still not solved, up to `nonsmooth_rows` rows: nonsmooth Gauss–Seidel sweeps from r = 0, then
    //    Newton from their iterate, whose answer is taken where it solves the problem or improves on the
    //    best.
    if (residual > problem.tolerance && settings_.nonsmooth_sweeps > 0 && rows <= settings_.nonsmooth_rows) {
      Vector& swept = buffers.sweep_r;
      swept.setZero(problem.q.size());
      double now = nonsmooth_gauss_seidel(problem, blocks, swept, residual, stats);
      if (now > problem.tolerance) {
        steps_left_ = kSweepNewtonSteps;
        now = newton(problem, blocks, swept, kSweepNewtonSteps, stats);
      }
      if (now < residual) {
        if (now <= problem.tolerance) ++stats.nonsmooth_solved;
        r = swept;
        residual = now;
      }
    }
    // 5b. Still not solved, a cold solve (no warm start) of up to `projection_rows` rows: projected
    //     fixed-point iterations from the relaxation's (first) answer, with Newton tried from their
    //     iterate as it nears a solution. A warm-started problem (an island of a running scene) does not
    //     get it: its next step goes on from its best answer, and on the frictional pile the stage ran 35
    //     times in 500 steps, solved none and nearly doubled the resolver's time.
    if (residual > problem.tolerance && projection_follows) {
      Vector& projected = buffers.projection_best;
      projected = buffers.relaxation_first;
      const double now = projection(problem, blocks, projected, residual, stats);
      if (now < residual) {
        if (now <= problem.tolerance) ++stats.projection_solved;
        r = projected;
        residual = now;
      }
    }
    // 5c. Still not solved there: the rest of the Newton stages' steps, from the best answer.
    if (residual > problem.tolerance && projection_follows && stage_steps < settings_.max_newton_steps)
      residual = solve_stages(problem, r, true, stats, settings_.max_newton_steps - stage_steps);
    // 6. A few more Newton steps. Near a solution they converge quadratically, so the answer is exact to
    //    rounding, not just to the tolerance, and does not depend on which stage found it (a slope turned
    //    about its normal gives the same slip to 1e-12; the interior point's answer on the pyramid of
    //    K = 50 at rest goes from 1.4e-10 to 5e-13). Not on a slipping warm answer taken: like every
    //    answer of the warm path, it is kept as Newton left it, within the tolerance (on the frictional
    //    heap these steps were 12% of the frictional solver's time).
    if (residual <= problem.tolerance && !warm_answer_taken) residual = refine(problem, blocks, r, residual, stats);
    // 7. Still not solved, on a small problem: one pressed contact released (release_one_contact).
    if (residual > problem.tolerance && blocks.size() <= settings_.release_max_contacts)
      residual = release_one_contact(problem, blocks, r, stats);
  }
  if (residual > problem.tolerance) ++stats.non_converged;
  stats.residual = std::max(stats.residual, residual);
}

// Nonsmooth Gauss–Seidel sweeps from r (M. Jean and J. J. Moreau's NSGS, Siconos's default solver):
// contact after contact, its own Coulomb problem solved exactly (contact_solve) with every other impulse
// held, u = W r + q kept up to date by the contact's columns of W. Not guaranteed to converge on Coulomb's
// nonconvex problem, but its iterates follow another path than Newton's: on the sphere pyramid K = 10
// dropped at μ = 0.5, or with one contact left out at μ = 0.7, it reaches 1e-14 in 2,000–4,000 sweeps
// where the Newton stages stall at 1e-2. The residual is checked every kSweepCheck sweeps (u recomputed
// there, so rounding does not accumulate); the stage ends at the tolerance, after
// `nonsmooth_sweeps`, when kSweepStall sweeps have not halved the best residual, or when 2 kSweepStall
// sweeps have not brought it below `entry` (the best residual the stages before reached). r becomes the
// best iterate; returns its residual.
double FrictionalSolver::nonsmooth_gauss_seidel(const FrictionalProblem& problem, const std::vector<Block>& blocks,
                                                Vector& r, double entry, FrictionalStats& stats) {
  const SparseMatrix& w = *problem.w;
  FrictionalWorkspace::Newton& buffers = *buffers_;
  std::vector<Eigen::Matrix3d>& block_w = buffers.block_w;
  block_w.resize(blocks.size());
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const Block& b = blocks[k];
    block_w[k].setZero();
    for (int c = 0; c < b.size; ++c)
      for (SparseMatrix::InnerIterator it(w, b.first + c); it; ++it)
        if (it.row() >= b.first && it.row() < b.first + b.size) block_w[k](it.row() - b.first, c) = it.value();
  }
  Vector &u = buffers.sweep_u, &best = buffers.sweep_best;
  double best_residual = natural_map_residual_in(problem, r, u);
  best = r;
  double mark = best_residual;  // the best residual kSweepStall sweeps ago
  std::uint64_t since_mark = 0;
  const double handoff = kSweepHandoff * problem.tolerance;
  for (std::uint64_t sweep = 1; sweep <= settings_.nonsmooth_sweeps && best_residual > handoff; ++sweep) {
    ++stats.nonsmooth_sweeps;
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      const Block& b = blocks[k];
      const Eigen::Index n = b.first;
      const Eigen::Matrix3d& a = block_w[k];
      if (!(a(0, 0) > 0.0)) continue;  // nothing movable behind the row
      Eigen::Vector3d before = Eigen::Vector3d::Zero(), after = Eigen::Vector3d::Zero();
      if (b.size == 3) {
        before = r.segment<3>(n);
        after = contact_solve(a, u.segment<3>(n) - a * before, b.mu, before);
      } else {
        before(0) = r(n);
        after(0) = before(0) - u(n) / a(0, 0);  // a joint row: u = 0
        if (b.role != RowRole::equality) after(0) = std::max(0.0, after(0));
      }
      const Eigen::Vector3d change = after - before;
      if (!change.allFinite()) continue;
      for (int c = 0; c < b.size; ++c) {
        if (change(c) == 0.0) continue;
        r(n + c) = after(c);
        for (SparseMatrix::InnerIterator it(w, n + c); it; ++it) u(it.row()) += it.value() * change(c);
      }
    }
    if (sweep % kSweepCheck != 0 && sweep != settings_.nonsmooth_sweeps) continue;
    if (const double now = natural_map_residual_in(problem, r, u); now < best_residual) {
      best_residual = now;
      best = r;
    }
    since_mark += kSweepCheck;
    if (since_mark >= kSweepStall) {
      if (best_residual > 0.5 * mark || (sweep >= 2 * kSweepStall && best_residual > entry)) break;
      mark = best_residual;
      since_mark = 0;
    }
  }
  r = best;
  return best_residual;
}

namespace {

// F(r) = u + μ‖u_t‖ e_n (De Saxcé's modified velocity at each frictional contact; u itself at the other
// rows) with u = W r + q, into u and f.
void modified_velocity(const FrictionalProblem& problem, const std::vector<Block>& blocks, const BlockedW& w,
                       const Vector& r, Vector& u, Vector& f) {
  w.multiply(r, u);
  u += problem.q;
  f = u;
  for (const Block& b : blocks)
    if (b.size == 3) f(b.first) += b.mu * std::hypot(u(b.first + 1), u(b.first + 2));
}

// y ← P_K(y), block by block: a frictional contact on its cone, a frictionless one on r ≥ 0, a joint row
// left free.
void project_on_blocks(const std::vector<Block>& blocks, Vector& y) {
  for (const Block& b : blocks) {
    if (b.size == 3)
      project_on_cone(b.mu, y(b.first), y(b.first + 1), y(b.first + 2));
    else if (b.role != RowRole::equality)
      y(b.first) = std::max(0.0, y(b.first));
  }
}

}  // namespace

// The projected fixed point of Coulomb's problem written as a variational inequality (find r ∈ K with
// F(r)·(s − r) ≥ 0 for every s ∈ K, F(r) = u + μ‖u_t‖ e_n, De Saxcé's modified velocity, whose solutions
// are exactly the problem's): r ← P_K(r − ρ D F(r)), D the contacts' weights 1/W_nn (one per contact, so
// P_K is still the projection in D's metric), one product with W per iteration. Acary, Brémond and Huber
// (2018) list it (VI_FPP) among the slow but robust methods. It converges where Newton, the sweeps and
// Cadoux's fixed point do not: on the sphere pyramid K = 20 dropped at μ = 0.5 it reaches 3e-3 in 8,256
// iterations from the relaxation's answer, and Newton finishes from there. The step: kProjectionStep.
// Ends at the tolerance (through Newton), after `projection_iterations`, or when it stalls
// (kProjectionStall, kProjectionEntry: `entry` is the best residual before it); r becomes the best
// iterate met (the projection's or Newton's), whose residual is returned.
double FrictionalSolver::projection(const FrictionalProblem& problem, const std::vector<Block>& blocks, Vector& r,
                                    double entry, FrictionalStats& stats) {
  FrictionalWorkspace::Newton& buffers = *buffers_;
  Vector &x = buffers.projection_r, &u = buffers.projection_u, &f = buffers.projection_f;
  Vector &weight = buffers.projection_weight, &power = buffers.projection_power, &image = buffers.projection_image;
  Vector& polished = buffers.polished;
  BlockedW& blocked = buffers.projection_w;
  blocked.assign(*problem.w, blocks);
  const Eigen::Index m = problem.q.size();
  weight.resize(m);
  for (const Block& b : blocks) weight.segment(b.first, b.size).setConstant(b.rho_n);
  // λ: the power method on D^½ W D^½ from the vector of ones.
  double lambda = 0.0;
  power.setOnes(m);
  power /= power.norm();
  for (int k = 0; k < kPowerIterations; ++k) {
    f = power.cwiseProduct(weight.cwiseSqrt());  // f: scratch until the iteration sets it
    blocked.multiply(f, image);
    image.array() *= weight.array().sqrt();
    lambda = image.norm();
    if (!(lambda > 0.0) || !std::isfinite(lambda)) return natural_map_residual(problem, r);
    power = image / lambda;
  }
  double rho = kProjectionStep / lambda;
  x = r;
  project_on_blocks(blocks, x);
  modified_velocity(problem, blocks, blocked, x, u, f);
  double best_residual = natural_map_residual(problem, x, u);
  r = x;
  double mark = best_residual;  // the best residual kProjectionStall iterations ago
  double next_newton = kProjectionNewton * problem.tolerance;
  for (std::uint64_t k = 1; k <= settings_.projection_iterations && best_residual > problem.tolerance; ++k) {
    ++stats.projection_iterations;
    x -= rho * weight.cwiseProduct(f);
    project_on_blocks(blocks, x);
    modified_velocity(problem, blocks, blocked, x, u, f);
    if (k % kProjectionCheck != 0) continue;
    const double now = natural_map_residual(problem, x, u);
    if (!(now <= kProjectionDiverged * best_residual)) {  // diverging (or not finite): a shorter step
      rho *= 0.5;
      x = r;
      modified_velocity(problem, blocks, blocked, x, u, f);
      continue;
    }
    if (now < best_residual) {
      best_residual = now;
      r = x;
    }
    if (best_residual <= next_newton) {  // Newton from the iterate: quadratic near a solution
      next_newton = kProjectionNewtonFactor * best_residual;
      polished = x;
      steps_left_ = kSweepNewtonSteps;
      const double polished_residual = newton(problem, blocks, polished, kSweepNewtonSteps, stats);
      if (polished_residual < best_residual) {
        best_residual = polished_residual;
        r = polished;
      }
    }
    if (k % kProjectionEntry == 0 && best_residual > kProjectionEntryFactor * entry) break;
    if (k % kProjectionStall == 0) {
      if (best_residual > 0.5 * mark) break;
      mark = best_residual;
    }
  }
  return best_residual;
}

// Newton steps per release try at most (release_one_contact): a contact rightly released leaves a
// problem Newton solves in a few steps from the iterate; a wrong one is abandoned quickly.
constexpr std::uint64_t kReleaseNewtonSteps = 30;

// From the best iterate r of a problem the stages left unsolved: the pressed contacts that separate
// there (r_n > 0 but u_n > 0), fastest first, each in turn forced open (its q_n raised by 10 (‖q‖ + 1),
// so that it separates whatever the others do) and the problem solved again from r with that contact's
// impulse zeroed, by a solver of the same settings without this stage. A try is kept if it solves the
// problem itself (the released contact's u_n ≥ 0 then, its r = 0). Returns r's residual. The tries run in
// their own buffers (an allocation per try: small problems, after the stages have failed).
double FrictionalSolver::release_one_contact(const FrictionalProblem& problem, const std::vector<Block>& blocks,
                                             Vector& r, FrictionalStats& stats) {
  const Vector u = problem.w->transpose() * r + problem.q;  // W r + q (W symmetric), as a gather
  std::vector<std::pair<double, std::size_t>> candidates;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const Block& b = blocks[k];
    if (b.role == RowRole::normal && r(b.first) > 0.0 && u(b.first) > 0.0) candidates.emplace_back(-u(b.first), k);
  }
  std::sort(candidates.begin(), candidates.end());
  if (candidates.size() > settings_.release_tries) candidates.resize(settings_.release_tries);
  FrictionalSettings inner_settings = settings_;
  inner_settings.release_max_contacts = 0;
  inner_settings.max_newton_steps = kReleaseNewtonSteps;
  const double raise = 10.0 * (problem.q.norm() + 1.0);
  for (const auto& [speed, k] : candidates) {
    const Block& b = blocks[k];
    FrictionalWorkspace workspace;
    FrictionalProblem released = problem;
    released.q(b.first) += raise;
    released.workspace = &workspace;
    Vector start = r;
    start.segment(b.first, b.size).setZero();
    released.start = &start;
    FrictionalSolver inner(inner_settings);
    FrictionalStats inner_stats;
    Vector answer;
    inner.solve(released, inner_stats, answer);
    inner_stats.problems = 0;  // one problem, counted by the caller
    inner_stats.warm_started = inner_stats.non_converged = 0;
    inner_stats.residual = 0.0;
    add(stats, inner_stats);
    if (const double residual = natural_map_residual(problem, answer); residual <= problem.tolerance) {
      ++stats.releases;
      r = answer;
      return residual;
    }
  }
  return natural_map_residual(problem, r);
}

// kWarmRelaxationSteps Newton steps on the relaxation `relaxed` from r (a warm start, or the slipping
// answer Newton reached from it); returns the relaxation's residual at the best iterate, left in r.
double FrictionalSolver::warm_relaxation(const FrictionalProblem& relaxed, Vector& r, FrictionalStats& stats) {
  FrictionalWorkspace::Newton& buffers = *buffers_;
  buffers.stage_diagonal = relaxed.w->diagonal();
  make_blocks(relaxed, buffers.stage_diagonal, buffers.stage_blocks);
  steps_left_ = kWarmRelaxationSteps;
  return newton(relaxed, buffers.stage_blocks, r, kWarmRelaxationSteps, stats);
}

// A few Newton steps past the tolerance from an answer r within it (`residual`): near a solution they
// converge quadratically, so the answer is exact to rounding. Returns the new residual.
double FrictionalSolver::refine(const FrictionalProblem& problem, const std::vector<Block>& blocks, Vector& r,
                                double residual, FrictionalStats& stats) {
  if (residual == 0.0) return residual;
  FrictionalProblem& exact = buffers_->exact;
  exact = problem;
  exact.tolerance = 0.0;
  steps_left_ = settings_.refinement_steps;
  return newton(exact, blocks, r, settings_.refinement_steps, stats);
}

// Every contact sticking (and every frictionless contact and joint row pressed): one Newton step from
// r = 0 with every block linearized on its active piece, i.e. (W + shift I) r = −q, the proximal
// solution nearest 0. Its answer is a static equilibrium if it lies in the cones; then at most
// kGuessNewtonSteps Newton steps on Coulomb's problem, and r is kept (true) only if it solves both
// Coulomb's problem and the relaxation to the tolerance: the relaxation's velocities are unique, so it
// is the relaxation's answer, the one the cold path would give. Else r = 0 (false).
bool FrictionalSolver::sticking_guess(const FrictionalProblem& problem, Vector& r, FrictionalStats& stats) {
  FrictionalWorkspace::Newton& buffers = *buffers_;
  const Eigen::Index m = problem.q.size();
  if (m == 0) return false;
  buffers.diagonal = problem.w->diagonal();
  make_blocks(problem, buffers.diagonal, buffers.blocks);
  const std::vector<Block>& blocks = buffers.blocks;
  buffers.lin.assign(blocks.size(), Linearization{});
  for (Linearization& l : buffers.lin) l.piece = Piece::active;
  buffers.f.resize(m);
  for (const Block& b : blocks)  // F on the active piece at r = 0: ρ u = ρ q
    for (int j = 0; j < b.size; ++j) buffers.f(b.first + j) = (j == 0 ? b.rho_n : b.rho_t) * problem.q(b.first + j);
  const double shift = settings_.regularization * buffers.diagonal.maxCoeff();
  ++stats.newton_steps;
  if (!symmetric_direction(blocks, buffers.lin, *problem.w, shift, buffers.f, buffers, buffers.d)) {
    r.setZero(m);
    return false;
  }
  r = buffers.d;
  // In the cones, up to rounding (Newton's steps take it the rest of the way).
  double largest = 0.0;
  for (const Block& b : blocks)
    if (b.role != RowRole::equality) largest = std::max(largest, r(b.first));
  const double slack = kGuessConeSlack * largest;
  const bool in_cones = std::all_of(blocks.begin(), blocks.end(), [&](const Block& b) {
    if (b.role == RowRole::equality) return true;
    if (r(b.first) < -slack) return false;
    return b.size == 1 || std::hypot(r(b.first + 1), r(b.first + 2)) <= b.mu * r(b.first) + slack;
  });
  if (in_cones) {
    steps_left_ = kGuessNewtonSteps;
    if (newton(problem, blocks, r, kGuessNewtonSteps, stats) <= problem.tolerance) {
      FrictionalProblem& relaxed = buffers.relaxed;
      relaxed = problem;
      relaxed.convex = true;
      relaxed.start = nullptr;
      if (natural_map_residual(relaxed, r) <= relaxed.tolerance) return true;
    }
  }
  r.setZero(m);
  return false;
}

// The stages (file comment) on `problem` from r, which they overwrite with the best iterate met; returns
// its natural-map residual.
double FrictionalSolver::solve_stages(const FrictionalProblem& problem, Vector& r, bool warm, FrictionalStats& stats,
                                      std::uint64_t max_steps, bool interior_point) {
  const SparseMatrix& w = *problem.w;
  FrictionalWorkspace::Newton& buffers = *buffers_;
  const Vector& diagonal = buffers.stage_diagonal = w.diagonal();
  make_blocks(problem, diagonal, buffers.stage_blocks);
  const std::vector<Block>& blocks = buffers.stage_blocks;
  steps_left_ = max_steps;

  // 1. Newton on the problem itself: enough whenever W is well conditioned on the contacts that end up
  //    pressed, or near a solution.
  double residual = natural_map_residual(problem, r);
  bool polish = false;  // Newton only polishes the interior-point answer
  if (problem.convex && !warm) {
    // The relaxation is a convex cone program: an interior-point method solves it whatever the
    // redundancy, and Newton polishes its answer.
    ConeQpReport report;
    solve_cone_qp(problem, problem.tolerance, settings_.interior_point_iterations, buffers.cone_qp, buffers.ldlt, r,
                  report);
    stats.interior_point_steps += report.iterations;
    stats.interior_point_body_steps += report.body_space_steps;
    residual = natural_map_residual(problem, r);
    warm = polish = true;
  }
  // Where the interior point on Coulomb's problem follows (1b), Newton's first attempt is short: on the
  // problems that interior point solves it did not converge in its 60 steps either.
  const bool coulomb_interior_point =
      interior_point && !problem.convex && settings_.coulomb_interior_point_iterations > 0;
  if (!likely_redundant(problem) || warm)
    residual = newton(problem, blocks, r,
                      polish                   ? settings_.polish_newton_iterations
                      : coulomb_interior_point ? settings_.coulomb_interior_point_newton_steps
                                               : settings_.newton_iterations,
                      stats);

  // 1b. Coulomb's problem by the interior point (cone_qp.hpp), where the caller allows it: where it
  //     converges, in 10–35 steps what the proximal rounds below take hundreds of Newton steps for
  //     (the dropped pyramid K = 10 at μ = 0.5, a stack of 10 boxes); where it does not, the rounds go
  //     on from the better of its best answer and Newton's.
  if (coulomb_interior_point && residual > problem.tolerance) {
    ConeQpReport report;
    Vector& answer = buffers.coulomb_answer;
    solve_cone_qp(problem, problem.tolerance, settings_.coulomb_interior_point_iterations, buffers.cone_qp,
                  buffers.ldlt, answer, report);
    stats.coulomb_interior_point_steps += report.iterations;
    if (report.iterations > 0) {
      if (const double now = natural_map_residual(problem, answer); now < residual) {
        residual = now;
        r = answer;
        if (now <= problem.tolerance) ++stats.coulomb_interior_point_solved;
      }
    }
  }

  // 2. Redundant contacts or a stalled Newton: proximal Newton steps (fast near a solution, and
  //    bounded along W's null space), and if they stall, a round of projected Gauss–Seidel sweeps
  //    (robust, slow; it brings the iterate nearer a solution) before the next try.
  Vector& best = buffers.stage_best;
  best = r;
  double best_residual = residual;
  for (std::uint64_t round = 0;
       round < settings_.hybrid_rounds && best_residual > problem.tolerance && steps_left_ > 0; ++round) {
    r = best;
    proximal_newton(problem, blocks, r, stats);
    if (const double now = natural_map_residual(problem, r); now < best_residual) {
      best_residual = now;
      best = r;
    }
    if (best_residual <= problem.tolerance) break;
    ++stats.fallbacks;
    r = best;
    for (std::uint64_t sweep = 0; sweep < settings_.sweeps_per_round; ++sweep) {
      gauss_seidel_sweep(blocks, w, problem.q, diagonal, r);
      ++stats.fallback_sweeps;
    }
    if (const double now = natural_map_residual(problem, r); now < best_residual) {
      best_residual = now;
      best = r;
    }
  }
  r = best;
  return best_residual;
}

}  // namespace impetus::ledas
