#include "sparse_lu.hpp"

namespace impetus::ledas {

SparseLu::SparseLu() {
  klu_defaults(&common_);
  // No row scaling, and no check of the matrix on each factorization. The Jacobian's entries are of
  // order one already: identity rows, and W's rows times ρ = 1/W_ii, whose diagonal is ~1 and whose
  // entry ρ_i W_ij is at most √(W_jj / W_ii), in the rows KLU sees (Jᵀ's) as in J's. The matrix is
  // assembled here on a pattern klu_analyze has checked. KLU's default (scale = 2: each row divided by
  // its largest entry, and the matrix checked, at every refactorization) was 16% of the time of the
  // frictional pile's large islands, whose factors have little fill (README, "Friction").
  common_.scale = -1;
}

SparseLu::~SparseLu() {
  free_numeric();
  if (symbolic_ != nullptr) klu_free_symbolic(&symbolic_, &common_);
}

void SparseLu::free_numeric() {
  if (numeric_ != nullptr) klu_free_numeric(&numeric_, &common_);
}

bool SparseLu::analyze(const RowMajorMatrix& a) {
  free_numeric();
  if (symbolic_ != nullptr) klu_free_symbolic(&symbolic_, &common_);
  // KLU's int interface takes non-const pointers it does not write through.
  symbolic_ = klu_analyze(static_cast<int>(a.rows()), const_cast<int*>(a.outerIndexPtr()),
                          const_cast<int*>(a.innerIndexPtr()), &common_);
  return symbolic_ != nullptr;
}

bool SparseLu::factorize(const RowMajorMatrix& a, bool reuse_pivots) {
  if (symbolic_ == nullptr) return false;
  int* outer = const_cast<int*>(a.outerIndexPtr());
  int* inner = const_cast<int*>(a.innerIndexPtr());
  double* value = const_cast<double*>(a.valuePtr());
  if (reuse_pivots && numeric_ != nullptr && klu_refactor(outer, inner, value, symbolic_, numeric_, &common_) == 1 &&
      common_.status == KLU_OK)
    return true;
  free_numeric();
  numeric_ = klu_factor(outer, inner, value, symbolic_, &common_);
  return numeric_ != nullptr && common_.status == KLU_OK;
}

bool SparseLu::solve(Vector& x) {
  if (numeric_ == nullptr) return false;
  // Aᵀ's factors, transposed: A x = b.
  return klu_tsolve(symbolic_, numeric_, static_cast<int>(x.size()), 1, x.data(), &common_) == 1;
}

}  // namespace impetus::ledas
