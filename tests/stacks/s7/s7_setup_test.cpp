// Setup Communication (protocol-facts.md §H.4; tools-and-formats.md §3.4; stacks/s7).
#include "pbvbus/s7/s7_setup.hpp"

#include <gtest/gtest.h>

#include "hex.hpp"

#include "pbvbus/s7/cotp_data.hpp"

namespace pbvbus::s7 {
namespace {

using test::hex;

Decoded<SetupCommunication> setup_of(const std::vector<std::uint8_t>& pdu) {
  const auto d = decode_s7_pdu(pdu);
  if (!d.ok()) return {{}, d.error, d.at};
  return decode_setup_communication(d.value);
}

// §3.4: "Setup comm req : 03 00 00 19 02 F0 80 32 01 ... F0 00 00 01 00 01 01 E0"
TEST(S7Setup, ReferenceRequestDecodesAndEncodes) {
  const auto frame =
      hex("03 00 00 19 02 F0 80 32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 01 E0");
  const auto s = setup_of(std::vector<std::uint8_t>(frame.begin() + 7, frame.end()));
  ASSERT_TRUE(s.ok()) << to_string(s.error);
  EXPECT_EQ(s.value, (SetupCommunication{1, 1, 480}));
  const auto pdu = encode_setup_communication_request(0, s.value);
  ASSERT_TRUE(pdu.ok());
  EXPECT_EQ(encode_tpkt_data(pdu.value).value, frame);
}

// §3.4: "Setup comm resp : 03 00 00 1B 02 F0 80 32 03 ... F0 00 00 01 00 01 00 F0 (PDU 240)":
// a CPU that can do 240 answers the client's 480 with the lower value.
TEST(S7Setup, ServerAnswersTheLowerPduLength) {
  const SetupCommunication own{1, 1, 240};
  const auto answer = negotiate(SetupCommunication{1, 1, 480}, own);
  EXPECT_EQ(answer, (SetupCommunication{1, 1, 240}));
  const auto pdu = encode_setup_communication_response(0, answer);
  ASSERT_TRUE(pdu.ok());
  EXPECT_EQ(
      encode_tpkt_data(pdu.value).value,
      hex("03 00 00 1B 02 F0 80 32 03 00 00 00 00 00 08 00 00 00 00 F0 00 00 01 00 01 00 F0"));
  const auto back = setup_of(pdu.value);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back.value, answer);
}

// nodes7 0.3.18 asks for AmQ 8/8 and PDU 960 (tools-and-formats.md §3.4, composed here with
// PDU reference 0); libnodave sends F0 00 00 01 00 01 03 C0 (1/1, 960; protocol-facts §H.4).
TEST(S7Setup, Nodes7AndLibnodaveRequests) {
  const auto nodes7 = setup_of(hex("32 01 00 00 00 00 00 08 00 00 | F0 00 00 08 00 08 03 C0"));
  ASSERT_TRUE(nodes7.ok());
  EXPECT_EQ(nodes7.value, (SetupCommunication{8, 8, 960}));
  EXPECT_EQ(negotiate(nodes7.value, SetupCommunication{3, 3, 480}),
            (SetupCommunication{3, 3, 480}));
  const auto dave = setup_of(hex("32 01 00 00 00 00 00 08 00 00 | F0 00 00 01 00 01 03 C0"));
  ASSERT_TRUE(dave.ok());
  EXPECT_EQ(dave.value, (SetupCommunication{1, 1, 960}));
  EXPECT_EQ(negotiate(dave.value, SetupCommunication{8, 8, 960}), dave.value);
}

TEST(S7Setup, Errors) {
  struct Case {
    const char* octets;
    Error error;
    std::size_t at;
  } cases[] = {
      {"32 07 00 00 00 00 00 08 00 00 | F0 00 00 01 00 01 01 E0", Error::S7WrongPduType, 1},
      {"32 02 00 00 00 00 00 00 00 00 00 00", Error::S7WrongPduType, 1},
      {"32 01 00 00 00 00 00 00 00 00", Error::S7BadParameterLength, 6},
      {"32 01 00 00 00 00 00 08 00 00 | 04 00 00 01 00 01 01 E0", Error::S7UnexpectedFunction, 10},
      {"32 01 00 00 00 00 00 07 00 00 | F0 00 00 01 00 01 01", Error::S7BadParameterLength, 6},
      {"32 01 00 00 00 00 00 08 00 01 | F0 00 00 01 00 01 01 E0 | 00", Error::S7UnexpectedData, 18},
  };
  for (const auto& c : cases) {
    const auto s = setup_of(hex(c.octets));
    EXPECT_EQ(s.error, c.error) << c.octets << ": " << to_string(s.error);
    EXPECT_EQ(s.at, c.at) << c.octets;
  }
}

}  // namespace
}  // namespace pbvbus::s7
