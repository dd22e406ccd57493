#pragma once
// Oracles over arbitrary input for the S7 codecs, shared by the seeded mutation test
// (s7_mutation_parser_test.cpp, gcc and the sanitizer builds) and the libFuzzer targets
// (tests/fuzz/fuzz_iso_transport.cpp, fuzz_s7_pdu.cpp). Each returns nullptr when every
// invariant held, else a fixed text naming the broken one.
#include <cstdint>
#include <span>

namespace pbvbus::s7::test {

/// Octet 0 chooses a chunking and a reassembler bound; the rest is a TCP byte stream. The
/// TPKTs must be the same whether the stream is fed whole or in chunks, stay within the bound,
/// and every TPDU in them must decode without reading outside it; an accepted CR's CC decodes
/// back with the echoed TSAPs, an accepted DT/DR/DC/ER re-encodes to what was decoded.
const char* iso_transport_oracle(std::span<const std::uint8_t> in);

/// The input is one S7 PDU. Whatever a decoder accepts must re-encode (or be refused with a
/// documented encoder error) and decode again to the same values; spans stay inside the input.
const char* s7_pdu_oracle(std::span<const std::uint8_t> in);

}  // namespace pbvbus::s7::test
