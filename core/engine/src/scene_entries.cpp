// `generators:` and `constraints:` entries: the ones that make bodies in bulk or refer to them by name.

#include "impetus/core/format.hpp"
#include "impetus/engine/generators.hpp"
#include "scene_internal.hpp"

#include <algorithm>
#include <climits>
#include <cmath>

namespace impetus::scene_detail {
namespace {

// The single entry of a one-key mapping such as `{pyramid: {...}}` or `{point_point: {...}}`.
const Fields::Entry& only_entry(const SceneReader& r, const Fields& f, const std::string& choices) {
  if (f.entries().size() != 1)
    r.fail(f.entries().empty() ? f.node() : f.entries()[1].key_node,
           f.context() + " expects exactly one of: " + choices);
  return f.entries().front();
}

int read_int(const SceneReader& r, const YAML::Node& node, const char* what) {
  return static_cast<int>(r.integer(node, what, INT_MIN, INT_MAX));
}

// Reads the optional keys shared by both generators into the params' fields.
template <typename Params>
void read_spheres(const SceneReader& r, const Fields& f, Params& p) {
  if (const YAML::Node* n = f.find("radius")) p.radius = r.number(*n, "radius");
  if (const YAML::Node* n = f.find("mass")) p.mass = r.number(*n, "mass");
  if (const YAML::Node* n = f.find("velocity")) p.velocity = r.vec3(*n, "velocity");
  if (const YAML::Node* n = f.find("restitution")) p.restitution = r.number(*n, "restitution");
  if (const YAML::Node* n = f.find("friction")) p.friction = r.number(*n, "friction");
  if (const YAML::Node* n = f.find("overlap")) p.overlap = r.number(*n, "overlap");
}

// Refuses a generator of `count` bodies that would take the scene past its limit (SceneLimits).
void check_room(const SceneReader& r, const YAML::Node& node, BodyRoom room, const char* kind, std::size_t count) {
  if (count > room.limit - std::min(room.used, room.limit))
    r.fail(node, "this " + std::string(kind) + " makes " + std::to_string(count) + " bodies, and with the " +
                     std::to_string(room.used) + " before it the scene would hold more than " +
                     std::to_string(room.limit) + " bodies (the limit)");
}

}  // namespace

std::vector<ReadBody> read_generator(const SceneReader& r, const YAML::Node& node, BodyRoom room) {
  const Fields entry(r, node, "generator", {"pyramid", "line"});
  const Fields::Entry& kind = only_entry(r, entry, "pyramid, line");
  std::vector<RigidBody> bodies;
  // Types are checked here, with locations; ranges by the generator itself, so they live in one place.
  if (kind.key == "pyramid") {
    const Fields f(r, kind.value, "pyramid",
                   {"rows", "radius", "mass", "velocity", "restitution", "friction", "overlap", "ground"});
    PyramidParams p;
    p.rows = read_int(r, f.require("rows"), "rows");
    read_spheres(r, f, p);
    if (const YAML::Node* n = f.find("ground")) p.ground = r.boolean(*n, "ground");
    try {
      check_room(r, *f.find("rows"), room, "pyramid", body_count(p));
      bodies = make_pyramid(p);
    } catch (const GeneratorError& e) {
      r.fail(f.find(e.field()) ? *f.find(e.field()) : kind.value, e.what());
    }
  } else {
    const Fields f(r, kind.value, "line", {"count", "radius", "mass", "wall", "velocity", "restitution", "friction",
                                                 "overlap"});
    LineParams p;
    p.count = read_int(r, f.require("count"), "count");
    read_spheres(r, f, p);
    if (const YAML::Node* n = f.find("wall")) p.wall = r.boolean(*n, "wall");
    try {
      check_room(r, *f.find("count"), room, "line", body_count(p));
      bodies = make_line(p);
    } catch (const GeneratorError& e) {
      r.fail(f.find(e.field()) ? *f.find(e.field()) : kind.value, e.what());
    }
  }
  std::vector<ReadBody> out;
  out.reserve(bodies.size());
  for (RigidBody& body : bodies) out.push_back({std::move(body), kind.key_node});
  return out;
}

namespace {

// What every constraint kind has: two different bodies, not both fixed, a level, and `collide`.
struct ConstraintEnds {
  BodyIndex a = 0, b = 0;
  ConstraintLevel level = ConstraintLevel::position;
  bool collide = false;
};

ConstraintEnds read_ends(const SceneReader& r, const Fields& f, const std::vector<RigidBody>& bodies,
                         const std::map<std::string, BodyIndex>& index_by_name) {
  const YAML::Node& names = f.require("bodies");
  if (!names.IsSequence() || names.size() != 2)
    r.fail(names, "'bodies' expects a list of two body names, got " + SceneReader::describe(names));
  BodyIndex index[2] = {0, 0};
  for (std::size_t i = 0; i < 2; ++i) {
    const std::string name = r.string(names[i], "bodies");
    const auto it = index_by_name.find(name);
    if (it == index_by_name.end()) r.fail(names[i], "no body named '" + name + "'");
    index[i] = it->second;
  }
  if (index[0] == index[1]) r.fail(names, "a constraint needs two different bodies, got '" + bodies[index[0]].name + "' twice");
  const RigidBody& a = bodies[index[0]];
  const RigidBody& b = bodies[index[1]];
  if (a.fixed && b.fixed) r.fail(names, "both '" + a.name + "' and '" + b.name + "' are fixed; nothing can move");
  ConstraintEnds ends{index[0], index[1]};
  if (const YAML::Node* n = f.find("level"))
    ends.level = r.choice(*n, "level", {"velocity", "position"}) == "velocity" ? ConstraintLevel::velocity
                                                                                : ConstraintLevel::position;
  if (const YAML::Node* n = f.find("collide")) ends.collide = r.boolean(*n, "collide");
  return ends;
}

// A world point at the initial poses, in a body's frame.
Vec3 to_body(const RigidBody& body, const Vec3& world_point) {
  return body.rotation.transpose() * (world_point - body.position);
}

}  // namespace

Constraint read_constraint(const SceneReader& r, const YAML::Node& node, const std::vector<RigidBody>& bodies,
                           const std::map<std::string, BodyIndex>& index_by_name) {
  const Fields entry(r, node, "constraint", {"point_point", "coaxial"});
  const Fields::Entry& kind = only_entry(r, entry, "point_point, coaxial");
  if (kind.key == "point_point") {
    const Fields f(r, kind.value, "point_point", {"bodies", "point", "level", "collide"});
    const ConstraintEnds ends = read_ends(r, f, bodies, index_by_name);
    const Vec3 point = r.vec3(f.require("point"), "point");
    // The joined point is given in the world at the initial poses; store it in each body's frame.
    PointPointConstraint c;
    c.a = ends.a;
    c.b = ends.b;
    c.level = ends.level;
    c.collide = ends.collide;
    c.anchor_a = to_body(bodies[c.a], point);
    c.anchor_b = to_body(bodies[c.b], point);
    return c;
  }
  // coaxial: b's points `point` and `point + length·axis` stay on a's axis through `point` along `axis`
  // (world values at the initial poses).
  const Fields f(r, kind.value, "coaxial", {"bodies", "point", "axis", "length", "level", "collide"});
  const ConstraintEnds ends = read_ends(r, f, bodies, index_by_name);
  const Vec3 point = r.vec3(f.require("point"), "point");
  const Vec3 unit = r.direction(f.require("axis"), "axis");
  CoaxialConstraint c;
  c.a = ends.a;
  c.b = ends.b;
  c.level = ends.level;
  c.collide = ends.collide;
  if (const YAML::Node* n = f.find("length")) {
    c.length = r.number(*n, "length");
    if (!(c.length > 0.0)) r.fail(*n, "'length' must be positive, got " + format_number(c.length));
    // The rows' lever arms grow with the length; the resolver's system holds their squares over the
    // bodies' inertia, which must stay finite.
    const auto flexibility = [](const RigidBody& b) {
      return b.fixed ? 0.0 : b.inv_inertia_body.cwiseAbs().maxCoeff() + b.inv_mass;
    };
    if (!std::isfinite(c.length * c.length * (flexibility(bodies[c.a]) + flexibility(bodies[c.b]))))
      r.fail(*n, "'length' " + format_number(c.length) + " overflows the constraint's rows (length² over the "
                 "bodies' inertia must be finite)");
  }
  c.anchor_a = to_body(bodies[c.a], point);
  c.anchor_b = to_body(bodies[c.b], point);
  c.axis_a = bodies[c.a].rotation.transpose() * unit;
  c.axis_b = bodies[c.b].rotation.transpose() * unit;
  return c;
}

}  // namespace impetus::scene_detail
