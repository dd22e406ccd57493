// The whole reference exchange of tools-and-formats.md §3.4 through the codecs as the coming
// ISO-on-TCP door will chain them: client octets in arbitrary chunks -> TPKT reassembly ->
// COTP -> S7 -> an answer built with the encoders -> exactly the reference server octets.
#include <gtest/gtest.h>

#include "hex.hpp"

#include "pbvbus/s7/cotp.hpp"
#include "pbvbus/s7/cotp_connect.hpp"
#include "pbvbus/s7/cotp_data.hpp"
#include "pbvbus/s7/s7_read_var.hpp"
#include "pbvbus/s7/s7_setup.hpp"
#include "pbvbus/s7/tpkt.hpp"
#include "pbvbus/s7/tsap.hpp"

namespace pbvbus::s7 {
namespace {

using test::hex;
using Bytes = std::vector<std::uint8_t>;

const Bytes kClient = hex(
    "03 00 00 16 11 E0 00 00 00 01 00 C0 01 0A C1 02 01 00 C2 02 01 02"
    "03 00 00 19 02 F0 80 32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 01 E0"
    "03 00 00 1F 02 F0 80 32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 04 00 01 84 00 00 00");
const Bytes kServer =
    hex("03 00 00 16 11 D0 00 01 00 01 00 C0 01 0A C1 02 01 00 C2 02 01 02"
        "03 00 00 1B 02 F0 80 32 03 00 00 00 00 00 08 00 00 00 00 F0 00 00 01 00 01 00 F0"
        "03 00 00 1D 02 F0 80 32 03 00 00 00 01 00 02 00 08 00 00 04 01 FF 04 00 20 DE AD BE EF");

// A toy CPU in slot 2 with DB1 = DE AD BE EF and PDU size 240: just enough server to answer.
class ToyServer {
 public:
  Bytes out;

  void on_tpkt(std::span<const std::uint8_t> tpdu) {
    const auto code = cotp_code(tpdu);
    ASSERT_TRUE(code.ok());
    if (code.value == kCotpCr) {
      const auto cr = decode_connect_request(tpdu);
      ASSERT_TRUE(cr.ok());
      const auto called = parse_s7_tsap(cr.value.called_tsap);
      ASSERT_TRUE(called && called->rack == 0 && called->slot == 2);
      Bytes cc;
      ASSERT_EQ(append_connect(cc, confirm_for(cr.value, 1)), Error::None);
      ASSERT_EQ(append_tpkt(out, cc), Error::None);
      return;
    }
    const auto dt = decode_data(tpdu);
    ASSERT_TRUE(dt.ok() && dt.value.eot);
    const auto pdu = decode_s7_pdu(dt.value.user_data);
    ASSERT_TRUE(pdu.ok());
    Encoded answer;
    if (const auto setup = decode_setup_communication(pdu.value); setup.ok()) {
      answer = encode_setup_communication_response(pdu.value.header.pdu_ref,
                                                   negotiate(setup.value, {1, 1, 240}));
    } else {
      const auto items = decode_read_var_request(pdu.value);
      ASSERT_TRUE(items.ok());
      std::vector<ReadVarResult> results;
      for (const auto& it : items.value) {
        const bool db1 = it.area == area::kDataBlock && it.db_number == 1;
        const std::size_t n = element_size(it.transport_size) * it.count;
        if (!db1) {
          results.push_back({return_code::kObjectDoesNotExist, data_transport::kNull, {}});
        } else if (it.byte_offset() + n > db1_.size()) {
          results.push_back({return_code::kAddressOutOfRange, data_transport::kNull, {}});
        } else {
          results.push_back({return_code::kSuccess, data_transport_for(it.transport_size),
                             std::span(db1_).subspan(it.byte_offset(), n)});
        }
      }
      answer = encode_read_var_response(pdu.value.header.pdu_ref, results);
    }
    ASSERT_TRUE(answer.ok());
    const auto frame = encode_tpkt_data(answer.value);
    ASSERT_TRUE(frame.ok());
    out.insert(out.end(), frame.value.begin(), frame.value.end());
  }

 private:
  Bytes db1_ = hex("DE AD BE EF");
};

Bytes serve(std::size_t chunk) {
  TpktReassembler r;
  ToyServer server;
  std::span<const std::uint8_t> rest(kClient);
  while (!rest.empty()) {
    const std::size_t n = r.feed(rest.first(std::min(chunk, rest.size())));
    rest = rest.subspan(n);
    if (r.ready()) {
      server.on_tpkt(r.payload());
      r.pop();
    } else if (n == 0) {
      ADD_FAILURE() << to_string(r.error());
      break;
    }
  }
  return server.out;
}

TEST(IsoExchange, ReferenceConversationByteForByteWhateverTheChunking) {
  for (std::size_t chunk = 1; chunk <= kClient.size(); ++chunk) {
    ASSERT_EQ(serve(chunk), kServer) << "chunk " << chunk;
  }
}

}  // namespace
}  // namespace pbvbus::s7
