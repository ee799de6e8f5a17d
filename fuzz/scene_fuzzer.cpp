// libFuzzer entry: the scene loader (YAML text in). See targets.hpp.
#include "targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  impetus::fuzz::scene_one_input(data, size);
  return 0;
}
