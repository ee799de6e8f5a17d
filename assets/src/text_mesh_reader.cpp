// The text mesh formats read at double precision: Wavefront OBJ, ASCII STL, ASCII PLY and OFF.
//
// Why not assimp: Debian's assimp 5.2 is built with 32-bit ai_real, so it rounds every coordinate of a
// text file to float32, and a mesh whose coordinates are not float32-exact (any CAD export) gets mass
// properties off by 1e-8 to 1e-7 relative where Mirtich's integrals in double are good to 1e-15
// (test_text_mesh_import measures both). Why not tinyobjloader (Debian's 2.0.0~rc10, double with
// TINYOBJLOADER_USE_DOUBLE): its number parser is not correctly rounded (it sums digit · 10^-k), and an
// unparseable number ("nan", "1.5x") silently becomes 0, a plausible wrong mesh; no Debian package
// reads ASCII STL, ASCII PLY or OFF in double at all. These four formats are simple, so they are read
// here: every number by std::from_chars (correctly rounded), every defect an Error naming the file and
// line, nothing allocated beyond what the file's bytes hold (a count is checked against the bytes
// before it is believed), indices checked against the vertices. Binary STL and binary PLY store
// float32 by definition, glTF's vertex accessors are float32, and the rest stay with assimp too.
//
// Non-finite numbers ("nan", "inf") are read as such, as assimp did: validation then refuses the mesh
// naming the vertex. Out-of-range ones (1e999) are refused here.

#include "text_mesh_reader.hpp"

#include "assimp_reader.hpp"
#include "impetus/core/error.hpp"
#include "text.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace impetus::assets::detail {
namespace {

constexpr std::uint64_t kMaxVertices = std::numeric_limits<std::uint32_t>::max();
constexpr std::size_t kMaxEarClipping = 1024;  // vertices of one non-convex face
// Point-in-triangle tests for all the non-convex faces of one file (about a second): ear clipping is
// O(n³) in the worst case, so a file of many large non-convex faces is bounded by work, not by count.
constexpr std::uint64_t kEarClippingWork = 200'000'000;

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// A leading '+' that from_chars would refuse, before a digit or '.' (so "+-1" stays refused).
bool plus_sign(std::string_view token) {
  return token.size() > 1 && token[0] == '+' && token[1] != '+' && token[1] != '-';
}

// A word of the file for a message: at most 40 bytes, control and non-ASCII bytes as \xHH, so a hostile
// file cannot put a NUL, an escape sequence or a line break into the error.
std::string quoted(std::string_view token) {
  constexpr std::size_t kShown = 40;
  std::string out = "'";
  for (const char ch : token.substr(0, kShown)) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7f) {
      out += ch;
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", c);
      out += hex;
    }
  }
  return out + (token.size() > kShown ? "…'" : "'");
}

// The file's text, line by line, with its line numbers, and the errors that name them.
class Source {
 public:
  Source(const std::filesystem::path& file, std::string text, std::string format)
      : label_(file.string()), text_(std::move(text)), format_(std::move(format)) {}

  // The next line (without its end), or false at the end of the file.
  bool next_line(std::string_view& line) {
    if (at_ >= text_.size()) return false;
    const std::size_t end = std::min(text_.find('\n', at_), text_.size());
    line = std::string_view(text_).substr(at_, end - at_);
    at_ = end + 1;
    ++line_;
    return true;
  }

  std::size_t line_number() const { return line_; }

  // Spends `steps` of the file's ear-clipping budget.
  void spend(std::uint64_t steps) {
    if (steps > clipping_work_left_)
      fail("its non-convex faces take more than " + std::to_string(kEarClippingWork) +
           " steps to triangulate: triangulate them when exporting");
    clipping_work_left_ -= steps;
  }
  std::size_t size() const { return text_.size(); }
  const std::string& label() const { return label_; }

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(label_ + ": malformed " + format_ + ": line " + std::to_string(line_) + ": " + what);
  }

  double real(std::string_view token, const char* what) const {
    std::string_view digits = token;
    if (plus_sign(digits)) digits.remove_prefix(1);  // from_chars takes no '+'
    double value = 0.0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec == std::errc::result_out_of_range)
      fail(std::string(what) + " " + quoted(token) + " is out of the range of a double");
    if (ec != std::errc{} || end != digits.data() + digits.size())
      fail(std::string(what) + " " + quoted(token) + " is not a number");
    return value;
  }

  std::int64_t integer(std::string_view token, const char* what) const {
    std::string_view digits = token;
    if (plus_sign(digits)) digits.remove_prefix(1);
    std::int64_t value = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc{} || end != digits.data() + digits.size())
      fail(std::string(what) + " " + quoted(token) + " is not an integer");
    return value;
  }

  // A count announced by the file, which must fit in its bytes at `bytes_each` per item.
  std::uint64_t count(std::string_view token, const char* what, std::uint64_t bytes_each) const {
    const std::int64_t n = integer(token, what);
    if (n < 0) fail(std::string(what) + " " + quoted(token) + " is negative");
    if (static_cast<std::uint64_t>(n) > text_.size() / bytes_each)
      fail(std::string(what) + " " + std::to_string(n) + " is more than the file's " + std::to_string(text_.size()) +
           " bytes can hold");
    return static_cast<std::uint64_t>(n);
  }

 private:
  std::string label_;
  std::string text_;
  std::string format_;
  std::size_t at_ = 0;
  std::size_t line_ = 0;
  std::uint64_t clipping_work_left_ = kEarClippingWork;
};

// The whitespace-separated words of a line, up to a comment character (none: '\0').
std::vector<std::string_view> words(std::string_view line, char comment) {
  if (comment) line = line.substr(0, line.find(comment));
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

// A polygon's vertices as triangles, counter-clockwise about the polygon's own (Newell) normal. A
// convex polygon (every corner turns the same way) becomes a fan; a non-convex one is ear-clipped, as
// assimp does: a fan would be exact for the mass properties (its signed areas sum to the polygon's)
// but would put triangles outside the face, where a detector colliding the triangles would see them.
void add_polygon(Source& source, const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& polygon,
                 std::vector<std::array<std::uint32_t, 3>>& triangles) {
  const std::size_t n = polygon.size();
  const auto at = [&](std::size_t i) -> const Vec3& { return vertices[polygon[i]]; };
  Vec3 normal = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) normal += at(i).cross(at((i + 1) % n));
  const auto turn = [&](const Vec3& a, const Vec3& b, const Vec3& c) { return (b - a).cross(c - b).dot(normal); };
  bool convex = true;
  for (std::size_t i = 0; i < n && convex; ++i) convex = !(turn(at(i), at((i + 1) % n), at((i + 2) % n)) < 0.0);
  if (n == 3 || convex || !normal.allFinite() || normal.squaredNorm() == 0.0) {  // degenerate ones: validation says so
    for (std::size_t i = 1; i + 1 < n; ++i) triangles.push_back({polygon[0], polygon[i], polygon[i + 1]});
    return;
  }
  if (n > kMaxEarClipping)
    source.fail("a non-convex face of " + std::to_string(n) + " vertices (more than " +
                std::to_string(kMaxEarClipping) + "): triangulate it when exporting");
  std::vector<std::uint32_t> left = polygon;
  while (left.size() > 3) {
    const std::size_t m = left.size();
    std::uint64_t steps = 0;
    bool clipped = false;
    for (std::size_t i = 0; i < m && !clipped; ++i) {
      const Vec3 &a = vertices[left[(i + m - 1) % m]], &b = vertices[left[i]], &c = vertices[left[(i + 1) % m]];
      if (!(turn(a, b, c) > 0.0)) continue;  // a reflex (or straight) corner is no ear
      bool empty = true;
      steps += m;
      for (std::size_t j = 0; j < m && empty; ++j) {
        if (j == i || j == (i + m - 1) % m || j == (i + 1) % m) continue;
        const Vec3& p = vertices[left[j]];
        empty = !((b - a).cross(p - a).dot(normal) >= 0.0 && (c - b).cross(p - b).dot(normal) >= 0.0 &&
                  (a - c).cross(p - c).dot(normal) >= 0.0);
      }
      if (!empty) continue;
      triangles.push_back({left[(i + m - 1) % m], left[i], left[(i + 1) % m]});
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(i));
      clipped = true;
    }
    source.spend(steps);
    if (!clipped) break;  // a self-intersecting polygon has no ear left: the rest as a fan
  }
  for (std::size_t i = 1; i + 1 < left.size(); ++i) triangles.push_back({left[0], left[i], left[i + 1]});
}

// A part's triangles as indices into the file's vertices, before the part gets its own vertices.
struct RawPart {
  std::string name;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

// Gives each part the vertices its triangles use, scaled; merged into one part in merge mode.
ImportedMesh assemble(const std::filesystem::path& file, std::string format, const std::vector<Vec3>& vertices,
                      std::vector<RawPart> raw, std::size_t dropped, const ImportOptions& options) {
  if (options.parts == PartMode::merge && raw.size() > 1) {
    RawPart all{file.stem().string(), {}};
    for (RawPart& part : raw) all.triangles.insert(all.triangles.end(), part.triangles.begin(), part.triangles.end());
    raw.assign(1, std::move(all));
  } else if (options.parts == PartMode::merge && raw.size() == 1) {
    raw[0].name = file.stem().string();
  }
  ImportedMesh out;
  out.file = file;
  out.format = std::move(format);
  std::vector<std::uint32_t> local(vertices.size(), UINT32_MAX);
  for (RawPart& part : raw) {
    if (part.triangles.empty()) continue;
    ImportedPart imported{std::move(part.name), {}};
    std::vector<std::uint32_t> used;
    for (const auto& t : part.triangles) {
      std::array<std::uint32_t, 3> renumbered{};
      for (int k = 0; k < 3; ++k) {
        std::uint32_t& slot = local[t[static_cast<std::size_t>(k)]];
        if (slot == UINT32_MAX) {
          slot = static_cast<std::uint32_t>(imported.mesh.vertices.size());
          imported.mesh.vertices.push_back(vertices[t[static_cast<std::size_t>(k)]] * options.scale);
          used.push_back(t[static_cast<std::size_t>(k)]);
        }
        renumbered[static_cast<std::size_t>(k)] = slot;
      }
      imported.mesh.triangles.push_back(renumbered);
    }
    for (std::uint32_t v : used) local[v] = UINT32_MAX;
    std::vector<std::array<std::uint32_t, 3>>().swap(part.triangles);  // the peak stays near one copy
    out.parts.push_back(std::move(imported));
  }
  finish_import(out, dropped, options);
  return out;
}

// Three coordinates from w[first…], parsed left to right (so the first bad one is the one named).
Vec3 point(const Source& source, const std::vector<std::string_view>& w, std::size_t first) {
  Vec3 p;
  for (std::size_t k = 0; k < 3; ++k) p[static_cast<Eigen::Index>(k)] = source.real(w[first + k], "coordinate");
  return p;
}

void add_vertex(const Source& source, std::vector<Vec3>& vertices, const Vec3& p) {
  if (vertices.size() >= kMaxVertices) source.fail("more than " + std::to_string(kMaxVertices) + " vertices");
  vertices.push_back(p);
}

// ---- Wavefront OBJ ---------------------------------------------------------------------------------
// Statements: v (x y z, then optional w or r g b), f (v, v/t, v/t/n or v//n; negative = relative),
// l and p (dropped), o and g (each starts a part, as assimp maps groups to objects; faces before any
// start the part "defaultobject", assimp's name). Texture, normal and material statements are skipped
// (mtllib is never opened); free-form geometry and unknown statements are refused.
ImportedMesh read_obj(const std::filesystem::path& file, std::string text, const ImportOptions& options) {
  Source source(file, std::move(text), "OBJ");
  std::vector<Vec3> vertices;
  std::vector<RawPart> parts;
  std::size_t dropped = 0;
  std::vector<std::uint32_t> polygon;
  const auto current = [&]() -> RawPart& {
    if (parts.empty()) parts.push_back({"defaultobject", {}});
    return parts.back();
  };
  static constexpr std::string_view kSkipped[] = {
      "vt",  "vn",    "vp",       "s",        "usemtl",     "mtllib",    "usemap", "maplib",
      "lod", "mg",    "bevel",    "c_interp", "d_interp",   "shadow_obj", "trace_obj", "ctech", "stech"};
  static constexpr std::string_view kFreeForm[] = {
      "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con"};
  std::string_view line;
  while (source.next_line(line)) {
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (!line.empty() && line.back() == '\\') source.fail("line continuation ('\\') is not supported");
    const std::vector<std::string_view> w = words(line, '#');
    if (w.empty()) continue;
    const std::string_view keyword = w[0];
    if (keyword == "v") {
      if (w.size() < 4) source.fail("a vertex needs three coordinates");
      if (w.size() > 8) source.fail("a vertex has at most x y z and w or r g b");
      const Vec3 p = point(source, w, 1);
      for (std::size_t i = 4; i < w.size(); ++i) source.real(w[i], "value");
      add_vertex(source, vertices, p);
    } else if (keyword == "f") {
      if (w.size() < 4) source.fail("a face needs at least three vertices");
      polygon.clear();
      for (std::size_t i = 1; i < w.size(); ++i) {
        const std::string_view ref = w[i].substr(0, w[i].find('/'));
        const std::int64_t n = source.integer(ref, "vertex index");
        const auto count = static_cast<std::int64_t>(vertices.size());
        const std::int64_t index = n > 0 ? n - 1 : count + n;
        if (n == 0 || index < 0 || index >= count)
          source.fail("vertex index " + std::to_string(n) + " does not name one of the " + std::to_string(count) +
                      " vertices defined before it");
        polygon.push_back(static_cast<std::uint32_t>(index));
      }
      add_polygon(source, vertices, polygon, current().triangles);
    } else if (keyword == "l") {
      if (w.size() < 3) source.fail("a line needs at least two vertices");
      dropped += w.size() - 2;
    } else if (keyword == "p") {
      if (w.size() < 2) source.fail("a point statement needs a vertex");
      dropped += w.size() - 1;
    } else if (keyword == "o" || keyword == "g") {
      std::string name;
      for (std::size_t i = 1; i < w.size(); ++i) name += (i > 1 ? " " : "") + std::string(w[i]);
      if (name.empty() && keyword == "g") name = "default";
      // A part without faces yet is renamed rather than followed: a file of nothing but `o` lines must
      // not cost a part each (empty parts are dropped anyway).
      if (!parts.empty() && parts.back().triangles.empty()) parts.back().name = std::move(name);
      else parts.push_back({std::move(name), {}});
    } else if (std::ranges::find(kFreeForm, keyword) != std::end(kFreeForm)) {
      source.fail("free-form geometry ('" + std::string(keyword) + "') is not supported: export the mesh as polygons");
    } else if (std::ranges::find(kSkipped, keyword) == std::end(kSkipped)) {
      source.fail("unknown statement " + quoted(keyword));
    }
  }
  return assemble(file, "Wavefront OBJ (double precision)", vertices, std::move(parts), dropped, options);
}

// ---- ASCII STL -------------------------------------------------------------------------------------
// solid NAME · (facet normal nx ny nz · outer loop · vertex x y z ×3 · endloop · endfacet)* · endsolid,
// one or more solids; each solid is a part named by it (assimp makes each a node). Keywords one per
// line, as every writer puts them; the normal is read but not used (the winding decides).
ImportedMesh read_ascii_stl(const std::filesystem::path& file, std::string text, const ImportOptions& options) {
  Source source(file, std::move(text), "ASCII STL");
  std::vector<Vec3> vertices;
  std::vector<RawPart> parts;
  enum class State { outside, solid, facet, loop, loop_done, facet_done } state = State::outside;
  std::array<std::uint32_t, 3> triangle{};
  std::size_t corners = 0;
  std::string_view line;
  while (source.next_line(line)) {
    const std::vector<std::string_view> w = words(line, '\0');
    if (w.empty()) continue;
    // Keywords in any case, as some older exporters write them in capitals.
    const std::string keyword = lower(std::string(w[0]));
    const auto expect = [&](State wanted, const char* where) {
      if (state != wanted) source.fail(quoted(w[0]) + " " + where);
    };
    if (keyword == "solid") {
      expect(State::outside, "inside a solid (no 'endsolid' before it)");
      std::string name;
      for (std::size_t i = 1; i < w.size(); ++i) name += (i > 1 ? " " : "") + std::string(w[i]);
      parts.push_back({name, {}});
      state = State::solid;
    } else if (keyword == "facet") {
      expect(State::solid, "outside a solid or inside a facet");
      if (w.size() != 5 || lower(std::string(w[1])) != "normal") source.fail("expected 'facet normal nx ny nz'");
      for (std::size_t i = 2; i < 5; ++i) source.real(w[i], "normal component");
      state = State::facet;
    } else if (keyword == "outer") {
      expect(State::facet, "outside a facet");
      if (w.size() != 2 || lower(std::string(w[1])) != "loop") source.fail("expected 'outer loop'");
      state = State::loop;
      corners = 0;
    } else if (keyword == "vertex") {
      expect(State::loop, "outside a loop");
      if (w.size() != 4) source.fail("expected 'vertex x y z'");
      if (corners == 3) source.fail("a facet has more than three vertices");
      add_vertex(source, vertices, point(source, w, 1));
      triangle[corners++] = static_cast<std::uint32_t>(vertices.size() - 1);
    } else if (keyword == "endloop") {
      expect(State::loop, "outside a loop");
      if (corners != 3) source.fail("a facet has " + std::to_string(corners) + " vertices, not three");
      parts.back().triangles.push_back(triangle);
      state = State::loop_done;
    } else if (keyword == "endfacet") {
      expect(State::loop_done, "before its loop ended");
      state = State::solid;
    } else if (keyword == "endsolid") {
      expect(State::solid, "inside a facet or outside a solid");
      state = State::outside;
    } else {
      source.fail("unknown keyword " + quoted(w[0]));
    }
  }
  if (state != State::outside) source.fail("the file ends inside a solid (no 'endsolid')");
  return assemble(file, "ASCII STL (double precision)", vertices, std::move(parts), 0, options);
}

// ---- ASCII PLY -------------------------------------------------------------------------------------
// The header's elements in order; in the body each element instance is one line of its properties'
// values (lists: a length, then that many values). x, y, z of `vertex` are the coordinates, read at
// double whatever type the header declares (a float32 property printed with 17 digits is the usual
// way to carry doubles); `vertex_indices` (or `vertex_index`) of `face` the polygons.
ImportedMesh read_ascii_ply(const std::filesystem::path& file, std::string text, const ImportOptions& options) {
  Source source(file, std::move(text), "PLY");
  struct Property {
    std::string name;
    bool list = false;
  };
  struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> properties;
  };
  std::vector<Element> elements;
  std::string_view line;
  bool ended = false;
  while (!ended && source.next_line(line)) {
    const std::vector<std::string_view> w = words(line, '\0');
    if (source.line_number() == 1) {
      if (w.size() != 1 || w[0] != "ply") source.fail("the file does not start with 'ply'");
      continue;
    }
    if (w.empty()) continue;
    if (w[0] == "format") {
      if (w.size() != 3 || w[1] != "ascii" || w[2] != "1.0") source.fail("expected 'format ascii 1.0'");
    } else if (w[0] == "comment" || w[0] == "obj_info") {
    } else if (w[0] == "element") {
      if (w.size() != 3) source.fail("expected 'element NAME COUNT'");
      elements.push_back({std::string(w[1]), source.count(w[2], "element count", 2), {}});
    } else if (w[0] == "property") {
      if (elements.empty()) source.fail("a property before any element");
      const bool list = w.size() >= 2 && w[1] == "list";
      if (w.size() != (list ? 5u : 3u))
        source.fail(list ? "expected 'property list COUNT_TYPE VALUE_TYPE NAME'" : "expected 'property TYPE NAME'");
      elements.back().properties.push_back({std::string(w.back()), list});
    } else if (w[0] == "end_header") {
      ended = true;
    } else {
      source.fail("unknown header line starting " + quoted(w[0]));
    }
  }
  if (!ended) source.fail("the header has no 'end_header'");

  std::vector<Vec3> vertices;
  std::vector<RawPart> parts(1, RawPart{"", {}});
  std::size_t dropped = 0;
  std::vector<std::uint32_t> polygon;
  for (const Element& element : elements) {
    const bool is_vertex = element.name == "vertex", is_face = element.name == "face";
    std::array<int, 3> xyz = {-1, -1, -1};
    int indices = -1;
    for (std::size_t i = 0; i < element.properties.size(); ++i) {
      const Property& p = element.properties[i];
      for (int k = 0; k < 3; ++k)
        if (is_vertex && !p.list && p.name == std::string(1, static_cast<char>('x' + k)))
          xyz[static_cast<std::size_t>(k)] = static_cast<int>(i);
      if (is_face && p.list && (p.name == "vertex_indices" || p.name == "vertex_index")) indices = static_cast<int>(i);
    }
    if (is_vertex && (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)) source.fail("element 'vertex' has no x, y and z");
    for (std::uint64_t n = 0; n < element.count; ++n) {
      std::vector<std::string_view> w;
      while (w.empty()) {
        if (!source.next_line(line))
          source.fail("the file ends in element '" + element.name + "' #" + std::to_string(n) + " of " +
                      std::to_string(element.count));
        w = words(line, '\0');
      }
      std::size_t at = 0;
      const auto take = [&]() -> std::string_view {
        if (at >= w.size()) source.fail("element '" + element.name + "' #" + std::to_string(n) + " has too few values");
        return w[at++];
      };
      Vec3 p = Vec3::Zero();
      polygon.clear();
      for (std::size_t i = 0; i < element.properties.size(); ++i) {
        if (!element.properties[i].list) {
          const double value = source.real(take(), "value");
          for (int k = 0; k < 3; ++k)
            if (static_cast<int>(i) == xyz[static_cast<std::size_t>(k)]) p[k] = value;
          continue;
        }
        const std::uint64_t length = source.count(take(), "list length", 2);
        for (std::uint64_t j = 0; j < length; ++j) {
          const std::string_view value = take();
          if (static_cast<int>(i) != indices) {
            source.real(value, "value");
            continue;
          }
          const std::int64_t index = source.integer(value, "vertex index");
          if (index < 0 || static_cast<std::uint64_t>(index) >= vertices.size())
            source.fail("vertex index " + std::to_string(index) + " does not name one of the " +
                        std::to_string(vertices.size()) + " vertices");
          polygon.push_back(static_cast<std::uint32_t>(index));
        }
      }
      if (at != w.size()) source.fail("element '" + element.name + "' #" + std::to_string(n) + " has too many values");
      if (is_vertex) add_vertex(source, vertices, p);
      if (is_face && polygon.size() >= 3) add_polygon(source, vertices, polygon, parts[0].triangles);
      if (is_face && polygon.size() < 3) ++dropped;
    }
  }
  while (source.next_line(line))
    if (!words(line, '\0').empty()) source.fail("data after the last element");
  return assemble(file, "ASCII PLY (double precision)", vertices, std::move(parts), dropped, options);
}

// ---- OFF -------------------------------------------------------------------------------------------
// OFF · vertex, face and edge counts · one vertex per line (x y z) · one face per line (n, then n
// indices, then an optional colour). '#' starts a comment; blank lines are skipped.
ImportedMesh read_off(const std::filesystem::path& file, std::string text, const ImportOptions& options) {
  Source source(file, std::move(text), "OFF");
  std::string_view line;
  std::vector<std::string_view> w;
  const auto next = [&](const std::string& what) {
    do {
      if (!source.next_line(line)) source.fail("the file ends before " + what);
      w = words(line, '#');
    } while (w.empty());
  };
  next("its header");
  if (w[0] != "OFF") source.fail("the file does not start with 'OFF'");
  if (w.size() == 1) next("its counts");
  else w.erase(w.begin());
  if (w.size() != 3) source.fail("expected the vertex, face and edge counts");
  const std::uint64_t vertex_count = source.count(w[0], "vertex count", 6);  // "0 0 0\n" at least
  const std::uint64_t face_count = source.count(w[1], "face count", 8);      // "3 0 1 2\n"
  source.integer(w[2], "edge count");
  std::vector<Vec3> vertices;
  for (std::uint64_t n = 0; n < vertex_count; ++n) {
    next("vertex " + std::to_string(n) + " of " + std::to_string(vertex_count));
    if (w.size() < 3) source.fail("a vertex needs three coordinates");
    for (std::size_t i = 3; i < w.size(); ++i) source.real(w[i], "value");
    add_vertex(source, vertices, point(source, w, 0));
  }
  std::vector<RawPart> parts(1, RawPart{"", {}});
  std::size_t dropped = 0;
  std::vector<std::uint32_t> polygon;
  for (std::uint64_t n = 0; n < face_count; ++n) {
    next("face " + std::to_string(n) + " of " + std::to_string(face_count));
    const std::uint64_t length = source.count(w[0], "face length", 2);
    if (w.size() < 1 + length) source.fail("a face of " + std::to_string(length) + " vertices lists fewer indices");
    polygon.clear();
    for (std::size_t i = 1; i <= length; ++i) {
      const std::int64_t index = source.integer(w[i], "vertex index");
      if (index < 0 || static_cast<std::uint64_t>(index) >= vertices.size())
        source.fail("vertex index " + std::to_string(index) + " does not name one of the " +
                    std::to_string(vertices.size()) + " vertices");
      polygon.push_back(static_cast<std::uint32_t>(index));
    }
    for (std::size_t i = 1 + length; i < w.size(); ++i) source.real(w[i], "colour value");
    if (polygon.size() >= 3) add_polygon(source, vertices, polygon, parts[0].triangles);
    else ++dropped;
  }
  while (source.next_line(line))
    if (!words(line, '#').empty()) source.fail("more data than its counts announce");
  return assemble(file, "OFF (double precision)", vertices, std::move(parts), dropped, options);
}

// Whether the text starts with `prefix`, for recognising a format.
bool starts_with(const std::string& text, std::string_view prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

// Binary STL may start with "solid" too (its 80-byte header is free text): it is binary when its size
// is exactly what its facet count says, as assimp decides.
bool is_ascii_stl(const std::string& text) {
  if (!starts_with(text, "solid")) return false;  // as assimp and check_binary_stl decide: lower case
  if (text.size() < 84) return true;
  std::uint32_t facets = 0;
  std::memcpy(&facets, text.data() + 80, 4);
  return text.size() != 84 + 50 * std::uint64_t{facets};
}

// The PLY header's format line says ascii (whitespace and comments before it allowed).
bool is_ascii_ply(const std::string& text) {
  const std::size_t format = text.find("\nformat ");
  return starts_with(text, "ply") && format != std::string::npos && format < 1024 &&
         text.compare(format + 8, 5, "ascii") == 0;
}

bool is_plain_off(const std::string& text) {
  std::size_t at = 0;
  while (at < text.size() && (is_space(text[at]) || text[at] == '\n')) ++at;
  return text.compare(at, 3, "OFF") == 0 && (at + 3 == text.size() || is_space(text[at + 3]) || text[at + 3] == '\n');
}

}  // namespace

std::optional<ImportedMesh> read_text_mesh(const std::filesystem::path& file, const ImportOptions& options) {
  const std::string extension = lower(file.extension().string());
  if (extension != ".obj" && extension != ".stl" && extension != ".ply" && extension != ".off") return std::nullopt;
  std::ifstream in(file, std::ios::binary);
  std::string text;
  if (in) {
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    in.seekg(0);
    if (size > 0) {
      text.resize(static_cast<std::size_t>(size));  // bounded by check_mesh_file's 1 GiB
      in.read(text.data(), size);
    }
  }
  if (!in) throw Error(file.string() + ": cannot read the mesh file");
  if (extension == ".obj") return read_obj(file, std::move(text), options);
  if (extension == ".stl" && is_ascii_stl(text)) return read_ascii_stl(file, std::move(text), options);
  if (extension == ".ply" && is_ascii_ply(text)) return read_ascii_ply(file, std::move(text), options);
  if (extension == ".off" && is_plain_off(text)) return read_off(file, std::move(text), options);
  return std::nullopt;
}

ImportedMesh read_mesh_file(const std::filesystem::path& file, const ImportOptions& options) {
  if (std::optional<ImportedMesh> mesh = read_text_mesh(file, options)) return std::move(*mesh);
  return read_with_assimp(file, options);
}

}  // namespace impetus::assets::detail
