// LEDAS resolver on the paper's benchmark scenes (pyramid drop, line push) and singular systems
// (Figure 2, a box on five points); the dense and sparse paths agree.
#include "impetus/engine/generators.hpp"
#include "ledas_test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

namespace impetus {
namespace {

using namespace ledas_test;

struct Outcome {
  std::vector<RigidBody> bodies;
  std::vector<Contact> contacts;
  ResolverCounters counters;
  LedasStats stats;
};

Outcome run(std::vector<RigidBody> bodies, const LedasSettings& settings) {
  Outcome out{std::move(bodies), {}, {}, {}};
  out.contacts = sphere_contacts(out.bodies);
  LedasResolver resolver(settings);
  out.counters = resolve(resolver, out.bodies, out.contacts);
  out.stats = resolver.last_stats();
  return out;
}

double normal_velocity_of(const Outcome& o, const Contact& c) { return normal_velocity(c, o.bodies[c.a], o.bodies[c.b]); }

// The paper's pyramid drop with K rows.
std::vector<RigidBody> pyramid_of(int rows) {
  PyramidParams params;
  params.rows = rows;
  return make_pyramid(params);
}

// Complementary mode started with every touching contact, so that the search meets the redundant rows.
LedasSettings touching_start() {
  LedasSettings s = settings_for(LedasMode::complementary);
  s.start_set = LedasStartSet::touching;
  return s;
}

// Two solutions of the same impact: both exact (no cap reached, residual and complementarity error
// ≤ 1e-9) and with the same velocities (1e-9 m/s: the velocities after an impact are unique).
void expect_same_exact_answer(const Outcome& a, const Outcome& b) {
  for (const Outcome* o : {&a, &b}) {
    EXPECT_EQ(o->counters.non_converged, 0u);
    EXPECT_LE(o->counters.residual, 1e-9);
    EXPECT_LE(o->counters.complementarity_error, 1e-9);
  }
  ASSERT_EQ(a.bodies.size(), b.bodies.size());
  for (std::size_t i = 0; i < a.bodies.size(); ++i) EXPECT_LT((a.bodies[i].velocity - b.bodies[i].velocity).norm(), 1e-9);
}

// Pyramid drop (every sphere at (0, 0, −1), e = 0). Complementary: p ≥ 0, v_n⁺ ≥ −1e-9, |p v_n⁺| ≤ 1e-9,
// mirror-symmetric in x (1e-9). Paper: ends with no approaching contact; rounds and pulling impulses
// printed.
TEST(LedasSystems, PyramidDrop) {
  for (int rows : {3, 4, 10, 20}) {
    PyramidParams params;
    params.rows = rows;
    const std::vector<RigidBody> pyramid = make_pyramid(params);
    const std::size_t spheres = pyramid.size() - 1;
    const Outcome exact = run(pyramid, settings_for(LedasMode::complementary));
    ASSERT_EQ(exact.contacts.size(), static_cast<std::size_t>(3 * rows * (rows - 1) / 2 + rows));
    for (const Contact& c : exact.contacts) {
      const double vn = normal_velocity_of(exact, c);
      EXPECT_GE(c.impulse, 0.0);
      EXPECT_GE(vn, -1e-9);
      EXPECT_LE(std::abs(c.impulse * vn), 1e-9);
    }
    // Mirror in x: sphere i of row j ↔ sphere (rows − j − 1 − i) of the same row.
    std::size_t first = 0;
    for (int j = 0; j < rows; ++j) {
      const int n = rows - j;
      for (int i = 0; i < n; ++i) {
        const Vec3& v = exact.bodies[first + static_cast<std::size_t>(i)].velocity;
        const Vec3& w = exact.bodies[first + static_cast<std::size_t>(n - 1 - i)].velocity;
        EXPECT_NEAR(v.x(), -w.x(), 1e-9);
        EXPECT_NEAR(v.z(), w.z(), 1e-9);
      }
      first += static_cast<std::size_t>(n);
    }
    EXPECT_EQ(exact.counters.non_converged, 0u);
    EXPECT_LE(exact.counters.complementarity_error, 1e-9);

    const Outcome paper = run(pyramid, settings_for(LedasMode::paper));
    for (const Contact& c : paper.contacts) EXPECT_GE(normal_velocity_of(paper, c), -1e-9);
    EXPECT_EQ(paper.counters.non_converged, 0u);
    EXPECT_LE(paper.counters.residual, 1e-9);
    std::printf("[ledas] pyramid K=%d (%zu spheres, %zu contacts): complementary %llu active-set iterations, "
                "%llu released (pulling), %llu singular, KE after %.6g J | paper %llu rounds, %llu pulling "
                "impulses applied, %llu singular, complementarity error %.3g, KE after %.6g J\n",
                rows, spheres, exact.contacts.size(), (unsigned long long)exact.counters.rounds,
                (unsigned long long)exact.counters.pulling_impulses, (unsigned long long)exact.counters.singular_systems,
                kinetic_energy(exact.bodies), (unsigned long long)paper.counters.rounds,
                (unsigned long long)paper.counters.pulling_impulses, (unsigned long long)paper.counters.singular_systems,
                paper.counters.complementarity_error, kinetic_energy(paper.bodies));
  }
}

// Line push (first sphere at (1, 0, 0), fixed wall after the last). e = 1: both modes send the first
// sphere back at −1 and leave the rest at rest; e = 0: everything stops. Exact (1e-12) in complementary
// mode; the paper's rounds stop when no contact approaches faster than the tolerance (1e-9 m/s), so
// the spheres may keep N × 1e-9 m/s. Rounds printed.
TEST(LedasSystems, LinePush) {
  for (int count : {10, 100})
    for (double e : {0.0, 1.0})
      for (LedasMode mode : {LedasMode::paper, LedasMode::complementary}) {
        LineParams params;
        params.count = count;
        params.restitution = e;
        const Outcome o = run(make_line(params), settings_for(mode));
        ASSERT_EQ(o.contacts.size(), static_cast<std::size_t>(count));
        for (int i = 0; i < count; ++i) {
          const double expected = (e == 1.0 && i == 0) ? -1.0 : 0.0;
          const double tolerance = mode == LedasMode::paper ? count * 1e-9 : 1e-12;
          EXPECT_NEAR(o.bodies[static_cast<std::size_t>(i)].velocity.x(), expected, tolerance) << "sphere " << i;
        }
        for (const Contact& c : o.contacts) EXPECT_GE(normal_velocity_of(o, c), -1e-9);
        EXPECT_EQ(o.counters.non_converged, 0u);
        std::printf("[ledas] line N=%d e=%g %s: %llu rounds (systems solved), %llu pulling, residual %.2g\n", count, e,
                    mode == LedasMode::paper ? "paper" : "complementary", (unsigned long long)o.counters.rounds,
                    (unsigned long long)o.counters.pulling_impulses, o.counters.residual);
      }
}

// A stack of ten boxes (four corner contacts per interface) all falling at 1 m/s onto the ground, e = 0.
// The bodies move together, so in the paper's mode only the ground contacts approach at first and the
// stop travels up layer by layer; the complementary mode stops the whole stack at once. Both end with
// no approaching contact (1e-9) and everything at rest (complementary 1e-12). Rounds printed.
TEST(LedasSystems, BoxStackDrop) {
  for (LedasMode mode : {LedasMode::paper, LedasMode::complementary}) {
    std::vector<RigidBody> bodies{ground_plane()};
    for (int i = 0; i < 10; ++i) bodies.push_back(solid(Box{Vec3(1, 1, 1)}, 1.0 + 0.1 * i, Vec3(0, 0, 0.5 + i), Vec3(0, 0, -1)));
    std::vector<Contact> contacts;
    DetectorCounters detected;
    BoxStackDetector(1e-6).detect(bodies, StepContext{}, contacts, detected);
    ASSERT_EQ(contacts.size(), 40u);
    LedasResolver resolver(settings_for(mode));
    const ResolverCounters c = resolve(resolver, bodies, contacts);
    for (const Contact& k : contacts) EXPECT_GE(normal_velocity(k, bodies[k.a], bodies[k.b]), -1e-9);
    for (std::size_t i = 1; i < bodies.size(); ++i)
      EXPECT_LT(bodies[i].velocity.norm() + bodies[i].angular_velocity.norm(), mode == LedasMode::paper ? 1e-7 : 1e-12);
    EXPECT_EQ(c.non_converged, 0u);
    std::printf("[ledas] 10-box stack drop (40 contacts) %s: %llu rounds (systems solved), %llu pulling, %llu singular, %llu redundant\n",
                mode == LedasMode::paper ? "paper" : "complementary", (unsigned long long)c.rounds,
                (unsigned long long)c.pulling_impulses, (unsigned long long)c.singular_systems,
                (unsigned long long)c.redundant_systems);
  }
}

// The paper's Figure 2: a segment on a longer segment with contacts at its two ends and its middle.
// A is singular (three collinear points, two relative degrees of freedom); the minimum-norm solution
// shares the impulse equally (1e-9). Both bodies move, gravity-free.
TEST(LedasSystems, FigureTwoSharesTheImpulseEqually) {
  for (LedasMode mode : {LedasMode::paper, LedasMode::complementary}) {
    std::vector<RigidBody> bodies{solid(Box{Vec3(4, 0.2, 0.2)}, 3.0, {0, 0, 0}),
                                  solid(Box{Vec3(2, 0.2, 0.2)}, 1.0, {0, 0, 0.2}, {0.1, 0, -1})};
    std::vector<Contact> contacts;
    for (double x : {-1.0, 0.0, 1.0}) contacts.push_back(contact(0, 1, {x, 0, 0.1}, Vec3::UnitZ()));
    LedasResolver resolver(settings_for(mode));
    const ResolverCounters c = resolve(resolver, bodies, contacts);
    const double total = 1.0 * 3.0 / 4.0;  // reduced mass × approach speed
    for (const Contact& k : contacts) EXPECT_NEAR(k.impulse, total / 3.0, 1e-9);
    // Redundant, and solved exactly by the minimum norm: not a failure.
    EXPECT_GE(c.redundant_systems, 1u);
    EXPECT_EQ(c.singular_systems, 0u);
    EXPECT_EQ(c.nan_caught, 0u);
    EXPECT_NEAR(bodies[0].velocity.z(), bodies[1].velocity.z(), 1e-12);
    EXPECT_LT(bodies[1].angular_velocity.norm() + bodies[0].angular_velocity.norm(), 1e-12);
  }
}

// A box landing flat on four corner contacts plus a fifth at the face centre: rank 3 of 5; minimum
// norm gives m v / 5 at each point (1e-9), no NaN.
TEST(LedasSystems, BoxOnFivePointsSharesEqually) {
  for (LedasMode mode : {LedasMode::paper, LedasMode::complementary}) {
    std::vector<RigidBody> bodies{ground_plane(), solid(Box{Vec3(1, 0.8, 0.5)}, 2.0, {0, 0, 0.25}, {0, 0, -1.5})};
    std::vector<Contact> contacts;
    for (int k = 0; k < 4; ++k) contacts.push_back(contact(0, 1, {k & 1 ? 0.5 : -0.5, k & 2 ? 0.4 : -0.4, 0}, Vec3::UnitZ()));
    contacts.push_back(contact(0, 1, {0, 0, 0}, Vec3::UnitZ()));
    LedasResolver resolver(settings_for(mode));
    const ResolverCounters c = resolve(resolver, bodies, contacts);
    for (const Contact& k : contacts) EXPECT_NEAR(k.impulse, 2.0 * 1.5 / 5.0, 1e-9);
    EXPECT_LT(bodies[1].velocity.norm() + bodies[1].angular_velocity.norm(), 1e-12);
    EXPECT_GE(c.redundant_systems, 1u);  // a redundant contact set, solved: not counted as singular
    EXPECT_EQ(c.singular_systems, 0u);
    EXPECT_EQ(c.nan_caught, 0u);
  }
}

// Islands go to the resolver's lanes by a body of theirs, not by their place in the list: the pyramid K =
// 20 resolved again after a new island appeared before it (two spheres far away, one falling onto the
// other, whose contact is listed first) finds its cached symbolic analysis (dealt by index, it moved to
// the next lane, which had none), and its bodies get the same velocities, to the bit, as without the
// new island.
TEST(LedasSystems, AnIslandKeepsItsAnalysisWhenAnotherAppearsBeforeIt) {
  const std::vector<RigidBody> pyramid = pyramid_of(20);
  LedasSettings settings = touching_start();
  settings.solver.dense_limit = 8;
  LedasResolver resolver(settings);
  std::vector<RigidBody> alone = pyramid;
  std::vector<Contact> contacts = sphere_contacts(alone);
  resolve(resolver, alone, contacts);
  ASSERT_GT(resolver.last_stats().velocity.symbolic_analyses, 0u);

  std::vector<RigidBody> bodies = pyramid;
  const auto sphere = std::find_if(pyramid.begin(), pyramid.end(), [](const RigidBody& b) {
    return !b.fixed && std::holds_alternative<Sphere>(b.shape);
  });
  ASSERT_NE(sphere, pyramid.end());
  const double r = std::get<Sphere>(sphere->shape).radius;
  RigidBody low = *sphere, high = *sphere;
  low.position = Vec3(1000.0, 0.0, 500.0);
  low.velocity = Vec3::Zero();
  high.position = low.position + Vec3(0.0, 0.0, 2.0 * r);
  high.velocity = Vec3(0.0, 0.0, -1.0);
  bodies.push_back(low);
  bodies.push_back(high);
  const auto new_body = static_cast<BodyIndex>(pyramid.size());
  contacts = sphere_contacts(bodies);
  std::stable_partition(contacts.begin(), contacts.end(), [&](const Contact& c) { return c.a >= new_body; });
  ASSERT_EQ(contacts.front().a, new_body);
  resolve(resolver, bodies, contacts);
  EXPECT_EQ(resolver.last_stats().velocity.symbolic_analyses, 0u);
  EXPECT_GT(resolver.last_stats().velocity.symbolic_reused, 0u);
  for (std::size_t i = 0; i < pyramid.size(); ++i) {
    EXPECT_EQ(bodies[i].velocity, alone[i].velocity) << "body " << i;
    EXPECT_EQ(bodies[i].angular_velocity, alone[i].angular_velocity) << "body " << i;
  }
  // The new pair: a head-on impact of equal masses with e = 0 (the pyramid's), 0.5 m/s each after it.
  EXPECT_NEAR(bodies[new_body].velocity.z(), -0.5, 1e-12);
  EXPECT_NEAR(bodies[new_body + 1].velocity.z(), -0.5, 1e-12);
}

// Pyramid K = 20 (rank-deficient: 590 contacts on 420 in-plane degrees of freedom), started with every
// touching contact so that the search meets the redundant rows, with and without the minimum-norm polish
// of the complementary mode (tried on final systems of at most dense_limit rows: 100000 vs 8): the same
// impulses and velocities (1e-9) — the proximal iteration's split among redundant contacts stays at the
// minimum-norm one; resolving the same contact graph again reuses every symbolic analysis.
TEST(LedasSystems, SparseAndDensePathsAgree) {
  const std::vector<RigidBody> pyramid = pyramid_of(20);
  LedasSettings sparse = touching_start(), dense = sparse;
  sparse.solver.dense_limit = 8;
  dense.solver.dense_limit = 100000;
  const Outcome a = run(pyramid, sparse), b = run(pyramid, dense);
  EXPECT_GT(a.stats.velocity.sparse, 0u);
  EXPECT_EQ(a.stats.velocity.polished, 0u);
  EXPECT_GE(a.stats.velocity.singular, 1u);
  ASSERT_EQ(a.contacts.size(), b.contacts.size());
  for (std::size_t k = 0; k < a.contacts.size(); ++k) EXPECT_NEAR(a.contacts[k].impulse, b.contacts[k].impulse, 1e-9);
  for (std::size_t i = 0; i < a.bodies.size(); ++i) EXPECT_LT((a.bodies[i].velocity - b.bodies[i].velocity).norm(), 1e-9);
  // The same contact graph again: the sparse symbolic analyses are reused, none is recomputed.
  LedasResolver again(sparse);
  std::vector<RigidBody> bodies = pyramid;
  std::vector<Contact> contacts = sphere_contacts(bodies);
  resolve(again, bodies, contacts);
  bodies = pyramid;
  resolve(again, bodies, contacts);
  EXPECT_GT(again.last_stats().velocity.symbolic_reused, 0u);
  EXPECT_EQ(again.last_stats().velocity.symbolic_analyses, 0u);
  std::printf("[ledas] pyramid K=20: %llu factorizations, %llu updates, %llu proximal solves, %llu symbolic analyses, "
              "%llu singular | with polish: %llu polished\n",
              (unsigned long long)a.stats.velocity.sparse, (unsigned long long)a.stats.velocity.updated,
              (unsigned long long)a.stats.velocity.proximal, (unsigned long long)a.stats.velocity.symbolic_analyses,
              (unsigned long long)a.stats.velocity.singular, (unsigned long long)b.stats.velocity.polished);
}

// Pyramid K = 20, started with every touching contact (so the search must release the 190 horizontal
// ones), with the active-set search shift (search_regularization 1e-3, the default) and without it (the
// tiny shift throughout): the velocities after the impact are unique, so they agree (1e-9), and so do
// the impulses here (the final free set has no redundant rows: 400 rows on 420 degrees of freedom); the
// search finds that set in at most 4 factorizations (2 here; 8 iterations and 4 factorizations without
// it).
TEST(LedasSystems, SearchShiftKeepsTheAnswer) {
  const std::vector<RigidBody> pyramid = pyramid_of(20);
  LedasSettings searched = touching_start(), plain = searched;
  plain.solver.search_regularization = 0.0;
  const Outcome a = run(pyramid, searched), b = run(pyramid, plain);
  EXPECT_EQ(a.counters.non_converged, 0u);
  EXPECT_EQ(b.counters.non_converged, 0u);
  EXPECT_LE(a.counters.residual, 1e-9);
  EXPECT_LE(a.counters.complementarity_error, 1e-9);
  EXPECT_LE(a.stats.velocity.sparse, 4u);
  EXPECT_GT(a.stats.velocity.refinements, 0u);
  ASSERT_EQ(a.contacts.size(), b.contacts.size());
  for (std::size_t k = 0; k < a.contacts.size(); ++k) EXPECT_NEAR(a.contacts[k].impulse, b.contacts[k].impulse, 1e-9);
  for (std::size_t i = 0; i < a.bodies.size(); ++i) EXPECT_LT((a.bodies[i].velocity - b.bodies[i].velocity).norm(), 1e-9);
  std::printf("[ledas] pyramid K=20, search shift: %llu iterations, %llu factorizations, %llu refinement steps | "
              "without: %llu iterations, %llu factorizations\n",
              (unsigned long long)a.stats.velocity.iterations, (unsigned long long)a.stats.velocity.sparse,
              (unsigned long long)a.stats.velocity.refinements, (unsigned long long)b.stats.velocity.iterations,
              (unsigned long long)b.stats.velocity.sparse);
}

// Pyramid K = 50 (3 725 contacts) started with every touching contact, where the search shift's
// preconditioner would need many conjugate-gradient steps (19 at K = 100, 12 here): the refinement
// refactors at a smaller shift once it predicts that cheaper. The answer is unique in the velocities, so
// with and without that switch they agree to 1e-9 m/s; both are exact (residual and complementarity
// error ≤ 1e-9), and the sharpened run takes fewer steps.
TEST(LedasSystems, SharpenedRefinementKeepsTheAnswerInFewerSteps) {
  const std::vector<RigidBody> pyramid = pyramid_of(50);
  LedasSettings sharpened = touching_start(), plain = sharpened;
  plain.solver.sharpen_refinement = false;
  const Outcome a = run(pyramid, sharpened), b = run(pyramid, plain);
  expect_same_exact_answer(a, b);
  EXPECT_GE(a.stats.velocity.sharpened, 1u);
  EXPECT_EQ(b.stats.velocity.sharpened, 0u);
  EXPECT_LT(a.stats.velocity.refinements, b.stats.velocity.refinements);
  std::printf("[ledas] pyramid K=50: %llu refinement steps, %llu factorizations | without sharpening: %llu steps\n",
              (unsigned long long)a.stats.velocity.refinements, (unsigned long long)a.stats.velocity.sparse,
              (unsigned long long)b.stats.velocity.refinements);
}

// The start set (ledas.hpp, LedasStartSet): started with the impact's contacts, the pyramid's search has
// nothing to release (its 190 / 1 225 horizontal contacts run across the impact's front and start out)
// and solves in one factorization; started with every touching contact it releases them. The velocities
// after the impact are unique, so the two agree (1e-9 m/s); both are exact (residual and complementarity
// error ≤ 1e-9).
TEST(LedasSystems, ImpactStartSetKeepsThePyramidsAnswer) {
  for (int rows : {20, 50}) {
    const std::vector<RigidBody> pyramid = pyramid_of(rows);
    const Outcome a = run(pyramid, settings_for(LedasMode::complementary)), b = run(pyramid, touching_start());
    expect_same_exact_answer(a, b);
    EXPECT_EQ(a.stats.velocity.sparse, 1u);
    EXPECT_EQ(a.stats.velocity.released, 0u);
    EXPECT_GE(b.stats.velocity.released, static_cast<std::uint64_t>(rows * (rows - 1) / 2));
  }
}

// Closable gaps in the start set (complementary_impact.cpp): a column of 30 unit spheres (1 kg) on the
// ground, sphere i falling at 9.81 − 0.1 i mm/s, so the ground's contact approaches and every other
// separates at 0.1 mm/s, less than the ground takes out of the bottom sphere. With e = 0 everything
// stops (each sphere reaches the one below once that one has stopped), and the contact under sphere i
// carries the momentum of sphere i and those above: Σ_{j≥i} (9.81 − 0.1 j) mm/s · 1 kg (analytic,
// 1e-12). Started with the touching contacts alone, the search adds one sphere per iteration (30
// iterations); with the impact's start set the first solve has them all (one iteration). Same answer.
TEST(LedasSystems, ImpactStartSetTakesTheGapsTheImpactCloses) {
  constexpr int kCount = 30;
  const auto fall = [](int i) { return 9.81e-3 - 1e-4 * i; };
  std::vector<RigidBody> column;
  for (int i = 0; i < kCount; ++i) column.push_back(sphere(0.5, 1.0, {0, 0, 0.5 + i * (1.0 - 1e-7)}, {0, 0, -fall(i)}));
  column.push_back(ground_plane());
  const Outcome a = run(column, settings_for(LedasMode::complementary)), b = run(column, touching_start());
  expect_same_exact_answer(a, b);
  for (const Outcome* o : {&a, &b}) {
    for (int i = 0; i < kCount; ++i) EXPECT_LT(o->bodies[static_cast<std::size_t>(i)].velocity.norm(), 1e-12) << i;
    for (const Contact& c : o->contacts) {
      const int lower = c.b == kCount ? 0 : static_cast<int>(c.b);  // the sphere above the contact
      double carried = 0.0;
      for (int j = lower; j < kCount; ++j) carried += fall(j);
      EXPECT_NEAR(c.impulse, carried, 1e-12) << "contact under sphere " << lower;
    }
  }
  EXPECT_EQ(a.stats.velocity.iterations, 1u);
  EXPECT_EQ(b.stats.velocity.iterations, static_cast<std::uint64_t>(kCount));
}

// A contact across the front that must push: P → L | R ← Q, four touching unit spheres in a line, the
// ends moving inward at 1 m/s, e = 0. L and R are both struck (the same distance from the impact), so
// L–R starts out of the impact's start set; the first solve leaves them approaching at 2 m/s and the
// search adds it. Everything stops (momentum 0, every contact pushing: analytic), each contact's
// impulse 1 N·s (1e-12).
TEST(LedasSystems, ImpactStartSetAddsAContactAcrossTheFront) {
  std::vector<RigidBody> bodies{sphere(0.5, 1, {0, 0, 0}, {1, 0, 0}), sphere(0.5, 1, {1, 0, 0}), sphere(0.5, 1, {2, 0, 0}),
                                sphere(0.5, 1, {3, 0, 0}, {-1, 0, 0})};
  std::vector<Contact> contacts = sphere_contacts(bodies);
  ASSERT_EQ(contacts.size(), 3u);
  LedasResolver resolver(settings_for(LedasMode::complementary));
  const ResolverCounters c = resolve(resolver, bodies, contacts);
  for (const RigidBody& b : bodies) EXPECT_LT(b.velocity.norm(), 1e-12);
  for (const Contact& k : contacts) EXPECT_NEAR(k.impulse, 1.0, 1e-12);
  EXPECT_GE(resolver.last_stats().velocity.added, 1u);
  EXPECT_EQ(c.non_converged, 0u);
}

// Random touching clusters: a hexagonal patch of 19 spheres with random masses, moving together, struck
// by two of its boundary spheres moving inward at random velocities (200 trials, e = 0 and 1). The
// impact's start set and every touching contact give the same velocities (1e-9 m/s), both exact.
TEST(LedasSystems, ImpactStartSetKeepsTheAnswerOnRandomClusters) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int added = 0, released = 0, iterations[2] = {0, 0}, factorizations[2] = {0, 0}, analyses[2] = {0, 0};
  for (int trial = 0; trial < 200; ++trial) {
    const double e = trial % 2 == 0 ? 0.0 : 1.0;
    const Vec3 drift(u(rng), u(rng), 0.0);
    std::vector<RigidBody> bodies;
    for (int q = -2; q <= 2; ++q)
      for (int r = -2; r <= 2; ++r) {
        if (std::abs(q + r) > 2) continue;
        const Vec3 x(q + 0.5 * r, r * std::sqrt(3.0) / 2.0, 0.0);
        bodies.push_back(sphere(0.5, 1.5 + u(rng), x, drift, e));
      }
    ASSERT_EQ(bodies.size(), 19u);
    for (int strikers = 0; strikers < 2; ++strikers) {
      RigidBody* outer = nullptr;
      while (outer == nullptr || outer->position.norm() < 1.5) outer = &bodies[static_cast<std::size_t>(rng() % bodies.size())];
      const Vec3 inward = -outer->position.normalized();
      outer->velocity = drift + (1.0 + u(rng)) * inward + 0.5 * u(rng) * Vec3(-inward.y(), inward.x(), 0.0);
    }
    Outcome out[2];
    for (int k = 0; k < 2; ++k) {
      LedasSettings settings = settings_for(LedasMode::complementary);
      settings.start_set = k == 0 ? LedasStartSet::impact : LedasStartSet::touching;
      out[k] = run(bodies, settings);
      EXPECT_EQ(out[k].counters.non_converged, 0u);
      EXPECT_LE(out[k].counters.residual, 1e-9);
    }
    for (int k = 0; k < 2; ++k) {
      iterations[k] += static_cast<int>(out[k].stats.velocity.iterations);
      factorizations[k] += static_cast<int>(out[k].stats.velocity.sparse);
      analyses[k] += static_cast<int>(out[k].stats.velocity.symbolic_analyses);
    }
    added += static_cast<int>(out[0].stats.velocity.added);
    released += static_cast<int>(out[1].stats.velocity.released);
    for (std::size_t i = 0; i < bodies.size(); ++i)
      EXPECT_LT((out[0].bodies[i].velocity - out[1].bodies[i].velocity).norm(), 1e-9) << "trial " << trial;
  }
  std::printf("[ledas] 200 random struck clusters: impact start set %d iterations, %d factorizations, %d symbolic "
              "analyses, %d rows added | touching start set %d iterations, %d factorizations, %d analyses, %d rows "
              "released\n",
              iterations[0], factorizations[0], analyses[0], added, iterations[1], factorizations[1], analyses[1], released);
}

}  // namespace
}  // namespace impetus
