#pragma once
/// \file
/// Exact solution of one island's frictional contact problem in its local form (docs/conventions.md,
/// "Friction"; the form of the Frictional Contact Library, fclib):
///
///   u = W r + q,   W = G M⁻¹ Gᵀ (eq. 7 with three rows per frictional contact: normal, t1, t2),
///
/// and per frictional contact with coefficient μ (r = (r_n, r_t), u = (u_n, u_t), u_n measured from the
/// row's target):  r_n ≥ 0, u_n ≥ 0, r_n u_n = 0;  ‖r_t‖ ≤ μ r_n;  and either u_t = 0 (stick) or
/// r_t = −μ r_n u_t/‖u_t‖ (slide). A frictionless contact is one row of the same complementarity as
/// the frictionless solver's; a joint row is an equality u = 0 with r free. Knows nothing of bodies:
/// W and q come in, r comes out, so it is tested (and later fed fclib's problems) directly.
///
/// Method (resolution/ledas/README.md, "Friction"), in stages:
///  0. a warm start, if given: taken if it solves the problem, else polished by a few Newton steps, then
///     by more whose answer is taken if it sticks, or if it slips and the relaxation (1) has no static
///     equilibrium; that relaxation, and the one the cold path starts from after a failed warm start,
///     first by Newton from the slipping answer or the warm start (a few steps), by the interior point
///     only where those do not solve it;
///  0b. without a warm start, every contact sticking (`sticking_guess`): W r = −q on every row, taken
///     if it lies in the cones and, after a few Newton steps, solves both Coulomb's problem and the
///     relaxation (so it is the relaxation's answer);
///  1. the convex relaxation (`convex`), solved by an interior-point method (cone_qp.hpp) and polished by
///     Newton on its natural map: a static equilibrium is its answer whenever one exists, and where its
///     answer has no pressed contact slipping it is Coulomb's answer;
///  2. else Newton on Coulomb's problem from it, one step of Cadoux's fixed point (the relaxation with q_n
///     raised by μ‖u_t‖; not on a warm-started problem above `fixed_point_rows`), and the Newton stages
///     below (on a cold problem the projection below would take next, only
///     `projection_stage_newton_steps` of them (none by default) before it, the rest after it if it
///     fails); on a cold problem of at most `coulomb_interior_point_rows` rows, where the Newton
///     stages' first attempt fails, the interior point on Coulomb's problem itself (De Saxcé's shift
///     μ‖u_t‖ at each iterate, its derivative in the step's matrix; cone_qp.hpp) before their proximal
///     rounds;
///  3. still unsolved: more of Cadoux's steps (`fixed_point_iterations`, on problems of at most
///     `fixed_point_rows`), then nonsmooth Gauss–Seidel sweeps from r = 0 (each contact's own problem
///     solved exactly in turn; at most `nonsmooth_rows`) and Newton from their iterate, or on larger
///     problems solved cold (up to `projection_rows`) a projected fixed point r ← P_K(r − ρ D F(r)) on
///     Coulomb's variational inequality from the relaxation's answer, with Newton from its iterates;
///  4. a cold answer within the tolerance gets a few Newton steps past it (exact to rounding). The Newton
///     stages: a semismooth Newton method on the Alart–Curnier function
///   F_n = r_n − max(0, z_n),  z_n = r_n − ρ_n u_n,
///   F_t = r_t − P_D(μ max(0, z_n)) (z_t),  z_t = r_t − ρ_t u_t,  P_D(R) the projection on the disk ‖·‖ ≤ R,
/// whose zeros are exactly the solutions above (ρ > 0 per contact; the cone is round and ρ_t is one
/// number per contact, so the iteration does not depend on the tangent basis). Each step solves the
/// generalized Jacobian's system by LU (dense up to `dense_limit` rows, sparse above, W shifted by
/// `regularization` × max W_ii so redundant contact sets stay solvable; above `dense_limit`, when no block
/// slides, by symmetric LDLᵀ on the active rows instead), with an Armijo line search on
/// ½‖F‖². The error is fclib's natural-map residual ‖r − P_K(r − (u + μ‖u_t‖ e_n))‖ (ρ = 1, no scaling).
/// Redundant contacts (more rows than `dofs`: W singular, the impulses not unique) or a stalled Newton:
/// proximal points take over — the same Newton on u = (W + εI) r + q − ε r̄, r̄ moved to each solution, ε
/// divided by 10 after a solved subproblem and multiplied by 10 after an unsolved one — alternating with
/// rounds of projected Gauss–Seidel sweeps on the cones when they stall. At most `max_newton_steps` Newton
/// steps per problem; whatever happens, the iterate with the smallest residual is returned and a failure
/// to reach the tolerance is counted, never hidden.

#include "impetus/modules/contact_problem.hpp"
#include "impetus/resolution/ledas/island_solver.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace impetus::ledas {

struct BodySpace;  // island_solver.hpp

/// W's factored form G M⁻¹ Gᵀ over a problem's rows (BodySpace), handed out on first use: only the
/// interior point reads it, and most problems (a warm start that solves) never get there.
class BodySpaceSource {
 public:
  virtual const BodySpace& body_space() = 0;

 protected:
  ~BodySpaceSource() = default;
};

/// What a row of a frictional problem is.
enum class RowRole : std::uint8_t {
  equality,  ///< a joint row: u = 0, r free
  normal,    ///< a contact's normal row; with μ > 0 its two tangent rows follow it
  tangent    ///< one of the two tangent rows after a frictional normal row
};

/// Buffers a solve works in. A caller that solves problems of one size again and again (an island, step
/// after step) keeps one per problem and hands it in (FrictionalProblem::workspace): a problem its warm
/// start solves then allocates nothing.
struct FrictionalWorkspace {
  FrictionalWorkspace();
  ~FrictionalWorkspace();
  FrictionalWorkspace(FrictionalWorkspace&&) noexcept;
  FrictionalWorkspace& operator=(FrictionalWorkspace&&) noexcept;

  Vector u;  ///< u = W r + q of the natural-map residual
  struct Newton;  ///< the Newton steps' buffers (frictional_solver.cpp)
  std::unique_ptr<Newton> newton;
  /// Forgets every analysis of a pattern (orderings, symbolic factorizations) while keeping the
  /// storage: the next solve analyses afresh, as a solve with a new workspace would, in memory already
  /// held.
  void forget_analyses();
};

/// One island's frictional contact problem.
struct FrictionalProblem {
  const SparseMatrix* w = nullptr;  ///< W (m × m), symmetric positive semi-definite, both triangles stored
  Vector q;                         ///< free velocities (m/s), targets already subtracted: u = W r + q
  std::vector<RowRole> role;        ///< per row
  std::vector<double> mu;           ///< per row: a normal row's μ (0: frictionless, no tangent rows follow)
  double tolerance = 1e-12;         ///< natural-map residual to reach (absolute)
  /// Degrees of freedom behind W (6 per movable body), 0 if unknown. More rows than that: W is singular,
  /// and the solver starts with its proximal stage.
  std::size_t dofs = 0;
  /// Optional warm start (size m), e.g. the last step's impulses: taken if it solves the problem, else
  /// polished by a few Newton steps; if those fail, the solve starts cold (from the convex relaxation).
  const Vector* start = nullptr;
  /// Solve the convex relaxation instead (Anitescu's cone complementarity: r ∈ K, u ∈ K*, rᵀu = 0, with
  /// K* = {u_n ≥ μ‖u_t‖}; a slipping contact separates at μ‖u_t‖). Its velocities are unique, and a
  /// static equilibrium (u = 0 with r in the cones), when one exists, is its answer.
  bool convex = false;
  FrictionalWorkspace* workspace = nullptr;  ///< buffers to solve in (null: the solve's own)
  /// W's factored form G M⁻¹ Gᵀ over the same rows, optional: with it the interior point of a problem
  /// with more rows than body coordinates solves its Newton systems in body space (cone_qp.hpp).
  BodySpaceSource* body_space = nullptr;
};

/// How frictional problems are solved (configuration).
struct FrictionalSettings {
  std::size_t dense_limit = 96;          ///< Jacobians of at most this many rows are factorized dense
  std::uint64_t newton_iterations = 60;  ///< Newton steps of the first attempt
  /// Newton steps per problem at most, over all stages: bounds the work of a problem the method cannot
  /// solve (then the best iterate is returned and counted in non_converged).
  std::uint64_t max_newton_steps = 300;
  /// The same for the Newton stages on Coulomb's problem after the relaxation (stage 2 of the file
  /// comment), on a problem that had a warm start: an island of a running scene, whose later stages and
  /// next step go on from the best answer. On the frictional pile, 187 of 287 such problems were solved
  /// there, 185 of them within 200 steps; the 100 left unsolved spent all 300 and 75% of the stage's
  /// time. 100 steps cost accuracy over a long run (resolution/ledas/README.md, "Friction").
  std::uint64_t warm_stage_newton_steps = 200;
  /// The same on a cold problem (no warm start) that the projection stage would take next (below):
  /// the rest of `max_newton_steps` runs after that stage if it fails too. On the dropped sphere
  /// pyramids K = 20 at μ = 0.5 and 0.2, the stages spent their 300 steps (1.3–1.5 s) and failed, and
  /// the projection solved them from the relaxation's answer as before: 1.8 → 0.83 s and 2.6 → 1.3 s.
  /// 50 steps failed there too; no problem of the benchmarks or of the frictional pile's first 500 steps
  /// that reaches this point is solved by them, so none (resolution/ledas/README.md, "Friction").
  std::uint64_t projection_stage_newton_steps = 0;
  std::uint64_t interior_point_iterations = 60;  ///< interior-point steps on the convex relaxation at most
  /// Where Newton's first attempt on Coulomb's problem (after the relaxation and Cadoux's step) fails on
  /// a cold problem: interior-point steps on Coulomb's problem itself (cone_qp.hpp), at most this many,
  /// ended early when 16 do not halve the residual; the proximal rounds go on from the best answer if
  /// they fail. 0: none.
  std::uint64_t coulomb_interior_point_iterations = 60;
  /// ... on problems of at most this many rows. On the dropped sphere pyramids K = 20 (1,770 rows) it
  /// failed (24–26 steps of ~16 ms, KLU with partial pivoting), and on the frictional pile's warm-started
  /// islands it solved 10 of some 400 problems.
  std::size_t coulomb_interior_point_rows = 1000;
  /// Newton's first attempt on such a problem, before the interior point: a few steps (60 otherwise).
  /// On `bench_fclib`'s problems none that Newton solves there needs more than 8; on the dropped pyramid
  /// K = 10 at μ = 0.5 the other 52 failed steps were 40% of the solve.
  std::uint64_t coulomb_interior_point_newton_steps = 8;
  /// Cadoux's fixed-point steps (relaxations) at most: the first before the Newton stages (not on a
  /// warm-started problem above `fixed_point_rows`), the others after them if they fail (up to
  /// `fixed_point_rows`), ended when 3 steps do not halve their residual.
  std::uint64_t fixed_point_iterations = 30;
  std::uint64_t polish_newton_iterations = 8;   ///< Newton steps on Coulomb's problem from each of them
  std::uint64_t warm_newton_iterations = 2;     ///< Newton steps from a warm start that does not solve at once
  /// Newton steps more when those do not solve it: a sticking answer is taken, a slipping one only if
  /// the convex relaxation has no static equilibrium (else the relaxation's answer is).
  std::uint64_t warm_checked_iterations = 28;
  /// Where those reach a slipping answer: check first with an interior point to 1e4 × the tolerance
  /// whether the relaxation's iterate slips too (Coulomb's residual above 1e3 × that target: no static
  /// equilibrium exists), and if so take the answer without solving the relaxation to the tolerance.
  bool slip_check = true;
  /// Where a warm start does not solve the problem (or reaches a slipping answer): first at most 12
  /// Newton steps on the relaxation from the slipping answer or the warm start; where they solve it, its
  /// answer decides the slip exactly and starts the cold path, and no interior point runs for it.
  bool warm_relaxation = true;
  std::uint64_t refinement_steps = 3;           ///< Newton steps past the tolerance on a cold answer
  /// A cold problem (no warm start) is first tried with every contact sticking: W r = −q on every row,
  /// one factorization, and if that answer lies in the cones, 3 Newton steps; it is taken only if it
  /// solves the convex relaxation too. It solves a standing tower of planks or stack of boxes at once;
  /// on a dropped sphere pyramid it pulls or leaves the cones and costs one factorization.
  bool sticking_guess = true;
  /// Where every stage before leaves Coulomb's problem unsolved: nonsmooth Gauss–Seidel sweeps (each
  /// contact's own problem solved exactly in turn) from r = 0, at most this many, ended early when 128
  /// sweeps do not halve the residual or 256 do not beat the stages; then Newton from their iterate. 0: none.
  std::uint64_t nonsmooth_sweeps = 4096;
  /// Cadoux's fixed point goes beyond its first step on problems of at most this many rows: above, each
  /// step's interior point costs tens to hundreds of ms, and on the frictional pile's islands of
  /// 400–2,300 rows it solved 2 of the 15 problems it was tried on, against 95 of 110 below.
  std::size_t fixed_point_rows = 400;
  /// The nonsmooth sweeps run on problems of at most this many rows (a sweep of 2,000 rows costs ~0.5 ms).
  std::size_t nonsmooth_rows = 1000;
  /// Where the sweeps do not run (above `nonsmooth_rows`, or switched off) and the stages leave a cold
  /// problem (no warm start) unsolved: projected fixed-point iterations on Coulomb's variational
  /// inequality from the relaxation's answer, at most this many (one product with W each), ended early
  /// when 16,384 do not halve the residual or 4,096 do not come within 10× of the stages' best; Newton
  /// is tried from their iterate as it nears a solution. 0: none.
  std::uint64_t projection_iterations = 131072;
  /// The projection stage runs on problems of at most this many rows (an iteration of 1,770 rows, the
  /// sphere pyramid K = 20, costs ~15 µs).
  std::size_t projection_rows = 4000;
  /// A problem of at most this many contacts that the stages leave unsolved is tried with one contact
  /// released: a pressed contact that separates at the best iterate (r_n > 0, u_n > 0) may belong open,
  /// where Newton, having pressed every contact, stalls (a box's four points on the ground, one of them
  /// leaving). Each try solves the problem with that contact forced open from the best iterate and is
  /// kept if it solves the problem itself. 0: never.
  std::size_t release_max_contacts = 8;
  std::uint64_t release_tries = 3;  ///< contacts tried, those separating fastest first
  std::uint64_t hybrid_rounds = 40;      ///< rounds of proximal Newton then Gauss–Seidel sweeps, at most
  std::uint64_t sweeps_per_round = 20;   ///< projected Gauss–Seidel sweeps per round
  double regularization = 1e-10;         ///< W's diagonal shift in the Jacobian, × max W_ii
  double proximal = 1e-3;                ///< the proximal stage's first ε, × max W_ii
  std::uint64_t proximal_iterations = 40; ///< proximal points per round at most
  /// Each solved proximal point p moves r̄ to r̄ + ω (p − r̄) (1: to p), unless p solves the problem or that
  /// point's residual is more than twice p's. ω in (0, 2): the range where the relaxed proximal point
  /// method converges on monotone problems (Eckstein and Bertsekas). On the frictional pile's first 500
  /// steps 1.5 left 65 problems unconverged of ~34,100 instead of 75, the worst at 1.4e-4 instead of 9.4e-3.
  double proximal_relaxation = 1.5;
  /// Newton steps per proximal point: near a solution Newton converges in a few; more means it is not
  /// near one yet, and Gauss–Seidel sweeps take over again.
  std::uint64_t proximal_newton_iterations = 10;
};

/// What the solver did, accumulated over calls (reset by the caller).
struct FrictionalStats {
  std::uint64_t problems = 0;          ///< problems solved
  std::uint64_t warm_started = 0;      ///< problems solved from their warm start (`start`)
  std::uint64_t sticking_guessed = 0;  ///< cold problems solved by the sticking guess (sticking_guess)
  std::uint64_t relaxed = 0;           ///< Coulomb problems started from their convex relaxation
  /// of those, warm-started ones whose relaxation Newton solved from the warm start (no interior point)
  std::uint64_t warm_relaxed = 0;
  /// slipping warm answers taken where Newton's relaxation or the loose check (slip_check) showed that no
  /// static equilibrium exists
  std::uint64_t slips_taken = 0;
  std::uint64_t releases = 0;          ///< problems solved with one contact released (release_max_contacts)
  std::uint64_t fixed_point_steps = 0; ///< Cadoux's fixed-point steps
  std::uint64_t newton_steps = 0;      ///< Newton steps (one factorization each, but newton_reused)
  std::uint64_t newton_reused = 0;     ///< Newton steps that reused the step before's factorization (same matrix)
  std::uint64_t interior_point_steps = 0;  ///< interior-point steps on relaxations (one factorization each)
  /// interior-point steps on Coulomb's problem itself (FrictionalSettings::coulomb_interior_point_iterations)
  std::uint64_t coulomb_interior_point_steps = 0;
  std::uint64_t coulomb_interior_point_solved = 0;  ///< problems those steps solved
  /// of those, steps whose Newton system was solved in body space (FrictionalProblem::body_space)
  std::uint64_t interior_point_body_steps = 0;
  std::uint64_t proximal = 0;          ///< problems that needed the proximal stage (redundant contacts)
  std::uint64_t proximal_steps = 0;    ///< its proximal points (a Newton solve each)
  std::uint64_t nonsmooth_sweeps = 0;  ///< nonsmooth Gauss–Seidel sweeps (FrictionalSettings::nonsmooth_sweeps)
  std::uint64_t nonsmooth_solved = 0;  ///< problems those sweeps (and Newton from them) solved
  std::uint64_t projection_iterations = 0;  ///< projected fixed-point iterations (FrictionalSettings::projection_iterations)
  std::uint64_t projection_solved = 0;      ///< problems that stage (and Newton from its iterates) solved
  std::uint64_t fallbacks = 0;         ///< problems where the projected Gauss–Seidel fallback ran
  std::uint64_t fallback_sweeps = 0;   ///< its sweeps
  std::uint64_t non_converged = 0;     ///< problems left above the tolerance (best iterate returned)
  std::uint64_t nan_caught = 0;        ///< non-finite steps rejected
  double residual = 0.0;               ///< largest natural-map residual returned
};

/// Adds the counts of `part` to `into` (the residual: the larger).
void add(FrictionalStats& into, const FrictionalStats& part);

/// The natural-map residual of `r` (fclib's error without its scaling): the 2-norm over rows of
/// r − P_K(r − (u + μ‖u_t‖ e_n)) for frictional contacts, r − max(0, r − u) for frictionless ones and u
/// for joint rows, with u = W r + q.
double natural_map_residual(const FrictionalProblem& problem, const Vector& r);
/// The same, with r's velocities u = W r + q given (a caller that has them saves the product with W).
double natural_map_residual(const FrictionalProblem& problem, const Vector& r, const Vector& u);

/// Projects y = (y_n, y_t1, y_t2) on the cone ‖y_t‖ ≤ μ y_n (in place).
void project_on_cone(double mu, double& yn, double& yt1, double& yt2);

/// Solves frictional problems (see the file comment). Not thread-safe; one per resolver.
class FrictionalSolver {
 public:
  explicit FrictionalSolver(FrictionalSettings settings = {}) : settings_(settings) {}

  /// Returns r (m): the iterate with the smallest natural-map residual, which is ≤ problem.tolerance
  /// unless counted in stats.non_converged.
  Vector solve(const FrictionalProblem& problem, FrictionalStats& stats);
  /// The same into `r` (its storage reused: with the problem's workspace, a problem its warm start solves
  /// is solved without allocating). `r` may be the warm start (`*problem.start`) itself.
  void solve(const FrictionalProblem& problem, FrictionalStats& stats, Vector& r);

  const FrictionalSettings& settings() const { return settings_; }
  /// The workspace of problems solved one by one (solve_local_problem), kept between them for its
  /// storage only: each of those solves forgets its analyses first.
  FrictionalWorkspace& local_workspace() { return local_workspace_; }

  struct Block;  // one contact's rows (frictional_solver.cpp)

 private:
  /// `interior_point`: Coulomb's problem may try the interior point after Newton (cold problems of at
  /// most `coulomb_interior_point_rows` rows).
  double solve_stages(const FrictionalProblem& problem, Vector& r, bool warm, FrictionalStats& stats,
                      std::uint64_t max_steps, bool interior_point = false);
  bool sticking_guess(const FrictionalProblem& problem, Vector& r, FrictionalStats& stats);
  double warm_relaxation(const FrictionalProblem& relaxed, Vector& r, FrictionalStats& stats);
  double refine(const FrictionalProblem& problem, const std::vector<Block>& blocks, Vector& r, double residual,
                FrictionalStats& stats);
  double newton(const FrictionalProblem& problem, const std::vector<Block>& blocks, Vector& r,
                std::uint64_t iterations, FrictionalStats& stats);
  void proximal_newton(const FrictionalProblem& problem, const std::vector<Block>& blocks, Vector& r,
                       FrictionalStats& stats);
  double nonsmooth_gauss_seidel(const FrictionalProblem& problem, const std::vector<Block>& blocks, Vector& r,
                                double entry, FrictionalStats& stats);
  double projection(const FrictionalProblem& problem, const std::vector<Block>& blocks, Vector& r, double entry,
                    FrictionalStats& stats);
  double release_one_contact(const FrictionalProblem& problem, const std::vector<Block>& blocks, Vector& r,
                             FrictionalStats& stats);

  FrictionalSettings settings_;
  FrictionalWorkspace local_workspace_;
  std::uint64_t steps_left_ = 0;  // Newton steps left to the current solve (max_newton_steps)
  FrictionalWorkspace::Newton* buffers_ = nullptr;  // the current solve's Newton buffers
};

/// Solves a problem given in local form (impetus/modules/contact_problem.hpp; fclib's layout, e.g. read
/// from a file), writing `solution` (r, u = W r + q, residual, iterations, converged). A contact with
/// μ = 0 keeps r_t = 0 and leaves u_t free; equality rows are joint rows. Throws std::invalid_argument
/// naming the defect for arrays that disagree (column pointers, row indices out of range, non-finite
/// values, negative μ, W not symmetric), before any of them is used as an index.
void solve_local_problem(FrictionalSolver& solver, const LocalContactProblem& problem,
                         LocalContactSolution& solution, FrictionalStats& stats);

}  // namespace impetus::ledas
