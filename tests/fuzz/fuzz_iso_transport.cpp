// libFuzzer target for the ISO-on-TCP transport codecs (stacks/s7): the TPKT reassembler
// (RFC 1006) over any byte stream and chunking, and the COTP CR/CC/DT/DR/DC/ER decoders on every
// TPDU it yields. Octet 0 picks the chunk size and the reassembler bound, the rest is the stream.
// Any broken invariant traps; the oracle is tests/stacks/s7/s7_oracle_helpers.cpp.
//   build-fuzz/bin/fuzz_iso_transport -max_total_time=60 <scratch dir>
//   tests/fuzz/corpus/iso_transport
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>

#include "s7_oracle_helpers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (const char* why = pbvbus::s7::test::iso_transport_oracle(std::span(data, size))) {
    std::fprintf(stderr, "iso transport oracle: %s\n", why);
    __builtin_trap();
  }
  return 0;
}
