// A frictional contact problem given directly in local form (impetus/modules/contact_problem.hpp, fclib's
// layout: three rows per contact, then equality rows), solved by the island's frictional solver.
#include "impetus/resolution/ledas/frictional_solver.hpp"
#include "impetus/resolution/ledas/ledas.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace impetus {

namespace ledas {

namespace {

// W may come from a file written by another program: it must be symmetric to this relative accuracy
// (rounding in a Delassus product is far below it), and is then symmetrized exactly.
constexpr double kSymmetryTolerance = 1e-9;

std::string row_name(const LocalContactProblem& p, std::int64_t row) {
  const auto contacts_rows = static_cast<std::int64_t>(3 * p.contacts);
  if (row < contacts_rows) return "row " + std::to_string(row) + " (contact " + std::to_string(row / 3) + ")";
  return "row " + std::to_string(row) + " (equality " + std::to_string(row - contacts_rows) + ")";
}

// Checks the arrays of `p` (sizes, ordering, finiteness, μ ≥ 0) before any of them is used as an index.
void check(const LocalContactProblem& p) {
  const std::uint64_t m64 = 3 * p.contacts + p.equalities;
  if (p.contacts > (1u << 28) || p.equalities > (1u << 28)) throw std::invalid_argument("too many rows");
  const auto m = static_cast<std::int64_t>(m64);
  if (m == 0) return;
  if (!p.w_columns || !p.w_rows || !p.w_values || !p.q || (p.contacts > 0 && !p.mu))
    throw std::invalid_argument("an array of the problem is missing");
  if (!(p.tolerance >= 0.0) || !std::isfinite(p.tolerance)) throw std::invalid_argument("the tolerance is not a finite number ≥ 0");
  if (p.w_columns[0] != 0) throw std::invalid_argument("W's column pointers do not start at 0");
  for (std::int64_t j = 0; j < m; ++j)
    if (p.w_columns[j + 1] < p.w_columns[j]) throw std::invalid_argument("W's column pointers decrease at column " + std::to_string(j));
  for (std::int64_t k = 0; k < p.w_columns[m]; ++k) {
    if (p.w_rows[k] < 0 || p.w_rows[k] >= m) throw std::invalid_argument("W has an entry outside its " + std::to_string(m) + " rows");
    if (!std::isfinite(p.w_values[k])) throw std::invalid_argument("W has a non-finite entry");
  }
  for (std::int64_t i = 0; i < m; ++i)
    if (!std::isfinite(p.q[i])) throw std::invalid_argument("q is not finite at " + row_name(p, i));
  for (std::uint64_t c = 0; c < p.contacts; ++c)
    if (!(p.mu[c] >= 0.0) || !std::isfinite(p.mu[c]))
      throw std::invalid_argument("mu of contact " + std::to_string(c) + " is " + std::to_string(p.mu[c]) + " (must be finite and ≥ 0)");
}

// W, checked symmetric to kSymmetryTolerance and made exactly symmetric: ½ (W + Wᵀ), its columns'
// entries sorted. A W stored sorted with a symmetric pattern (the usual case) is copied once and each
// pair of mirrored entries averaged in place, each entry's mirror found by binary search (no transpose:
// on this machine every fresh megabyte costs ~2.5 ms of page faults); any other is formed as a sum.
SparseMatrix symmetrized(const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::ColMajor, std::int32_t>>& w_file) {
  const Eigen::Index m = w_file.cols();
  const std::int32_t* outer = w_file.outerIndexPtr();
  const std::int32_t* inner = w_file.innerIndexPtr();
  const double scale = w_file.nonZeros() > 0 ? w_file.coeffs().cwiseAbs().maxCoeff() : 0.0;
  bool sorted = true;  // each column's rows strictly increasing (as fclib's writers and Impetus's store them)
  for (Eigen::Index j = 0; j < m && sorted; ++j)
    for (std::int32_t p = outer[j] + 1; p < outer[j + 1] && sorted; ++p) sorted = inner[p - 1] < inner[p];
  if (sorted) {
    SparseMatrix w(m, m);  // copied array by array (Eigen's assignment from a map grows entry by entry)
    w.resizeNonZeros(w_file.nonZeros());
    std::copy(outer, outer + m + 1, w.outerIndexPtr());
    std::copy(inner, inner + w_file.nonZeros(), w.innerIndexPtr());
    std::copy(w_file.valuePtr(), w_file.valuePtr() + w_file.nonZeros(), w.valuePtr());
    double* value = w.valuePtr();
    bool mirrored = true;
    for (Eigen::Index j = 0; j < m && mirrored; ++j)
      for (std::int32_t p = outer[j]; p < outer[j + 1]; ++p) {
        const std::int32_t i = inner[p];
        if (i >= j) continue;  // each pair once, from its upper entry
        const std::int32_t* at = std::lower_bound(inner + outer[i], inner + outer[i + 1], static_cast<std::int32_t>(j));
        if (at == inner + outer[i + 1] || *at != j) {
          mirrored = false;
          break;
        }
        double& mirror = value[at - inner];
        if (std::abs(value[p] - mirror) > kSymmetryTolerance * scale) throw std::invalid_argument("W is not symmetric");
        value[p] = mirror = 0.5 * (value[p] + mirror);
      }
    // Every upper entry has its mirror, and the counts agree: so does every lower one.
    std::int64_t upper = 0, lower = 0;
    for (Eigen::Index j = 0; j < m && mirrored; ++j)
      for (std::int32_t p = outer[j]; p < outer[j + 1]; ++p) {
        if (inner[p] < j) ++upper;
        else if (inner[p] > j) ++lower;
      }
    if (mirrored && upper == lower) return w;
  }
  const SparseMatrix transpose = w_file.transpose();
  const SparseMatrix w = transpose.transpose();  // W, sorted
  const SparseMatrix difference = w - transpose;
  if (difference.nonZeros() > 0 && difference.coeffs().cwiseAbs().maxCoeff() > kSymmetryTolerance * scale)
    throw std::invalid_argument("W is not symmetric");
  return 0.5 * (w + transpose);
}

}  // namespace

void solve_local_problem(FrictionalSolver& solver, const LocalContactProblem& p, LocalContactSolution& s,
                         FrictionalStats& stats) {
  check(p);
  const auto m = static_cast<Eigen::Index>(3 * p.contacts + p.equalities);
  if (m > 0 && (!s.r || !s.u)) throw std::invalid_argument("the solution's arrays are missing");
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::ColMajor, std::int32_t>> w_file(
      m, m, m > 0 ? p.w_columns[m] : 0, p.w_columns, p.w_rows, p.w_values);
  const SparseMatrix w = symmetrized(w_file);
  const Eigen::Map<const Vector> q_full(p.q, m);

  // The solver's rows: a contact's normal row, its tangent rows only if μ > 0 (with μ = 0 the cone forces
  // r_t = 0 and leaves u_t free), then the equality rows. kept[k] is row k's index in the full problem.
  std::vector<Eigen::Index> kept;
  FrictionalProblem problem;
  for (std::uint64_t c = 0; c < p.contacts; ++c) {
    const auto first = static_cast<Eigen::Index>(3 * c);
    const bool friction = p.mu[c] > 0.0;
    for (int k = 0; k < (friction ? 3 : 1); ++k) {
      kept.push_back(first + k);
      problem.role.push_back(k == 0 ? RowRole::normal : RowRole::tangent);
      problem.mu.push_back(friction ? p.mu[c] : 0.0);
    }
  }
  for (std::uint64_t e = 0; e < p.equalities; ++e) {
    kept.push_back(static_cast<Eigen::Index>(3 * p.contacts + e));
    problem.role.push_back(RowRole::equality);
    problem.mu.push_back(0.0);
  }
  const auto n = static_cast<Eigen::Index>(kept.size());
  SparseMatrix reduced;  // W on the kept rows, when some are dropped
  if (n < m) {
    std::vector<Eigen::Index> slot(static_cast<std::size_t>(m), -1);
    for (Eigen::Index k = 0; k < n; ++k) slot[static_cast<std::size_t>(kept[static_cast<std::size_t>(k)])] = k;
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(static_cast<std::size_t>(w.nonZeros()));
    for (Eigen::Index j = 0; j < m; ++j)
      for (SparseMatrix::InnerIterator it(w, j); it; ++it)
        if (const Eigen::Index a = slot[static_cast<std::size_t>(it.row())], b = slot[static_cast<std::size_t>(j)]; a >= 0 && b >= 0)
          entries.emplace_back(a, b, it.value());
    reduced.resize(n, n);
    reduced.setFromTriplets(entries.begin(), entries.end());
  }
  problem.w = n < m ? &reduced : &w;
  problem.q.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) problem.q(k) = q_full(kept[static_cast<std::size_t>(k)]);
  problem.tolerance = p.tolerance;
  // Solved cold (every analysis afresh), in the storage of the solver's last local problem: on this
  // machine a fresh page costs ~10 µs, and the tower of planks' W alone is 600 of them.
  solver.local_workspace().forget_analyses();
  problem.workspace = &solver.local_workspace();

  const FrictionalStats before = stats;
  const Vector r_kept = solver.solve(problem, stats);
  Eigen::Map<Vector> r(s.r, m), u(s.u, m);
  r.setZero();
  for (Eigen::Index k = 0; k < n; ++k) r(kept[static_cast<std::size_t>(k)]) = r_kept(k);
  u = w * r + q_full;
  s.residual = natural_map_residual(problem, r_kept);
  s.iterations = (stats.newton_steps - before.newton_steps) + (stats.interior_point_steps - before.interior_point_steps) +
                 (stats.coulomb_interior_point_steps - before.coulomb_interior_point_steps) +
                 (stats.fallback_sweeps - before.fallback_sweeps);
  s.converged = stats.non_converged == before.non_converged && s.residual <= p.tolerance;
}

}  // namespace ledas

ModuleStatus LedasResolver::solve_contact_problem(const LocalContactProblem& problem,
                                                  LocalContactSolution& solution) noexcept {
  if (settings_.mode == LedasMode::paper)
    return ModuleStatus::failure("ledas in paper mode has no frictional solver (use mode: complementary)");
  try {
    stats_ = {};
    ledas::solve_local_problem(friction_solver_, problem, solution, stats_.friction);
    return ModuleStatus::success();
  } catch (const std::exception& e) {
    return ModuleStatus::failure(std::string("the contact problem is malformed: ") + e.what());
  } catch (...) {
    return ModuleStatus::failure("the contact problem could not be solved (unknown error)");
  }
}

}  // namespace impetus
