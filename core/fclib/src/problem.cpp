// Contact problems in fclib's form without files: the problem of a scene's contacts, the reduction of a
// global problem to local form, the natural-map residual (fclib.hpp).
#include "impetus/fclib/fclib.hpp"

#include "impetus/core/error.hpp"

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>

namespace impetus::fclib {

LocalContactProblem LocalProblem::view(double tolerance) const {
  LocalContactProblem view;
  view.contacts = contacts();
  view.equalities = equalities;
  view.w_columns = w.outerIndexPtr();
  view.w_rows = w.innerIndexPtr();
  view.w_values = w.valuePtr();
  view.q = q.data();
  view.mu = mu.data();
  view.tolerance = tolerance;
  return view;
}

namespace {

// Projection of y on the cone ‖y_t‖ ≤ μ y_n (fclib's and Siconos's closed form).
Eigen::Vector3d project_on_cone(const Eigen::Vector3d& y, double mu) {
  const double tangent = std::hypot(y(1), y(2));
  if (mu * tangent <= -y(0)) return Eigen::Vector3d::Zero();  // in the polar cone
  if (tangent <= mu * y(0)) return y;                        // inside
  const double normal = (mu * tangent + y(0)) / (mu * mu + 1.0);
  return {normal, mu * normal * y(1) / tangent, mu * normal * y(2) / tangent};
}

}  // namespace

Eigen::Vector3d natural_map(const Eigen::Vector3d& r, const Eigen::Vector3d& u, double mu) {
  const Eigen::Vector3d shifted(u(0) + mu * std::hypot(u(1), u(2)), u(1), u(2));
  return r - project_on_cone(r - shifted, mu);
}

double natural_map_residual(const LocalProblem& problem, const Vector& r) {
  const Vector u = problem.w * r + problem.q;
  double sum = 0.0;
  for (std::size_t c = 0; c < problem.contacts(); ++c) {
    const auto i = static_cast<Eigen::Index>(3 * c);
    sum += natural_map(r.segment<3>(i), u.segment<3>(i), problem.mu[c]).squaredNorm();
  }
  sum += u.tail(static_cast<Eigen::Index>(problem.equalities)).squaredNorm();
  return std::sqrt(sum);
}

LocalProblem reduce(const GlobalProblem& problem) {
  const Eigen::Index n = problem.m.rows();
  const Eigen::Index contact_rows = problem.h.cols(), equalities = problem.g.cols();
  // [H G]: the contact rows, then the equality rows.
  SparseMatrix hg(n, contact_rows + equalities);
  std::vector<Eigen::Triplet<double>> entries;
  for (const SparseMatrix* part : {&problem.h, &problem.g})
    for (Eigen::Index j = 0; j < part->cols(); ++j)
      for (SparseMatrix::InnerIterator it(*part, j); it; ++it)
        entries.emplace_back(it.row(), j + (part == &problem.g ? contact_rows : 0), it.value());
  hg.setFromTriplets(entries.begin(), entries.end());

  Eigen::SimplicialLDLT<SparseMatrix> mass(problem.m);
  if (mass.info() != Eigen::Success || n == 0 || !(mass.vectorD().minCoeff() > 0.0))
    throw Error("M is not symmetric positive definite (its LDLᵀ factorization has a pivot ≤ 0)");
  const SparseMatrix m_inv_hg = mass.solve(hg);
  const Vector m_inv_f = mass.solve(problem.f);

  LocalProblem local;
  local.w = SparseMatrix(hg.transpose()) * m_inv_hg;
  local.w = 0.5 * (local.w + SparseMatrix(local.w.transpose()));  // exactly symmetric
  local.w.prune(0.0);
  local.q.resize(contact_rows + equalities);
  local.q.head(contact_rows) = problem.h.transpose() * m_inv_f + problem.w;
  local.q.tail(equalities) = problem.g.transpose() * m_inv_f + problem.b;
  local.mu = problem.mu;
  local.equalities = static_cast<std::size_t>(equalities);
  local.info = problem.info;
  return local;
}

SceneProblem scene_problem(std::span<const RigidBody> bodies, std::span<const Contact> contacts, double dt) {
  SceneProblem out;
  std::vector<std::int64_t> slot(bodies.size(), -1);  // a movable body's index in v, or −1
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const Contact& c = contacts[k];
    if (bodies[c.a].fixed && bodies[c.b].fixed) continue;
    out.contacts.push_back(k);
    for (BodyIndex i : {c.a, c.b})
      if (!bodies[i].fixed && slot[i] < 0) slot[i] = 0;
  }
  for (BodyIndex i = 0; i < bodies.size(); ++i)
    if (slot[i] >= 0) {
      slot[i] = static_cast<std::int64_t>(out.bodies.size());
      out.bodies.push_back(i);
    }
  const auto n = static_cast<Eigen::Index>(6 * out.bodies.size());
  const auto rows = static_cast<Eigen::Index>(3 * out.contacts.size());

  // M, M⁻¹ and f = M v⁻, block-diagonal per body (v, then ω; world frame).
  std::vector<Eigen::Triplet<double>> m_entries, m_inv_entries;
  GlobalProblem& g = out.global;
  g.f.resize(n);
  for (std::size_t s = 0; s < out.bodies.size(); ++s) {
    const RigidBody& body = bodies[out.bodies[s]];
    const auto base = static_cast<Eigen::Index>(6 * s);
    const Mat3 inertia = body.inertia_world(), inv_inertia = body.inv_inertia_world();
    for (int k = 0; k < 3; ++k) {
      m_entries.emplace_back(base + k, base + k, body.mass);
      m_inv_entries.emplace_back(base + k, base + k, body.inv_mass);
      for (int l = 0; l < 3; ++l) {
        m_entries.emplace_back(base + 3 + k, base + 3 + l, inertia(k, l));
        m_inv_entries.emplace_back(base + 3 + k, base + 3 + l, inv_inertia(k, l));
      }
    }
    g.f.segment<3>(base) = body.mass * body.velocity;
    g.f.segment<3>(base + 3) = inertia * body.angular_velocity;
  }
  g.m.resize(n, n);
  g.m.setFromTriplets(m_entries.begin(), m_entries.end());
  SparseMatrix m_inv(n, n);
  m_inv.setFromTriplets(m_inv_entries.begin(), m_inv_entries.end());

  // H: column 3k + d holds the impulse's direction and moment on b, negated on a.
  std::vector<Eigen::Triplet<double>> h_entries;
  g.w = Vector::Zero(rows);
  for (std::size_t k = 0; k < out.contacts.size(); ++k) {
    const Contact& c = contacts[out.contacts[k]];
    Vec3 frame[3];
    frame[0] = c.normal;
    tangent_basis(c.normal, frame[1], frame[2]);
    for (int d = 0; d < 3; ++d) {
      const auto column = static_cast<Eigen::Index>(3 * k + static_cast<std::size_t>(d));
      for (const auto& [index, sign] : {std::pair{c.a, -1.0}, std::pair{c.b, 1.0}}) {
        if (slot[index] < 0) continue;
        const RigidBody& body = bodies[index];
        const Vec3 moment = (c.point - body.position).cross(frame[d]);
        const auto base = static_cast<Eigen::Index>(6 * slot[index]);
        for (int l = 0; l < 3; ++l) {
          h_entries.emplace_back(base + l, column, sign * frame[d](l));
          h_entries.emplace_back(base + 3 + l, column, sign * moment(l));
        }
      }
    }
    g.w(static_cast<Eigen::Index>(3 * k)) = -std::min(0.0, c.depth) / dt;
    // A fixed body's prescribed velocity at the contact is a constant part of the relative velocity.
    const Vec3 prescribed = (bodies[c.b].fixed ? bodies[c.b].velocity_at(c.point) : Vec3::Zero()) -
                            (bodies[c.a].fixed ? bodies[c.a].velocity_at(c.point) : Vec3::Zero());
    for (int d = 0; d < 3; ++d) g.w(static_cast<Eigen::Index>(3 * k + static_cast<std::size_t>(d))) += frame[d].dot(prescribed);
    g.mu.push_back(combined_friction(bodies[c.a], bodies[c.b]));
  }
  g.h.resize(n, rows);
  g.h.setFromTriplets(h_entries.begin(), h_entries.end());
  g.g.resize(n, 0);

  // The local form with the bodies' own inverses: W = Hᵀ M⁻¹ H, q = Hᵀ v⁻ + w.
  LocalProblem& local = out.local;
  const SparseMatrix m_inv_h = m_inv * g.h;
  local.w = SparseMatrix(g.h.transpose()) * m_inv_h;
  local.w = 0.5 * (local.w + SparseMatrix(local.w.transpose()));
  Vector v(n);
  for (std::size_t s = 0; s < out.bodies.size(); ++s) {
    v.segment<3>(static_cast<Eigen::Index>(6 * s)) = bodies[out.bodies[s]].velocity;
    v.segment<3>(static_cast<Eigen::Index>(6 * s + 3)) = bodies[out.bodies[s]].angular_velocity;
  }
  local.q = g.h.transpose() * v + g.w;
  local.mu = g.mu;
  return out;
}

}  // namespace impetus::fclib
