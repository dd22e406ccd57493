// The addressing of every reply (groups.hpp reply_addressing_fault), checked by the runner on
// every exchange of every test (battery.cpp), whatever rule the test itself is about.
//
// protocol-facts.md §B.2: a response mirrors its request — response DA = request SA, response
// SA = request DA, response DSAP = request SSAP, response SSAP = request DSAP; without the
// extension bit the default SAP applies (Data_Exchange), and in DP practice an extension octet is
// one SAP with bits 7 and 6 clear (no region/segment octets unless the request had them).
//
// Decisions:
// - A reply without a DU may come without SAPs (an SD1 "RS: SAP not activated" cannot carry
//   them); a reply that carries data to a request with SAPs must carry the mirrored SAPs.
// - A reply to a request without SAPs (Data_Exchange) carries none.
// - SC (E5) has no address fields: nothing to check. A reply the codec rejects, or a request or
//   token in place of a reply, is the tests' business (reply_of: Bad).

#include "groups.hpp"
#include "report_util.hpp"

namespace pbvbus::conformance::detail {

namespace {

std::string sap_text(const std::optional<std::uint8_t>& s) {
  return s ? std::to_string(*s) : std::string("none");
}

}  // namespace

std::string reply_addressing_fault(const Exchange& e) {
  if (!e.answered || e.response_flags != 0 || e.response.empty() || e.request.empty()) return {};
  fdl::Telegram req, rsp;
  if (fdl::decode(e.request, req) != fdl::DecodeError::None) return {};
  if (fdl::decode(e.response, rsp) != fdl::DecodeError::None) return {};
  if (rsp.type == fdl::FrameType::SC || rsp.type == fdl::FrameType::SD4 || rsp.is_request()) return {};

  std::string why;
  auto add = [&](const std::string& s) { why += (why.empty() ? "" : "; ") + s; };
  if (rsp.da != req.sa)
    add("DA " + std::to_string(rsp.da) + " (expected " + std::to_string(req.sa) + " = the request's SA)");
  if (rsp.sa != req.da)
    add("SA " + std::to_string(rsp.sa) + " (expected " + std::to_string(req.da) + " = the request's DA)");
  const bool req_saps = req.dsap.has_value() || req.ssap.has_value();
  const bool rsp_saps = rsp.dsap.has_value() || rsp.ssap.has_value();
  if (!req_saps && rsp_saps) {
    add("DSAP " + sap_text(rsp.dsap) + ", SSAP " + sap_text(rsp.ssap) +
        " (expected none: the request used the default SAP)");
  } else if (req_saps && rsp_saps) {
    if (rsp.dsap != req.ssap || rsp.ssap != req.dsap)
      add("DSAP " + sap_text(rsp.dsap) + ", SSAP " + sap_text(rsp.ssap) + " (expected DSAP " +
          sap_text(req.ssap) + " = the request's SSAP, SSAP " + sap_text(req.dsap) +
          " = the request's DSAP)");
  } else if (req_saps && !rsp.data.empty()) {
    add("no SAPs on a reply with data (expected DSAP " + sap_text(req.ssap) + ", SSAP " +
        sap_text(req.dsap) + ")");
  }
  if ((rsp.da_segment && !req.sa_segment) || (rsp.sa_segment && !req.da_segment))
    add("a region/segment extension octet the request did not have (extension octets with bit 6 set)");
  if (why.empty()) return {};
  return "the reply to " + (e.note.empty() ? std::string("a request") : e.note) + " (" +
         hex_octets(e.response) + ") has " + why +
         " (protocol-facts.md §B.2: a response mirrors the request's addresses and SAPs)";
}

}  // namespace pbvbus::conformance::detail
