// libFuzzer target for the scenario loader (Protocol Buffers text format + the semantic checks
// of tools/scenario.hpp and dp_plan.hpp): any byte string must give either a plan or errors,
// never a crash or an abort. The file name places it in examples/, so GSD paths of the seeds
// resolve and the DP planner runs on real GSD files.
//   build-fuzz/bin/fuzz_scenario -max_total_time=60 <scratch corpus dir> tests/fuzz/corpus/scenario
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "pbvbus/scenario/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pbvbus::tools;
  const LoadResult r = parse_scenario(std::string_view(reinterpret_cast<const char*>(data), size),
                                      PBVBUS_SOURCE_DIR "/examples/fuzz.textproto");
  if (r.ok() == !r.errors.empty()) __builtin_trap();
  for (const auto& e : r.errors)
    if (e.message.empty()) __builtin_trap();
  return 0;
}
