#pragma once
/// \file
/// The fuzz targets as plain functions, so the libFuzzer binaries (fuzz/*_fuzzer.cpp, clang only) and
/// the regression test (tests/reliability, any compiler, also under the sanitizers) run the same code
/// on the same inputs. Each function takes arbitrary bytes, must never crash, hang or leak, and turns
/// every rejection into an impetus::Error internally. A violated invariant (a scene the loader accepts
/// but the World refuses, a validated mesh with non-finite or non-physical mass properties) aborts, so
/// the fuzzer reports it as a crash.

#include <cstddef>
#include <cstdint>
#include <string>

namespace impetus::fuzz {

/// What one input did, for the regression test's counts.
enum class Outcome { accepted, rejected };

/// The scene loader: `data` is YAML text, read as the file `fuzz.yaml` in the bundled scene directory
/// (so `../meshes/cube.obj` resolves); an accepted scene is then handed to a World body by body and
/// constraint by constraint, which must accept it too.
Outcome scene_one_input(const std::uint8_t* data, std::size_t size);

/// `--set` overrides and generator parameters: `data` is lines of KEY=VALUE, each parsed as the command
/// line parses one `--set` and applied to a small scene with two bodies, a constraint, and a line and a
/// pyramid generator (so `generators.0.line.count=…` and `bodies.ball.velocity=…` reach every
/// generator parameter and body field); an accepted scene must then be accepted by a World, as above.
Outcome overrides_one_input(const std::uint8_t* data, std::size_t size);

/// The mesh pipeline: `data` is written to a private temporary file named `input.<extension>`
/// (extension without the dot: obj, stl, ply, off, gltf, glb, dae) in a folder that also holds
/// `buffer.bin` (a unit cube's glTF buffer: 36 uint32 indices, then 8 float32 vertices), so that an input
/// can refer to a file that resolves (and to others, outside the folder, that must be refused), and
/// imported, validated, given mass
/// properties and a convex hull (assets::load_mesh_body). An accepted mesh must have a positive finite
/// volume and a finite, symmetric, positive definite inertia that satisfies the triangle inequality.
Outcome mesh_one_input(const std::uint8_t* data, std::size_t size, const std::string& extension);

}  // namespace impetus::fuzz
