#pragma once
/// \file
/// The bordered (Schur-complement) update of a masked factorization (masked_ldlt.hpp): solves
/// (A + εI)_WW p_W = c_W for an active set W that differs from the rows B of the last factorization by a
/// few rows, without refactoring.
///
/// With W = (B \ R) ∪ D and F = Pᵀ L D Lᵀ P the factorization of (A + εI)_BB, p_R = 0 is imposed by
/// multipliers μ on the rows R and the new rows D border the system:
///   (A + εI)_BB p_B + A_BD p_D + E_R μ = c_B,   A_DB p_B + (A + εI)_DD p_D = c_D,   E_Rᵀ p_B = 0.
/// With U = [A_BD, E_R], p_B = F⁻¹(c_B − U y), and y = (p_D, μ) solves the small Schur system
///   S y = (c_D, 0) − Uᵀ F⁻¹ c_B,   S = [(A + εI)_DD 0; 0 0] − Uᵀ F⁻¹ U.
/// With W = L⁻¹ P U, Uᵀ F⁻¹ U = Wᵀ D⁻¹ W: each column of W is a sparse forward solve along the
/// elimination tree (MaskedLdlt::forward_sparse), kept with its Gram entries while the factorization
/// is (the changes of an active-set search mostly grow), and one right-hand side costs one solve split
/// in halves: t = L⁻¹ P c, y from Wᵀ D⁻¹ t, then p_B = Pᵀ L⁻ᵀ D⁻¹ (t − W y).

#include "impetus/resolution/ledas/island_solver.hpp"

#include <Eigen/Dense>

#include <span>
#include <utility>
#include <vector>

namespace impetus::ledas {

class MaskedLdlt;

/// The update's state against one factorization: the border columns computed so far and the last
/// factorized Schur system. Belongs to one active-set loop at a time; forget() whenever it refactors.
/// Kept from solve to solve (ComplementarityWorkspace::update), it reuses its buffers: borders, Gram
/// matrix and one Schur factorization per system size, so a loop that meets the sizes it met before
/// allocates nothing.
class BorderedUpdate {
 public:
  /// Forgets the borders and the last update (the factorization they were computed against changed).
  void forget();
  /// Whether the last update solves for the active set `active` (apply() then solves on it).
  bool solves_for(const std::vector<char>& active) const { return updated_ && updated_for_ == active; }
  /// Solves (A + shift·I)_WW p_W = c_W for W = {k : active[k]} (p zero off W) by an update of `factor`,
  /// the factorization of the rows {k : in_base[k]}; reuses the last update if it was for W. Returns
  /// false (refactor) when the Schur system is singular to `rank_tolerance` or the result does not hold
  /// the active rows to 1e-10 relative.
  bool solve(const MaskedLdlt& factor, const std::vector<char>& in_base, const SparseMatrix& a, double shift,
             const Vector& c, const std::vector<char>& active, double rank_tolerance, Vector& p);
  /// The last update's solution for the right-hand side c (size of A) into `out`.
  void apply(const MaskedLdlt& factor, const Vector& c, Vector& out);

 private:
  // The entry of borders_ for a row that joins (u = A_B,row) or leaves (u = e_row) the rows B: computed
  // on first use, with its Gram entries against the borders already there.
  int border(const MaskedLdlt& factor, const std::vector<char>& in_base, const SparseMatrix& a, RowIndex row);

  // y = S⁻¹ rhs by the last Schur factorization (full pivoting, full rank), without a temporary.
  void solve_schur(std::span<const double> rhs, std::span<double> y);

  struct Border {  // one column of W = L⁻¹ P U, sparse
    std::vector<int> index;  // elimination order, increasing
    std::vector<double> value;
  };
  std::vector<Border> borders_;  // the first border_count_ are this factorization's; the rest keep storage
  std::size_t border_count_ = 0;
  std::vector<int> border_of_;  // per row: its entry in borders_, or −1
  Eigen::MatrixXd gram_;        // G_ij = w_iᵀ D⁻¹ w_j of the borders (i, j < border_count_; capacity grows)
  // The last update: the active set it solves for, its added and removed rows (their entries in
  // borders_, added first) and the factorized Schur system (schur_[size], one per size met).
  bool updated_ = false;
  std::vector<char> updated_for_;
  std::vector<RowIndex> added_, removed_;
  std::vector<int> slots_;
  std::vector<Eigen::MatrixXd> schur_matrix_;
  std::vector<Eigen::FullPivLU<Eigen::MatrixXd>> schur_;
  std::vector<std::pair<int, double>> column_;  // border()'s u
  Vector forward_;    // apply()'s t = L⁻¹ P c
  Vector scattered_;  // border()'s D⁻¹ w, zero between calls
  Vector out_, residual_;            // solve()'s candidate and its check
  std::vector<double> rhs_, y_, permuted_;  // apply()'s Schur right-hand side and solution; solve_schur's scratch
};

}  // namespace impetus::ledas
