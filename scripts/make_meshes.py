#!/usr/bin/env python3
"""Writes the bundled meshes (assets/meshes/) from their definitions: no downloaded data.

    python3 scripts/make_meshes.py [OUTPUT_DIR]      # default: assets/meshes next to this script

Good meshes are closed, outward-wound (counter-clockwise seen from outside), in metres, and written
in several formats so tests can check that every importer gives the same body: Wavefront OBJ, STL
(ASCII and binary), PLY (ASCII and binary), OFF, glTF 2.0 (.gltf with an embedded buffer, and .glb);
the writers are in mesh_formats.py.
Broken meshes (one defect each) exercise validation. Coordinates are rounded to float32 first (the
binary formats store float32) and printed in the shortest text that reads back, at double precision,
as that same float32 value, so all formats hold bit-identical vertices.

The output is deterministic: running the script twice gives byte-identical files (a test checks it).
Python standard library only.
"""

import math
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree (the tests run this script)
from mesh_formats import ALL_FORMATS, HEADER, WRITERS, f32, write_dae_cm, write_gltf, write_obj, write_stl_binary  # noqa: E402

# --- meshes --------------------------------------------------------------------------------------


def coordinate(x):
    """A vertex coordinate: float32, with rounding noise such as cos(pi/2) = 6e-17 made an exact 0
    (assimp's text parsers read exponents inexactly, and the noise means nothing)."""
    return f32(0.0 if abs(x) < 1e-12 else x)


class Mesh:
    """Triangles indexing vertices; `parts` splits the triangles into named objects (default: one)."""

    def __init__(self, name, vertices, triangles, parts=None):
        self.name = name
        self.vertices = [tuple(coordinate(c) for c in v) for v in vertices]
        self.triangles = [tuple(t) for t in triangles]
        self.parts = parts or [(name, 0, len(self.triangles))]


# --- shapes --------------------------------------------------------------------------------------


def box(name, lo, hi):
    """Axis-aligned box from corner lo to corner hi."""
    vertices = [(hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2])
                for i in range(8)]
    # Two triangles per face, counter-clockwise seen from outside.
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    triangles = []
    for a, b, c, d in quads:
        triangles += [(a, b, c), (a, c, d)]
    return Mesh(name, vertices, triangles)


def tetrahedron(name, half):
    """Regular tetrahedron: alternate corners of the cube [-half, half]^3 (edge 2·sqrt(2)·half)."""
    h = half
    vertices = [(h, h, h), (h, -h, -h), (-h, h, -h), (-h, -h, h)]
    return Mesh(name, vertices, [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)])


def icosphere(name, level, radius=1.0):
    """Icosahedron subdivided `level` times, every vertex pushed onto the sphere."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    points = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
              (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]

    def unit(p):
        length = math.sqrt(sum(c * c for c in p))
        return tuple(c / length for c in p)

    vertices = [unit(p) for p in points]
    for _ in range(level):
        midpoint = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoint:
                midpoint[key] = len(vertices)
                vertices.append(unit(tuple((vertices[a][i] + vertices[b][i]) / 2 for i in range(3))))
            return midpoint[key]

        refined = []
        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            refined += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = refined
    return Mesh(name, [tuple(radius * c for c in v) for v in vertices], faces)


def prism(name, sides, radius, length):
    """Regular polygonal prism, axis z, centered at the origin (a cylinder for many sides)."""
    ring = [(radius * math.cos(2 * math.pi * k / sides), radius * math.sin(2 * math.pi * k / sides))
            for k in range(sides)]
    z0, z1 = -length / 2, length / 2
    vertices = [(x, y, z0) for x, y in ring] + [(x, y, z1) for x, y in ring]
    vertices += [(0.0, 0.0, z0), (0.0, 0.0, z1)]  # cap centers: fans without slivers
    bottom, top = 2 * sides, 2 * sides + 1
    triangles = []
    for k in range(sides):
        n = (k + 1) % sides
        triangles += [(k, n, sides + n), (k, sides + n, sides + k)]
        triangles += [(bottom, n, k), (top, sides + k, sides + n)]
    return Mesh(name, vertices, triangles)


def torus(name, ring_segments, tube_segments, major, minor):
    """Torus around z: the tube's regular polygon (minor circumradius) swept by a regular polygon."""
    vertices = []
    for i in range(ring_segments):
        phi = 2 * math.pi * i / ring_segments
        for j in range(tube_segments):
            theta = 2 * math.pi * j / tube_segments
            rho = major + minor * math.cos(theta)
            vertices.append((rho * math.cos(phi), rho * math.sin(phi), minor * math.sin(theta)))
    triangles = []
    for i in range(ring_segments):
        for j in range(tube_segments):
            a = i * tube_segments + j
            b = ((i + 1) % ring_segments) * tube_segments + j
            c = ((i + 1) % ring_segments) * tube_segments + (j + 1) % tube_segments
            d = i * tube_segments + (j + 1) % tube_segments
            triangles += [(a, b, c), (a, c, d)]
    return Mesh(name, vertices, triangles)


def extrusion(name, profile, cap, depth):
    """The counter-clockwise polygon `profile` in the x-y plane (triangulated by `cap`) extruded
    along z from 0 to `depth`."""
    n = len(profile)
    vertices = [(x, y, 0.0) for x, y in profile] + [(x, y, depth) for x, y in profile]
    triangles = [(a, c, b) for a, b, c in cap] + [(n + a, n + b, n + c) for a, b, c in cap]
    for k in range(n):
        m = (k + 1) % n
        triangles += [(k, m, n + m), (k, n + m, n + k)]
    return Mesh(name, vertices, triangles)


def l_bracket(name, unit=1.0):
    """Non-convex L: a 0.4 x 0.1 foot and a 0.1 x 0.3 leg (x-y profile), 0.2 deep (m × unit)."""
    profile = [(0, 0), (0.4, 0), (0.4, 0.1), (0.1, 0.1), (0.1, 0.3), (0, 0.3)]
    cap = [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5)]
    return extrusion(name, [(x * unit, y * unit) for x, y in profile], cap, 0.2 * unit)


def t_handle():
    """T: a 1.0 x 0.1 bar and a 0.1 x 0.4 stem (x-y profile), 0.1 deep; three distinct principal
    moments, so it tumbles about its intermediate axis (Dzhanibekov effect)."""
    profile = [(-0.5, 0), (0.5, 0), (0.5, 0.1), (0.05, 0.1), (0.05, 0.5), (-0.05, 0.5), (-0.05, 0.1),
               (-0.5, 0.1)]
    cap = [(0, 1, 2), (0, 2, 3), (0, 3, 6), (0, 6, 7), (6, 3, 4), (6, 4, 5)]
    return extrusion("t_handle", profile, cap, 0.1)


def combine(name, meshes):
    """Several meshes as the named parts of one (each keeps its own vertices)."""
    vertices, triangles, parts = [], [], []
    for m in meshes:
        base = len(vertices)
        vertices += m.vertices
        parts.append((m.name, len(triangles), len(m.triangles)))
        triangles += [tuple(base + i for i in t) for t in m.triangles]
    return Mesh(name, vertices, triangles, parts)


# --- the catalogue -------------------------------------------------------------------------------


def good_meshes():
    """(mesh, formats, comment) for every well-formed mesh."""
    out = [
        (box("cube", (0, 0, 0), (1, 1, 1)), ALL_FORMATS, "unit cube [0, 1]^3"),
        (box("box", (1.0, -2.0, 0.25), (1.5, -0.75, 2.25)), ALL_FORMATS, "box 0.5 x 1.25 x 2 m"),
        (tetrahedron("tetrahedron", 0.5), ALL_FORMATS, "regular tetrahedron, edge sqrt(2) m"),
        (prism("cylinder", 32, 0.5, 1.0), ["obj", "stl", "glb"],
         "32-sided prism, circumradius 0.5 m, length 1 m, axis z"),
        (torus("torus", 32, 16, 1.0, 0.25), ["obj", "stl", "glb"],
         "torus, 32 x 16 segments, polygon circumradii 1 m and 0.25 m"),
        (l_bracket("l_bracket"), ALL_FORMATS, "non-convex L bracket, 0.4 x 0.3 x 0.2 m"),
        (t_handle(), ALL_FORMATS, "T handle, 1.0 x 0.5 x 0.1 m"),
    ]
    for level in range(5):
        formats = ALL_FORMATS if level == 2 else ["obj"]
        out.append((icosphere("icosphere_%d" % level, level), formats,
                    "icosphere, radius 1 m, %d subdivisions" % level))
    return out


def broken_meshes():
    """(file name, bytes or text, comment): each has exactly one defect."""
    cube = box("cube", (0, 0, 0), (1, 1, 1))
    out = []

    def obj(name, mesh, comment):
        out.append((name + ".obj", write_obj(mesh, comment)))

    obj("open_cube", Mesh("open_cube", cube.vertices, cube.triangles[2:]),
        "cube without its bottom face: 4 boundary edges")
    obj("inverted_cube", Mesh("inverted_cube", cube.vertices, [(a, c, b) for a, b, c in cube.triangles]),
        "cube wound inward (clockwise seen from outside): flipped with a warning")
    flipped = list(cube.triangles)
    flipped[4] = (flipped[4][0], flipped[4][2], flipped[4][1])
    obj("flipped_face_cube", Mesh("flipped_face_cube", cube.vertices, flipped),
        "cube with one triangle wound the wrong way")
    # Split the edge (0,0,0)-(1,0,0) at its midpoint m on one side and close the slit with the
    # zero-area triangle (a, b, m): closed and consistently oriented, but degenerate.
    vertices = list(cube.vertices) + [(0.5, 0.0, 0.0)]
    triangles = [t for t in cube.triangles if t != (0, 1, 5)] + [(0, 8, 5), (8, 1, 5), (0, 1, 8)]
    obj("degenerate_cube", Mesh("degenerate_cube", vertices, triangles), "cube with a zero-area triangle")
    text = write_obj(cube, "cube with a NaN vertex").replace("v 1 1 1", "v 1 nan 1")
    out.append(("nan_cube.obj", text))
    out.append(("empty.obj", ""))
    out.append(("no_triangles.obj", "# %s: vertices and a line, no faces\nv 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n"
                % HEADER))
    full = write_stl_binary(cube, "")
    out.append(("truncated.stl", full[:84 + 50 * 5 + 20]))  # header says 12 facets; 5.4 are there
    twin = combine("nonmanifold", [cube, box("cube2", (1, 1, 0), (2, 2, 1))])
    obj("nonmanifold", twin, "two cubes sharing an edge: the edge has four triangles")
    flat = Mesh("flat", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2), (0, 2, 1)])
    obj("flat", flat, "a triangle and its back face: closed, zero volume")
    overlap = combine("overlapping", [cube, box("cube2", (0.5, 0.5, 0.5), (1.5, 1.5, 1.5))])
    obj("overlapping", overlap, "two closed cubes overlapping: their common volume would count twice")
    return out


def special_meshes():
    """Files that test import options: several parts, node transforms, units."""
    out = []
    two = combine("two_boxes", [box("left", (0, 0, 0), (1, 1, 1)), box("right", (0, 0, 0), (1, 2, 0.5))])
    nodes = {"right": {"translation": [3.0, 0.0, 0.0]}}
    out.append(("two_boxes.gltf", write_gltf(two, "", nodes)))
    shifted = combine("two_boxes", [box("left", (0, 0, 0), (1, 1, 1)), box("right", (3, 0, 0), (4, 2, 0.5))])
    out.append(("two_boxes.obj", write_obj(shifted, "two boxes as two objects: left and right")))
    mirrored = combine("mirrored_box", [box("mirrored", (1, 0, 0), (2, 1, 1))])
    out.append(("mirrored_box.gltf", write_gltf(mirrored, "", {"mirrored": {"scale": [-1.0, 1.0, 1.0]}})))
    bracket = l_bracket("l_bracket_cm")
    out.append(("l_bracket_cm.dae", write_dae_cm(bracket, "the L bracket in centimetres")))
    out.append(("l_bracket_mm.stl", write_stl_binary(l_bracket("l_bracket_mm", 1000.0), "")))
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    target = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "assets", "meshes")
    broken_dir = os.path.join(target, "broken")
    os.makedirs(broken_dir, exist_ok=True)
    files = []
    for mesh, formats, comment in good_meshes():
        for fmt in formats:
            suffix, writer = WRITERS[fmt]
            files.append((os.path.join(target, mesh.name + suffix), writer(mesh, comment)))
    for name, data in special_meshes():
        files.append((os.path.join(target, name), data))
    for name, data in broken_meshes():
        files.append((os.path.join(broken_dir, name), data))
    for path, data in files:
        with open(path, "wb") as out:
            out.write(data.encode() if isinstance(data, str) else data)
    print("make_meshes.py: wrote %d files to %s" % (len(files), os.path.normpath(target)))


if __name__ == "__main__":
    main()
