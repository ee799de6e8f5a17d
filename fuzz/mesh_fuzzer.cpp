// libFuzzer entry: the mesh pipeline for one file format (IMPETUS_FUZZ_MESH_EXTENSION, e.g. "obj").
// One binary per format, so each has its own corpus and the format is never a fuzzed byte.
#include "targets.hpp"

#ifndef IMPETUS_FUZZ_MESH_EXTENSION
#error "IMPETUS_FUZZ_MESH_EXTENSION must name the format's file extension"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  impetus::fuzz::mesh_one_input(data, size, IMPETUS_FUZZ_MESH_EXTENSION);
  return 0;
}
