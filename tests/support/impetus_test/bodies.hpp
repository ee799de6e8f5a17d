#pragma once
// Small builders shared by the tests: the fixed ground and a contact written out by hand, the ones the
// conformance suites use (impetus/conformance/fixtures.hpp).

#include "impetus/conformance/fixtures.hpp"

namespace impetus::test {

/// The fixed ground "ground": the half-space z ≤ 0, with restitution `restitution`.
inline RigidBody ground_plane(double restitution = 0.0) { return conformance::ground(restitution); }

using conformance::contact;

}  // namespace impetus::test
