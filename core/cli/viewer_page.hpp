#pragma once
/// \file
/// The viewer page (README.md, "Seeing a run"): one self-contained HTML file — three.js and the page's
/// code bundled in, the run's binary glTF inside as base64 — that plays a run offline from `file://`.
/// The page's source is `core/cli/viewer/` (JavaScript); the build bundles it with esbuild into a
/// generated source file, so the tool needs nothing at run time.

#include <filesystem>
#include <string>
#include <string_view>

namespace impetus::cli {

/// Whether this build carries the page (Node.js and the npm packages in core/cli/viewer were there at
/// build time).
bool viewer_available();

/// Throws Error naming `what` (e.g. "--out run.html") when this build has no viewer page.
void check_viewer_available(const std::string& what);

/// The page around a glTF file's bytes (binary or JSON with embedded buffers), titled `title`.
std::string viewer_page(std::string_view gltf, std::string_view title);

/// `impetus view FILE.glb|FILE.gltf --out FILE.html`.
struct ViewArgs {
  std::string file, out;
  bool overwrite = false;
};

/// Checks that `file` is a glTF 2.0 file written by Impetus (`impetus run --out`) and writes its viewer
/// page; throws Error naming the file and the defect otherwise.
int run_view_command(const ViewArgs& args);

}  // namespace impetus::cli
