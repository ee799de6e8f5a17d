#include "impetus/detection/fcl/fcl_detector.hpp"

#include "impetus/detection/fcl/analytic.hpp"
#include "impetus/detection/fcl/broadphase.hpp"
#include "impetus/detection/fcl/fcl_queries.hpp"
#include "impetus/detection/fcl/manifold.hpp"
#include "impetus/detection/fcl/mesh_contacts.hpp"
#include "impetus/detection/fcl/shapes.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <unordered_map>
#include <chrono>
#include <deque>
#include <cmath>
#include <exception>
#include <map>
#include <string>
#include <tuple>
#include <utility>

namespace impetus {

using namespace collision;

namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

std::uint64_t pair_key(BodyIndex a, BodyIndex b) { return (static_cast<std::uint64_t>(a) << 32) | b; }

// Sleeping islands: a pair of two quiet bodies (asleep, or fixed with no motion) can change nothing and
// is not tested. Any other body touching a sleeping one is reported, so the world can wake it.
bool quiet(const RigidBody& body) { return body.asleep || (body.fixed && body.motion == PrescribedMotion::none); }

bool is_rounded(ShapeKind k) { return k == ShapeKind::sphere || k == ShapeKind::capsule; }

bool overlap(const Aabb& x, const Aabb& y) {
  return (x.min.array() <= y.max.array()).all() && (y.min.array() <= x.max.array()).all();
}

Aabb grown(const Aabb& box, double by) { return {(box.min.array() - by).matrix(), (box.max.array() + by).matrix()}; }

/// Why a body's primitive cannot be used ("" if it can).
std::string size_problem(const ShapeGeometry& g) {
  auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
  switch (g.kind) {
    case ShapeKind::sphere: return positive(g.radius) ? "" : "sphere radius must be positive";
    case ShapeKind::box: return positive(g.half_extents.minCoeff()) ? "" : "box sizes must be positive";
    case ShapeKind::capsule:
    case ShapeKind::cylinder:
      return positive(g.radius) && std::isfinite(g.half_length) && g.half_length >= 0.0
                 ? ""
                 : "radius must be positive and length non-negative";
    case ShapeKind::plane: return g.plane_normal.allFinite() ? "" : "plane normal must be non-zero";
    default: return "";
  }
}

/// The distance from the body's centre of mass to its nearest surface (m): how far the body can be
/// overlapped before a contact's normal may point out the wrong side. Half the thinnest dimension of a
/// primitive; the nearest face of a convex hull; 0 for a triangle mesh (its plates may be thin anywhere);
/// infinite for a plane (a half-space has no far side).
double inner_radius(const ShapeGeometry& g) {
  switch (g.kind) {
    case ShapeKind::sphere:
    case ShapeKind::capsule: return g.radius;
    case ShapeKind::cylinder: return std::min(g.radius, g.half_length);
    case ShapeKind::box: return g.half_extents.minCoeff();
    case ShapeKind::plane: return std::numeric_limits<double>::infinity();
    case ShapeKind::triangles: return 0.0;
    case ShapeKind::convex: {
      double nearest = std::numeric_limits<double>::infinity();
      for (std::size_t t = 0; t < g.mesh->triangles.size(); ++t)
        nearest = std::min(nearest, g.mesh->triangle_normals[t].dot(g.mesh->vertices[g.mesh->triangles[t][0]]));
      return std::max(0.0, nearest);
    }
  }
  return 0.0;
}

/// How far a body's surface can move in one step (m): translation plus rotation about the centre of mass
/// (|ω| times the bounding radius), an upper bound.
double reach(const RigidBody& body, double size, double dt) {
  return dt * (body.velocity.norm() + body.angular_velocity.norm() * size);
}

/// Conservative advancement's iteration budget per speculative pair: past it the pair keeps its
/// speculative contacts (the safe side: a possible impact is never dropped).
constexpr int kAdvanceIterations = 16;

/// `body` (placed as `now`) moved on by `tau` seconds at its current velocities.
Placed advanced(const Placed& now, const RigidBody& body, double tau) {
  Placed out = now;
  out.x += tau * body.velocity;
  const double turn = body.angular_velocity.norm() * tau;
  if (turn > 0.0) out.R = Eigen::AngleAxisd(turn, body.angular_velocity.normalized()).toRotationMatrix() * now.R;
  return out;
}

}  // namespace

struct FclDetector::Impl {
  struct Body {
    ShapeGeometry geometry;
    FclShapePtr fcl;  // null for planes
    bool fixed = false;
    std::uint32_t group = 0, mask = 0;
    double inner = 0.0;  // inner_radius(geometry)
  };

  FclDetectorSettings settings;
  PairSettings pair;
  std::vector<Body> bodies;
  std::vector<BodyIndex> movable, planes;
  std::vector<std::uint64_t> excluded;  // sorted pair keys
  std::vector<Aabb> boxes;              // tight world boxes grown by half the margin (at rest: once)
  std::vector<double> reach;            // how far each body's surface can move this step (m; 0 if at rest)
  double thinnest = 0.0;                // the smallest inner radius of any body (m)
  Broadphase broadphase;
  std::vector<BodyPair> pairs;
  // The narrowphase runs on consecutive runs of kPairsPerChunk pairs in parallel; a chunk's scratch,
  // contacts and counts are its own, and the chunks are joined in pair order, so the list is the same for
  // every thread count. The scratch is the chunk's, not the thread's: the same pairs find buffers of the
  // sizes they needed at the last step, whichever thread runs them, so a stable scene allocates nothing.
  struct Worker {
    // Room for the most points a pair of boxes gives before its manifold is reduced (a face clipped by a
    // face: 4 + 4), so that a stack whose faces slide a little against each other, giving 4 points one
    // step and 5 the next, does not grow the buffers in its steady state.
    static constexpr std::size_t kBoxPairPoints = 8;
    Worker() {
      points.reserve(kBoxPairPoints);
      speculative_points.reserve(kBoxPairPoints);
    }
    PairSettings pair;
    std::vector<ManifoldPoint> points;
    std::vector<ManifoldPoint> speculative_points;  // a speculative pair's contacts while it is advanced
    MeshContacts mesh;
    std::uint64_t fcl_failures = 0;
  };
  struct Chunk {
    Worker scratch;
    std::vector<Contact> contacts;
    std::uint64_t calls = 0, dropped = 0, speculative = 0;
  };
  static constexpr std::size_t kPairsPerChunk = 32;
  std::deque<Chunk> chunks;  // a deque: grown in place (a Chunk does not move)
  FclDetectorProfile profile;
  bool ready = false;

  using MeshCache =
      std::map<std::pair<const TriangleMesh*, bool>, std::pair<std::shared_ptr<const MeshData>, FclShapePtr>>;

  Placed placed(const RigidBody& body, BodyIndex i) const {
    return {&bodies[i].geometry, body.position, body.rotation};
  }
  ModuleStatus add_body(const RigidBody& body, BodyIndex index, MeshCache& meshes);
  bool filtered(BodyIndex a, BodyIndex b) const;
  void narrow_pair(Worker& w, BodyIndex a, BodyIndex b, std::span<const RigidBody> state, double dt,
                   bool speculative, Chunk& out);
  void narrow(Worker& w, const Placed& a, const Placed& b, const Body& ba, const Body& bb);
  bool meets_within_step(Worker& w, const Placed& a, const Placed& b, const RigidBody& ra, const RigidBody& rb,
                         BodyIndex ia, BodyIndex ib, double dt, double closing);
  std::uint64_t finish_pair(Worker& w, BodyIndex a, BodyIndex b, double scale, std::vector<Contact>& contacts);
};

bool FclDetector::Impl::filtered(BodyIndex a, BodyIndex b) const {
  const Body &ba = bodies[a], &bb = bodies[b];
  if (ba.fixed && bb.fixed) return true;
  if (!(ba.group & bb.mask) || !(bb.group & ba.mask)) return true;  // both ways must agree
  return std::binary_search(excluded.begin(), excluded.end(), pair_key(a, b));
}

FclDetector::FclDetector(const ModuleOptions& options) : FclDetector(FclDetectorSettings::from_options(options)) {}

FclDetector::FclDetector(const FclDetectorSettings& settings) : impl_(std::make_unique<Impl>()) {
  impl_->settings = settings;
  impl_->pair.margin = settings.margin;
}

FclDetector::~FclDetector() = default;

const FclDetectorSettings& FclDetector::settings() const { return impl_->settings; }
const FclDetectorProfile& FclDetector::last_profile() const { return impl_->profile; }

ModuleStatus FclDetector::Impl::add_body(const RigidBody& body, BodyIndex index, MeshCache& meshes) {
  const auto fail = [&](const std::string& why) {
    return ModuleStatus::failure("body '" + body.name + "' (" + shape_kind_name(body.shape) + "): " + why);
  };
  Body entry;
  entry.fixed = body.fixed;
  entry.group = body.collision_group;
  entry.mask = body.collision_mask;
  try {
    if (const auto* mesh = std::get_if<MeshShape>(&body.shape)) {
      // Convex collision uses the hull the asset pipeline computed, when there is one.
      const bool convex = mesh->collision == MeshCollision::convex;
      const TriangleMesh* geometry = mesh->collision_mesh();
      if (!geometry) return fail("mesh '" + mesh->file.string() + "' has no geometry (it was not imported)");
      auto& cached = meshes[{geometry, convex}];
      if (!cached.first) {
        if (const std::string why = mesh_problem(*geometry, convex); !why.empty())
          return fail("mesh '" + mesh->file.string() + "' " + why);
        cached.first = make_mesh_data(*geometry, convex);
        cached.second = make_fcl_shape(make_geometry(body.shape, cached.first));
      }
      entry.geometry = make_geometry(body.shape, cached.first);
      entry.fcl = cached.second;
    } else {
      entry.geometry = make_geometry(body.shape, nullptr);
      if (const std::string why = size_problem(entry.geometry); !why.empty()) return fail(why);
      if (entry.geometry.kind == ShapeKind::plane && !body.fixed) return fail("a plane must be fixed");
      if (entry.geometry.kind != ShapeKind::plane) entry.fcl = make_fcl_shape(entry.geometry);
    }
  } catch (const std::exception& e) {
    return fail(std::string("FCL rejected its geometry: ") + e.what());
  }
  if (!body.position.allFinite() || !body.rotation.allFinite()) return fail("its pose is not finite");
  entry.inner = inner_radius(entry.geometry);
  bodies.push_back(std::move(entry));
  if (bodies.back().geometry.kind == ShapeKind::plane) {
    planes.push_back(index);  // planes never enter the broadphase: they are tested against the boxes directly
    return ModuleStatus::success();
  }
  // A fixed body that moves (prescribed motion) has its box refreshed like a movable body's; it still
  // never pairs with another fixed body (filtered()).
  const bool moves = !body.fixed || body.motion == PrescribedMotion::moving;
  if (moves) movable.push_back(index);
  boxes[index] = grown(world_aabb(placed(body, index)), 0.5 * settings.margin);
  broadphase.add(index, !moves, boxes[index]);
  return ModuleStatus::success();
}

ModuleStatus FclDetector::set_bodies(std::span<const RigidBody> bodies, std::span<const BodyPair> excluded) noexcept {
  Impl& s = *impl_;
  s.ready = false;
  s.bodies.clear();
  s.movable.clear();
  s.planes.clear();
  s.broadphase.clear();
  s.boxes.assign(bodies.size(), Aabb{Vec3::Zero(), Vec3::Zero()});
  s.reach.assign(bodies.size(), 0.0);
  try {
    Impl::MeshCache meshes;  // bodies sharing one mesh share its derived data and FCL geometry
    for (std::size_t i = 0; i < bodies.size(); ++i)
      if (ModuleStatus status = s.add_body(bodies[i], static_cast<BodyIndex>(i), meshes); !status) return status;
    s.broadphase.finish();
    s.thinnest = std::numeric_limits<double>::infinity();
    for (const Impl::Body& b : s.bodies) s.thinnest = std::min(s.thinnest, b.inner);
    s.excluded.clear();
    for (const BodyPair& p : excluded)
      s.excluded.push_back(pair_key(std::min(p.first, p.second), std::max(p.first, p.second)));
    std::sort(s.excluded.begin(), s.excluded.end());
  } catch (const std::exception& e) {  // allocation failure
    return ModuleStatus::failure(std::string("detector set-up failed: ") + e.what());
  }
  s.ready = true;
  return ModuleStatus::success();
}

void FclDetector::detect(std::span<const RigidBody> bodies, const StepContext& ctx, std::vector<Contact>& contacts,
                         DetectorCounters& counters) noexcept {
  Impl& s = *impl_;
  contacts.clear();
  s.profile = FclDetectorProfile{};
  if (!s.ready || bodies.size() != s.bodies.size()) return;  // set_bodies() was not called for these bodies
  const double margin = s.settings.margin;
  const auto start = Clock::now();

  // 1. Broadphase: refresh the movable bodies' boxes (grown by half the margin each, so a gap up to the
  // margin still overlaps; a fast body's box also by its reach over the step, so whatever it can meet is
  // a candidate), collect the pairs whose boxes overlap (the grid), test the planes, keep the pairs whose
  // exact boxes overlap and that pass the filters, sort.
  const bool speculative = s.settings.speculative && std::isfinite(ctx.dt) && ctx.dt > 0.0;
  s.pairs.clear();
  // A scene asleep to the last body (and no fixed body moving) has nothing to detect.
  if (std::all_of(s.movable.begin(), s.movable.end(), [&](BodyIndex i) { return quiet(bodies[i]); }) &&
      std::all_of(s.planes.begin(), s.planes.end(), [&](BodyIndex i) { return quiet(bodies[i]); })) {
    s.profile.broadphase = seconds(start, Clock::now());
    return;
  }
  // A box grows by the body's reach only where a pair with it could need the look-ahead below (its
  // closing, at most the two reaches, beyond the margin and half the thinner inner radius: so the faster
  // body's reach beyond half the margin and a quarter of that radius). A slower partner's own reach, below
  // its threshold, is then missed at most: never enough to pass through anything.
  for (BodyIndex i : s.movable) {
    s.reach[i] = 0.0;
    if (bodies[i].asleep) continue;  // it has not moved since it fell asleep
    const Placed body = s.placed(bodies[i], i);
    if (!body.x.allFinite() || !body.R.allFinite()) continue;  // the world rolls such a state back
    double grow = 0.5 * margin;
    if (speculative) {
      s.reach[i] = reach(bodies[i], body.size(), ctx.dt);
      if (s.reach[i] > 0.5 * margin && s.reach[i] > 0.25 * std::min(s.bodies[i].inner, s.thinnest))
        grow += s.reach[i];
    }
    s.boxes[i] = grown(world_aabb(body), grow);
    s.broadphase.move(i, s.boxes[i]);
  }
  // Candidate pairs are bounded by work: many bodies generated at one point would give n²/2 of them (and
  // up to four contacts each). Past the limit the detection is refused, naming the most crowded body.
  const std::size_t pair_limit = s.settings.max_pairs_per_body == 0
                                     ? std::numeric_limits<std::size_t>::max()
                                     : std::max<std::size_t>(FclDetectorSettings::kMinPairLimit,
                                                             static_cast<std::size_t>(s.settings.max_pairs_per_body) *
                                                                 s.movable.size());
  if (!s.broadphase.collect(s.pairs, pair_limit)) {
    std::unordered_map<BodyIndex, std::uint64_t> count;
    for (const auto& [a, b] : s.pairs) ++count[a], ++count[b];
    std::pair<BodyIndex, std::uint64_t> crowded{0, 0};
    for (const auto& [body, n] : count)
      if (n > crowded.second || (n == crowded.second && body < crowded.first)) crowded = {body, n};
    counters.pairs_tested += s.pairs.size();
    counters.pair_limit = pair_limit;
    counters.crowded_body = crowded.first;
    counters.crowded_pairs = crowded.second;
    s.pairs.clear();
    s.profile.broadphase = seconds(start, Clock::now());
    return;
  }
  for (BodyIndex p : s.planes) {
    const WorldPlane plane = world_plane(s.placed(bodies[p], p));
    if (speculative) s.reach[p] = ctx.dt * bodies[p].velocity.norm();  // a moving plane
    const bool plane_quiet = quiet(bodies[p]);
    for (BodyIndex i : s.movable) {
      if (plane_quiet && quiet(bodies[i])) continue;
      const Vec3 center = 0.5 * (s.boxes[i].min + s.boxes[i].max), half = 0.5 * (s.boxes[i].max - s.boxes[i].min);
      if (plane.normal.dot(center) - plane.normal.cwiseAbs().dot(half) <= plane.offset + 0.5 * margin)
        s.pairs.emplace_back(std::min(i, p), std::max(i, p));
    }
  }
  counters.pairs_tested += s.pairs.size();
  std::erase_if(s.pairs, [&](const BodyPair& p) {
    const bool planar =
        s.bodies[p.first].geometry.kind == ShapeKind::plane || s.bodies[p.second].geometry.kind == ShapeKind::plane;
    return (!planar && !overlap(s.boxes[p.first], s.boxes[p.second])) || s.filtered(p.first, p.second) ||
           (quiet(bodies[p.first]) && quiet(bodies[p.second]));
  });
  std::sort(s.pairs.begin(), s.pairs.end());
  const auto broad_end = Clock::now();

  // 2. Narrowphase: one manifold per pair, in pair order (so the list comes out sorted). A pair that can
  // close by more than the margin and more than half the thinner body's inner radius in one step (it
  // could pass through, or so deep into the other that the normal flips) is searched with its margin
  // grown by that closing distance: speculative contacts, with depth = −gap, which the resolvers let
  // close exactly at the end of the step (detection/fcl/README.md, "Fast bodies").
  const std::size_t chunk_count = (s.pairs.size() + Impl::kPairsPerChunk - 1) / Impl::kPairsPerChunk;
  if (s.chunks.size() < chunk_count) s.chunks.resize(chunk_count);
  const auto run_chunks = [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t c = range.begin(); c != range.end(); ++c) {
      Impl::Chunk& out = s.chunks[c];
      Impl::Worker& w = out.scratch;
      out.contacts.clear();
      out.calls = out.dropped = out.speculative = 0;
      const std::size_t end = std::min(s.pairs.size(), (c + 1) * Impl::kPairsPerChunk);
      for (std::size_t k = c * Impl::kPairsPerChunk; k < end; ++k)
        s.narrow_pair(w, s.pairs[k].first, s.pairs[k].second, bodies, ctx.dt, speculative, out);
    }
  };
  if (chunk_count > 1) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunk_count, 1), run_chunks);
  else run_chunks(tbb::blocked_range<std::size_t>(0, chunk_count, 1));
  for (std::size_t c = 0; c < chunk_count; ++c) {
    const Impl::Chunk& out = s.chunks[c];
    contacts.insert(contacts.end(), out.contacts.begin(), out.contacts.end());
    counters.narrowphase_calls += out.calls;
    counters.contacts_dropped += out.dropped;
    counters.speculative_pairs += out.speculative;
  }
  for (std::size_t c = 0; c < chunk_count; ++c) {
    s.profile.fcl_failures += s.chunks[c].scratch.fcl_failures;
    s.chunks[c].scratch.fcl_failures = 0;
  }
  counters.contacts += contacts.size();
  const auto end = Clock::now();
  s.profile.broadphase = seconds(start, broad_end);
  s.profile.narrowphase = seconds(broad_end, end);
}

// One pair's manifold into `out` (the narrowphase of detect(), on a worker's scratch).
void FclDetector::Impl::narrow_pair(Worker& w, BodyIndex a, BodyIndex b, std::span<const RigidBody> state,
                                    double dt, bool speculative, Chunk& out) {
  const double margin = settings.margin;
  ++out.calls;
  const Placed pa = placed(state[a], a), pb = placed(state[b], b);
  if (!pa.x.allFinite() || !pa.R.allFinite() || !pb.x.allFinite() || !pb.R.allFinite()) return;
  w.points.clear();
  w.pair = pair;
  bool speculative_pair = false;
  double closing = 0.0;  // how far the pair's surfaces can close within the step, at most (m)
  // The two reaches bound the closing: most pairs are ruled out without the exact bound.
  const double thinner = 0.5 * std::min(bodies[a].inner, bodies[b].inner);
  if (speculative && reach[a] + reach[b] > margin && reach[a] + reach[b] > thinner) {
    const RigidBody &ra = state[a], &rb = state[b];
    closing = dt * ((rb.velocity - ra.velocity).norm() + ra.angular_velocity.norm() * pa.size() +
                    rb.angular_velocity.norm() * pb.size());
    if (closing > margin && closing > thinner && std::isfinite(closing)) {
      w.pair.margin = margin + closing;
      speculative_pair = true;
      ++out.speculative;
    }
  }
  narrow(w, pa, pb, bodies[a], bodies[b]);
  // Speculative contacts are kept only if the bodies really meet within the step: a ball flying past
  // an edge has a closest point ahead of it, but never reaches it.
  if (speculative_pair && !w.points.empty() &&
      !meets_within_step(w, pa, pb, state[a], state[b], a, b, dt, closing))
    w.points.clear();
  const double scale = pa.kind() == ShapeKind::plane   ? pb.size()
                       : pb.kind() == ShapeKind::plane ? pa.size()
                                                       : std::min(pa.size(), pb.size());
  out.dropped += finish_pair(w, a, b, scale, out.contacts);
}

void FclDetector::Impl::narrow(Worker& w, const Placed& a, const Placed& b, const Body& ba, const Body& bb) {
  const ShapeKind ka = a.kind(), kb = b.kind();
  if (ka == ShapeKind::plane || kb == ShapeKind::plane) return halfspace_contacts(a, b, w.pair, w.points);
  if (ka == ShapeKind::triangles && kb == ShapeKind::triangles)
    return w.mesh.mesh_vs_mesh(a, *ba.fcl, b, *bb.fcl, w.pair, w.points, w.fcl_failures);
  if (ka == ShapeKind::triangles)
    return w.mesh.mesh_vs_convex(a, *ba.fcl, b, *bb.fcl, true, w.pair, w.points, w.fcl_failures);
  if (kb == ShapeKind::triangles)
    return w.mesh.mesh_vs_convex(b, *bb.fcl, a, *ba.fcl, false, w.pair, w.points, w.fcl_failures);
  if (is_rounded(ka) && is_rounded(kb)) return rounded_contacts(a, b, w.pair, w.points);
  if ((ka == ShapeKind::sphere && kb == ShapeKind::box) || (ka == ShapeKind::box && kb == ShapeKind::sphere))
    return sphere_box_contacts(a, b, w.pair, w.points);
  const bool capsule_box =
      (ka == ShapeKind::capsule && kb == ShapeKind::box) || (ka == ShapeKind::box && kb == ShapeKind::capsule);
  if ((ka == ShapeKind::box && kb == ShapeKind::box) || capsule_box) {
    const AxisResult axis = capsule_box ? capsule_box_axis(a, b) : box_box_axis(a, b);
    if (axis.overlap >= -w.pair.margin) convex_contacts(a, b, axis, w.pair, w.points);
    return;
  }
  // Generic convex pair: FCL's signed distance gives the gap or the penetration with witness points;
  // its normal is then checked and sharpened against the shapes' own face normals.
  const SignedDistance sd = fcl_signed_distance(*ba.fcl, a, *bb.fcl, b);
  if (!sd.ok) ++w.fcl_failures;
  if (sd.ok && sd.distance > w.pair.margin) return;
  const double eps = 1e-12 * (a.size() + b.size());
  Vec3 fcl_normal = Vec3::Zero();
  if (sd.ok && sd.distance > eps) fcl_normal = (sd.on_b - sd.on_a).normalized();
  else if (sd.ok && sd.distance < -eps) fcl_normal = (sd.on_a - sd.on_b).normalized();
  const Vec3 centers = b.x - a.x;
  const Vec3 hint = fcl_normal.allFinite() && !fcl_normal.isZero() ? fcl_normal
                    : centers.norm() > eps                         ? Vec3(centers.normalized())
                                                                   : Vec3(Vec3::UnitZ());
  SmallVec<Vec3, 64> candidates;
  candidate_axes(a, hint, b.x, candidates);
  candidate_axes(b, hint, a.x, candidates);
  candidates.push_back(hint);  // last: a face normal wins a tie
  const AxisResult axis =
      least_overlap_axis(a, b, {candidates.begin(), candidates.end()}, 1e-12 * (a.size() + b.size()));
  if (axis.valid && axis.overlap >= -w.pair.margin) convex_contacts(a, b, axis, w.pair, w.points);
}

// Conservative advancement over the step (the classic time-of-impact bound, as FCL's continuous
// collision and Mirtich's thesis use it): the bodies move on at their current velocities by the largest
// time their gap allows (the gap over a bound on how fast it can close: the relative velocity along the
// closest normal, plus |ω| times each bounding radius), until the gap is within the margin (they meet:
// true), the step is over, or nothing is left within the remaining look-ahead (they do not: false).
// Leaves w.points as they were on entry (the contacts now).
bool FclDetector::Impl::meets_within_step(Worker& w, const Placed& a, const Placed& b, const RigidBody& ra,
                                          const RigidBody& rb, BodyIndex ia, BodyIndex ib, double dt, double closing) {
  const double margin = settings.margin;
  const auto deepest = [](const std::vector<ManifoldPoint>& p) {
    return *std::max_element(p.begin(), p.end(),
                             [](const ManifoldPoint& l, const ManifoldPoint& r) { return l.depth < r.depth; });
  };
  if (-deepest(w.points).depth <= margin) return true;  // touching already
  w.speculative_points = w.points;
  const double spin = ra.angular_velocity.norm() * a.size() + rb.angular_velocity.norm() * b.size();
  const Vec3 dv = rb.velocity - ra.velocity;
  // Between convex shapes in translation the gap is a convex function of time, so its slope along the
  // closest normal bounds how fast it closes; a triangle mesh is many shapes, and another piece may be
  // closing faster, so there the whole relative speed is the bound.
  const bool convex = a.kind() != ShapeKind::triangles && b.kind() != ShapeKind::triangles;
  bool meets = true;  // undecided within the budget: keep the contacts
  double tau = 0.0;
  for (int iteration = 0; iteration < kAdvanceIterations; ++iteration) {
    if (w.points.empty()) {
      meets = false;  // nothing within the look-ahead left for the rest of the step
      break;
    }
    const ManifoldPoint closest = deepest(w.points);
    const double gap = -closest.depth;
    if (gap <= margin) break;
    const double rate = (convex ? std::abs(dv.dot(closest.normal)) : dv.norm()) + spin;
    if (!(rate > 0.0)) {  // the gap cannot close
      meets = false;
      break;
    }
    tau += (gap - 0.5 * margin) / rate;
    if (!(tau < dt)) {
      meets = false;
      break;
    }
    w.points.clear();
    w.pair.margin = margin + closing * (1.0 - tau / dt);
    narrow(w, advanced(a, ra, tau), advanced(b, rb, tau), bodies[ia], bodies[ib]);
  }
  w.points.swap(w.speculative_points);
  return meets;
}

std::uint64_t FclDetector::Impl::finish_pair(Worker& w, BodyIndex a, BodyIndex b, double scale,
                                            std::vector<Contact>& contacts) {
  std::uint64_t dropped = 0;
  // A NaN or zero normal never reaches a resolver.
  std::size_t kept = 0;
  for (std::size_t i = 0; i < w.points.size(); ++i) {
    ManifoldPoint p = w.points[i];
    const double len = p.normal.norm();
    if (!p.point.allFinite() || !std::isfinite(p.depth) || !std::isfinite(len) || len < 1e-9) {
      ++dropped;
      continue;
    }
    p.normal /= len;
    w.points[kept++] = p;
  }
  w.points.resize(kept);
  dropped += merge_duplicates(w.points, settings.merge_tolerance * scale);
  dropped += reduce_to_spanning(w.points, static_cast<std::size_t>(settings.max_contacts_per_pair));
  // Pairs come in (a, b) order; sorting each manifold by (feature, point) makes the whole list sorted
  // by (a, b, feature, point), independent of how the manifold was assembled.
  std::sort(w.points.begin(), w.points.end(), [](const ManifoldPoint& l, const ManifoldPoint& r) {
    return std::tie(l.feature, l.point.x(), l.point.y(), l.point.z()) <
           std::tie(r.feature, r.point.x(), r.point.y(), r.point.z());
  });
  for (const ManifoldPoint& p : w.points) contacts.push_back(Contact{a, b, p.point, p.normal, p.depth, p.feature, 0.0});
  return dropped;
}

}  // namespace impetus
