#!/usr/bin/env bash
# usage: run_embed_example.sh BUILD_DIR EXAMPLE_SRC WORK_DIR [PLUGIN_TEMPLATE_SRC [TYPED_EXAMPLE_SRC]]
set -euo pipefail
build=$1 example=$2 work=$3 template=${4:-} typed=${5:-}
rm -rf "$work"
mkdir -p "$work"
cmake --install "$build" --prefix "$work/staging" >/dev/null
mv "$work/staging" "$work/prefix"   # relocated: nothing may point back at the staging path
cmake -S "$example" -B "$work/build" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/build" >/dev/null
"$work/build/embed" "$work/prefix/share/impetus/scenes/demo.yaml"
# The second way to embed: typed settings in code, and a scene with its resolver swapped by an override.
if [[ -n "$typed" ]]; then
  cmake -S "$typed" -B "$work/typed" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
  cmake --build "$work/typed" >/dev/null
  "$work/typed/typed"
fi
"$work/prefix/bin/impetus" plugins | grep -q "$work/prefix/.*impetus_integrator_euler.so" || {
  echo "installed impetus does not find its own plugins" >&2; "$work/prefix/bin/impetus" plugins >&2; exit 1; }
# Meshes are imported by the importer program, which the relocated library must find in its own prefix.
mass=$("$work/prefix/bin/impetus" mass "$work/prefix/share/impetus/meshes/cube.obj" 2>&1) || {
  echo "installed impetus cannot import a mesh: $mass" >&2; exit 1; }
# The plugin template, built out of tree against the relocated install, passes the integrator
# conformance suite that the install ships (impetus_add_conformance_tests()).
if [[ -n "$template" ]]; then
  cmake -S "$template" -B "$work/template" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
  cmake --build "$work/template" >/dev/null
  grep -q '^CMAKE_BUILD_TYPE:STRING=Release$' "$work/template/CMakeCache.txt" || {
    echo "the plugin template does not default to an optimised (Release) build" >&2; exit 1; }
  ctest --test-dir "$work/template" --output-on-failure >/dev/null || {
    echo "the plugin template fails the installed conformance suite" >&2
    ctest --test-dir "$work/template" --output-on-failure >&2; exit 1; }
fi
