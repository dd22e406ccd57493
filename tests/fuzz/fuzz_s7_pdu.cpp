// libFuzzer target for the S7 PDU codecs (stacks/s7): header, Setup Communication, Read Var,
// Write Var, Userdata/Read SZL. The input is one S7 PDU; whatever a decoder accepts must
// re-encode and decode to the same values, with every span inside the input. Any broken
// invariant traps; the oracle is tests/stacks/s7/s7_oracle_helpers.cpp.
//   build-fuzz/bin/fuzz_s7_pdu -max_total_time=60 <scratch dir> tests/fuzz/corpus/s7_pdu
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>
#include <vector>

#include "s7_oracle_helpers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // An exact-size heap copy so ASan sees any read past the PDU's end.
  const std::vector<std::uint8_t> pdu(data, data + size);
  if (const char* why = pbvbus::s7::test::s7_pdu_oracle(pdu)) {
    std::fprintf(stderr, "s7 pdu oracle: %s\n", why);
    __builtin_trap();
  }
  return 0;
}
