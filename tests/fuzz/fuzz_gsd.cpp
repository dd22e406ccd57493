// libFuzzer target for the GSD reader (PI 2.122): any byte string must give either a model or
// located errors, and every model operation must work on an accepted model.
//   build-fuzz/bin/fuzz_gsd -dict=tests/fuzz/gsd.dict -max_total_time=60 <scratch corpus dir> \
//     tests/data/gsd examples/gsd
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "pbvbus/gsd/gsd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pbvbus::devices;
  const GsdParseResult r = parse_gsd(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.gsd");
  if (r.ok() == !r.errors.empty()) __builtin_trap();
  if (!r.ok()) {
    for (const auto& e : r.errors)
      if (e.reason.empty()) __builtin_trap();
    return 0;
  }
  const GsdFile& f = *r.file;
  std::vector<std::size_t> all(f.modules().size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  auto p = f.user_prm_data(all);
  if (!p.ok()) __builtin_trap();
  auto c = f.cfg_data(all);
  if (!c.ok()) __builtin_trap();
  (void)f.check_modules(all);
  (void)f.prm_area_defaults(f.global_prm());
  return 0;
}
