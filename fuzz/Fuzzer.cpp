// One libFuzzer target; fuzz/CMakeLists.txt compiles it once per loader with PNEUMA_FUZZ_LOADER set to the
// loader's enumerator (Model, Anatomy, Gains, Style, Scenario or Pattern).
#include <cstddef>
#include <cstdint>
#include <string>

#include "FuzzLoaders.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pneuma::fuzz::runLoader(pneuma::fuzz::Loader::PNEUMA_FUZZ_LOADER,
                          std::string(reinterpret_cast<const char*>(data), size), PNEUMA_RESOURCE_DIR);
  return 0;
}
