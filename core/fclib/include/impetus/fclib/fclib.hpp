#pragma once
/// \file
/// Frictional contact problems in the Frictional Contact Library's form (fclib: HDF5 files of local
/// problems W, q, μ and global ones M, H, G, f, w, b, μ; Acary, Cadoux, Lamarque, Huber et al.), read and
/// written through Debian's libfclib, and the problem Impetus sees in a scene after one detection.
///
/// Conventions (docs/conventions.md, "Contact problems in fclib's form"): per contact three rows (normal
/// out of a into b, t1, t2 of tangent_basis(normal)); r is the impulse on b (−r on a), u the relative
/// velocity of b with respect to a at the contact point, both in the contact's frame.
///
///   global:  M v = H r + G λ + f,  Gᵀ v + b = 0,  u = Hᵀ v + w     (v: 6 per movable body, v then ω)
///   local:   u = W r + q,  W = Hᵀ M⁻¹ H,  q = Hᵀ M⁻¹ f + w          (plus fclib's mixed rows V, R, s)
///
/// Files come from anywhere: every size, index and value is checked before use, and a defect is an
/// impetus::Error naming the file, the dataset and the problem. libfclib stops the process on an HDF5
/// read that fails, so each dataset it will read is first checked with HDF5 itself (exists, is numeric,
/// has the size fclib allocates for it).

#include "impetus/core/body.hpp"
#include "impetus/modules/contact.hpp"
#include "impetus/modules/contact_problem.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace impetus::fclib {

/// Compressed sparse columns with 32-bit indices: fclib's and LocalContactProblem's layout.
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, std::int32_t>;
using Vector = Eigen::VectorXd;

/// The text fclib stores with a problem (all optional).
struct Info {
  std::string title, description, math_info;
};

/// A local problem: the 3·contacts rows of the contacts, then `equalities` mixed rows (fclib's V, R, s,
/// stored here as W = [W V; Vᵀ R], q = [q; s]).
struct LocalProblem {
  SparseMatrix w;
  Vector q;
  std::vector<double> mu;  ///< per contact
  std::size_t equalities = 0;
  Info info;

  std::size_t contacts() const { return mu.size(); }
  std::size_t rows() const { return static_cast<std::size_t>(q.size()); }
  /// A view for CollisionResolver::solve_contact_problem (valid while this problem lives).
  LocalContactProblem view(double tolerance) const;
};

/// A global problem (fclib_global): n velocities, 3·contacts contact rows, p equality rows.
struct GlobalProblem {
  SparseMatrix m, h, g;  ///< M (n × n, symmetric positive definite), H (n × 3 n_c), G (n × p, may be empty)
  Vector f, w, b;
  std::vector<double> mu;  ///< per contact
  Info info;

  std::size_t contacts() const { return mu.size(); }
};

/// Which form a file holds.
enum class Form { local, global };

/// A problem read from a file: the local form (a global problem reduced), and the global one if stored.
struct FileProblem {
  Form form = Form::local;
  LocalProblem local;
  GlobalProblem global;  ///< empty unless form == global
};

/// Reads an fclib file (a local problem, or a global one reduced to local form). Throws impetus::Error
/// naming the file and the defect: not HDF5, no fclib problem in it, a dataset missing or of the wrong
/// size, sizes that disagree, an index out of range, a non-finite value, a negative μ, a space dimension
/// other than 3, W not symmetric, M not positive definite.
FileProblem read_problem(const std::filesystem::path& file);

/// Writes `problem` as an fclib local (or global) problem into `file`, which must not exist (the caller
/// decides about overwriting). Throws impetus::Error if fclib cannot write it.
void write_problem(const std::filesystem::path& file, const LocalProblem& problem);
void write_problem(const std::filesystem::path& file, const GlobalProblem& problem);

/// The local form of a global problem: W = [H G]ᵀ M⁻¹ [H G], q = [H G]ᵀ M⁻¹ f + [w; b] (the G rows become
/// equality rows). Throws impetus::Error if M is not positive definite.
LocalProblem reduce(const GlobalProblem& problem);

/// fclib's merit (fclib_merit_local, MERIT_1) of the impulses r for `problem`: the natural-map residual
/// of the contacts divided by 1 + √‖q‖, plus the equality rows' ‖Vᵀr + Rλ + s‖ / (1 + ‖s‖).
double merit(const LocalProblem& problem, const Vector& r);

/// The natural-map residual of r, unscaled (the absolute error the ledas solver reaches): the 2-norm over
/// contacts of r − P_K(r − û) and over equality rows of u, with u = W r + q.
double natural_map_residual(const LocalProblem& problem, const Vector& r);

/// One contact's natural-map residual vector r − P_K(r − û), û = (u_n + μ‖u_t‖, u_t), for an impulse r and
/// a relative velocity u in the contact's frame (normal first): zero exactly when (r, u) satisfies Coulomb's
/// law at that contact. natural_map_residual is the 2-norm of these over the contacts (u = W r + q there);
/// a caller with r and u from elsewhere (another engine's impulses and velocities) sums them itself.
Eigen::Vector3d natural_map(const Eigen::Vector3d& r, const Eigen::Vector3d& u, double mu);

/// The contact problem of `contacts` on `bodies` as `impetus resolve` sees it, for a step of `dt` (s): the
/// movable bodies touched by a contact (in index order) and every contact with at least one of them;
/// f = M v⁻ (the bodies' current velocities), w = −min(0, depth)/dt on normal rows (a gap may close
/// within the step), μ = combined_friction. Restitution is not part of it (the inelastic impact).
struct SceneProblem {
  GlobalProblem global;
  LocalProblem local;  ///< its local form, W from the bodies' own M⁻¹ (m⁻¹, R J⁻¹ Rᵀ) as resolvers build it
  std::vector<BodyIndex> bodies;     ///< the movable bodies, in the order of v
  std::vector<std::size_t> contacts; ///< the contacts' indices in `contacts`, in row order
};
SceneProblem scene_problem(std::span<const RigidBody> bodies, std::span<const Contact> contacts, double dt);

}  // namespace impetus::fclib
