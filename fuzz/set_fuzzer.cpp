// libFuzzer entry: `--set` overrides and generator parameters (lines of KEY=VALUE). See targets.hpp.
#include "targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  impetus::fuzz::overrides_one_input(data, size);
  return 0;
}
