// `generators:` and `constraints:` entries: the ones that make bodies in bulk or refer to them by name.

#include "impetus/core/generators.hpp"
#include "scene_internal.hpp"

#include <climits>

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
  if (const YAML::Node* n = f.find("overlap")) p.overlap = r.number(*n, "overlap");
}

}  // namespace

std::vector<ReadBody> read_generator(const SceneReader& r, const YAML::Node& node) {
  const Fields entry(r, node, "generator", {"pyramid", "line"});
  const Fields::Entry& kind = only_entry(r, entry, "pyramid, line");
  std::vector<RigidBody> bodies;
  // Types are checked here, with locations; ranges by the generator itself, so they live in one place.
  if (kind.key == "pyramid") {
    const Fields f(r, kind.value, "pyramid",
                   {"rows", "radius", "mass", "velocity", "restitution", "overlap", "ground"});
    PyramidParams p;
    p.rows = read_int(r, f.require("rows"), "rows");
    read_spheres(r, f, p);
    if (const YAML::Node* n = f.find("ground")) p.ground = r.boolean(*n, "ground");
    try {
      bodies = make_pyramid(p);
    } catch (const GeneratorError& e) {
      r.fail(f.find(e.field()) ? *f.find(e.field()) : kind.value, e.what());
    }
  } else {
    const Fields f(r, kind.value, "line", {"count", "radius", "mass", "wall", "velocity", "restitution", "overlap"});
    LineParams p;
    p.count = read_int(r, f.require("count"), "count");
    read_spheres(r, f, p);
    if (const YAML::Node* n = f.find("wall")) p.wall = r.boolean(*n, "wall");
    try {
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

Constraint read_constraint(const SceneReader& r, const YAML::Node& node, const std::vector<RigidBody>& bodies,
                           const std::map<std::string, BodyIndex>& index_by_name) {
  const Fields entry(r, node, "constraint", {"point_point"});
  const Fields::Entry& kind = only_entry(r, entry, "point_point");
  const Fields f(r, kind.value, "point_point", {"bodies", "point", "level", "collide"});
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

  PointPointConstraint c;
  c.a = index[0];
  c.b = index[1];
  const Vec3 point = r.vec3(f.require("point"), "point");
  // The joined point is given in the world at the initial poses; store it in each body's frame.
  c.anchor_a = a.rotation.transpose() * (point - a.position);
  c.anchor_b = b.rotation.transpose() * (point - b.position);
  if (const YAML::Node* n = f.find("level"))
    c.level = r.choice(*n, "level", {"velocity", "position"}) == "velocity" ? ConstraintLevel::velocity
                                                                             : ConstraintLevel::position;
  if (const YAML::Node* n = f.find("collide")) c.collide = r.boolean(*n, "collide");
  return c;
}

}  // namespace impetus::scene_detail
