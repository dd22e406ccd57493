// Oracles for the S7 codecs (s7_oracle_helpers.hpp).
#include "s7_oracle_helpers.hpp"

#include <algorithm>
#include <vector>

#include "pbvbus/s7/cotp.hpp"
#include "pbvbus/s7/cotp_connect.hpp"
#include "pbvbus/s7/cotp_data.hpp"
#include "pbvbus/s7/cotp_disconnect.hpp"
#include "pbvbus/s7/s7_read_var.hpp"
#include "pbvbus/s7/s7_setup.hpp"
#include "pbvbus/s7/s7_szl.hpp"
#include "pbvbus/s7/s7_write_var.hpp"
#include "pbvbus/s7/tpkt.hpp"

namespace pbvbus::s7::test {
namespace {

using Bytes = std::vector<std::uint8_t>;

bool inside(std::span<const std::uint8_t> part, std::span<const std::uint8_t> whole) {
  return part.empty() ||
         (part.data() >= whole.data() && part.data() + part.size() <= whole.data() + whole.size());
}

bool same(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b) {
  return std::ranges::equal(a, b);
}

struct Framing {
  std::vector<Bytes> tpkts;
  Error error = Error::None;
  std::size_t error_offset = 0;
  bool over_bound = false;  ///< the reassembler held more than its bound
};

Framing frame(std::span<const std::uint8_t> stream, std::size_t chunk, std::size_t max) {
  Framing f;
  TpktReassembler r(max);
  std::size_t at = 0;
  while (at < stream.size()) {
    const auto piece = stream.subspan(at, std::min(chunk, stream.size() - at));
    const std::size_t n = r.feed(piece);
    at += n;
    if (r.pending() > r.max_length()) f.over_bound = true;
    if (r.ready()) {
      f.tpkts.emplace_back(r.tpkt().begin(), r.tpkt().end());
      r.pop();
    } else if (n == 0) {
      break;
    }
  }
  f.error = r.error();
  f.error_offset = r.error_offset();
  return f;
}

const char* check_tpdu(std::span<const std::uint8_t> tpdu) {
  const auto code = cotp_code(tpdu);
  if (!code.ok()) return nullptr;
  switch (code.value) {
    case kCotpCr: {
      const auto cr = decode_connect_request(tpdu);
      if (!cr.ok()) return nullptr;
      if (!inside(cr.value.calling_tsap, tpdu) || !inside(cr.value.called_tsap, tpdu))
        return "CR TSAP outside the TPDU";
      Bytes out;
      if (append_connect(out, confirm_for(cr.value, 1)) != Error::None) return "CC not encodable";
      const auto cc = decode_connect_confirm(out);
      if (!cc.ok()) return "CC does not decode";
      if (!same(cc.value.called_tsap, cr.value.called_tsap) ||
          !same(cc.value.calling_tsap, cr.value.calling_tsap))
        return "CC does not echo the TSAPs";
      if (cc.value.dst_ref != cr.value.src_ref) return "CC dst-ref is not the CR's src-ref";
      if (cc.value.tpdu_size_code > kTpduSizeClass0MaxCode) return "CC TPDU size above class 0";
      return nullptr;
    }
    case kCotpDt: {
      const auto dt = decode_data(tpdu);
      if (!dt.ok()) return nullptr;
      if (!inside(dt.value.user_data, tpdu)) return "DT user data outside the TPDU";
      Bytes out;
      append_data(out, dt.value.user_data, dt.value.eot);
      if (dt.value.number == 0 && !same(out, tpdu)) return "DT does not re-encode";
      return nullptr;
    }
    case kCotpDr:
    case kCotpDc: {
      const auto d = decode_disconnect(tpdu);
      if (!d.ok()) return nullptr;
      Bytes out;
      if (d.value.code == kCotpDr)
        append_disconnect_request(out, d.value.dst_ref, d.value.src_ref, d.value.reason);
      else
        append_disconnect_confirm(out, d.value.dst_ref, d.value.src_ref);
      const auto back = decode_disconnect(out);
      if (!back.ok() || back.value.dst_ref != d.value.dst_ref ||
          back.value.reason != d.value.reason)
        return "DR/DC does not round-trip";
      return nullptr;
    }
    case kCotpEr: {
      const auto e = decode_error_tpdu(tpdu);
      if (!e.ok()) return nullptr;
      if (!inside(e.value.invalid_tpdu, tpdu)) return "ER parameter outside the TPDU";
      Bytes out;
      append_error_tpdu(out, e.value.dst_ref, e.value.cause, e.value.invalid_tpdu);
      const auto back = decode_error_tpdu(out);
      if (!back.ok() || !same(back.value.invalid_tpdu, e.value.invalid_tpdu))
        return "ER does not round-trip";
      return nullptr;
    }
    default:
      return nullptr;
  }
}

bool documented_item_refusal(Error e) {
  return e == Error::S7ItemLengthMismatch || e == Error::S7ItemTooLong;
}

const char* check_read_var(const S7Pdu& pdu) {
  if (const auto r = decode_read_var_request(pdu); r.ok()) {
    const auto again = encode_read_var_request(pdu.header.pdu_ref, r.value);
    if (!again.ok()) return "Read Var request not re-encodable";
    const auto d = decode_s7_pdu(again.value);
    if (!d.ok()) return "re-encoded Read Var request is no PDU";
    const auto back = decode_read_var_request(d.value);
    if (!back.ok() || back.value != r.value) return "Read Var request does not round-trip";
  }
  if (const auto r = decode_read_var_response(pdu); r.ok()) {
    std::vector<ReadVarResult> results;
    for (const auto& it : r.value) {
      if (!inside(it.data, pdu.data)) return "Read Var data outside the data block";
      results.push_back({it.return_code, it.transport_size, it.data});
    }
    const auto again = encode_read_var_response(pdu.header.pdu_ref, results);
    if (!again.ok())
      return documented_item_refusal(again.error) ? nullptr : "Read Var response refused";
    const auto d = decode_s7_pdu(again.value);
    const auto back = d.ok() ? decode_read_var_response(d.value) : decltype(r){};
    if (!back.ok() || back.value.size() != r.value.size())
      return "Read Var response does not round-trip";
    for (std::size_t i = 0; i < r.value.size(); ++i) {
      if (back.value[i].return_code != r.value[i].return_code ||
          !same(back.value[i].data, r.value[i].data))
        return "Read Var response item changed";
    }
  }
  return nullptr;
}

const char* check_write_var(const S7Pdu& pdu) {
  if (const auto r = decode_write_var_request(pdu); r.ok()) {
    if (r.value.values.size() != r.value.items.size()) return "Write Var values != items";
    std::vector<WriteVarItem> items;
    for (std::size_t i = 0; i < r.value.items.size(); ++i) {
      if (!inside(r.value.values[i].data, pdu.data)) return "Write Var data outside the data block";
      items.push_back({r.value.items[i], r.value.values[i].transport_size, r.value.values[i].data});
    }
    const auto again = encode_write_var_request(pdu.header.pdu_ref, items);
    if (!again.ok())
      return documented_item_refusal(again.error) ? nullptr : "Write Var request refused";
    const auto d = decode_s7_pdu(again.value);
    const auto back = d.ok() ? decode_write_var_request(d.value) : decltype(r){};
    if (!back.ok() || back.value.items != r.value.items)
      return "Write Var request does not round-trip";
    for (std::size_t i = 0; i < items.size(); ++i)
      if (!same(back.value.values[i].data, r.value.values[i].data))
        return "Write Var value changed";
  }
  if (const auto r = decode_write_var_response(pdu); r.ok()) {
    const auto again = encode_write_var_response(pdu.header.pdu_ref, r.value);
    const auto d = again.ok() ? decode_s7_pdu(again.value) : Decoded<S7Pdu>{};
    const auto back = d.ok() ? decode_write_var_response(d.value) : decltype(r){};
    if (!back.ok() || back.value != r.value) return "Write Var response does not round-trip";
  }
  return nullptr;
}

const char* check_userdata(const S7Pdu& pdu) {
  if (const auto u = decode_userdata_params(pdu); u.ok()) {
    Bytes out;
    append_userdata_params(out, u.value);
    if (!same(out, pdu.params)) return "userdata parameters do not re-encode";
  }
  if (const auto r = decode_szl_request(pdu); r.ok()) {
    const auto again = encode_szl_request(pdu.header.pdu_ref, r.value);
    const auto d = again.ok() ? decode_s7_pdu(again.value) : Decoded<S7Pdu>{};
    const auto back = d.ok() ? decode_szl_request(d.value) : decltype(r){};
    if (!back.ok() || back.value != r.value) return "SZL request does not round-trip";
  }
  if (const auto r = decode_szl_response(pdu); r.ok()) {
    if (!inside(r.value.records, pdu.data)) return "SZL records outside the data block";
    const bool whole =
        r.value.records.size() == std::size_t{r.value.record_length} * r.value.record_count;
    if (r.value.error_code == 0 && !whole) return nullptr;  // a part of a list: not re-encodable
    const auto again = encode_szl_response(pdu.header.pdu_ref, r.value);
    if (!again.ok()) return "SZL response refused";
    const auto d = decode_s7_pdu(again.value);
    const auto back = d.ok() ? decode_szl_response(d.value) : decltype(r){};
    if (!back.ok() || back.value.error_code != r.value.error_code || back.value.id != r.value.id ||
        !same(back.value.records, r.value.records))
      return "SZL response does not round-trip";
  }
  return nullptr;
}

}  // namespace

const char* iso_transport_oracle(std::span<const std::uint8_t> in) {
  if (in.empty()) return nullptr;
  const std::size_t chunk = 1 + (in[0] & 0x0F);
  const std::size_t max = (in[0] & 0x10) ? 64 : kTpktDefaultMaxLength;
  const auto stream = in.subspan(1);
  const Framing whole = frame(stream, stream.size() + 1, max);
  const Framing chunked = frame(stream, chunk, max);
  if (whole.over_bound || chunked.over_bound) return "reassembler held more than its bound";
  if (whole.tpkts != chunked.tpkts) return "chunking changed the TPKTs";
  if (whole.error != chunked.error || whole.error_offset != chunked.error_offset)
    return "chunking changed the error";
  for (const auto& t : whole.tpkts) {
    if (t.size() < kTpktMinLength || t.size() > max) return "TPKT outside its bounds";
    if (t[0] != kTpktVersion || (std::size_t{t[2]} << 8 | t[3]) != t.size())
      return "TPKT header disagrees with its size";
    if (const char* why = check_tpdu(std::span(t).subspan(kTpktHeaderLength))) return why;
  }
  // The stream itself read as one TPDU too (no TPKT in front).
  return check_tpdu(stream);
}

const char* s7_pdu_oracle(std::span<const std::uint8_t> in) {
  const auto p = decode_s7_pdu(in);
  if (!p.ok()) {
    if (p.at > in.size()) return "error offset past the input";
    return nullptr;
  }
  const auto& pdu = p.value;
  if (!inside(pdu.params, in) || !inside(pdu.data, in)) return "blocks outside the PDU";
  const auto again = encode_s7_pdu(pdu.header, pdu.params, pdu.data);
  if (!again.ok() || again.value.size() != in.size()) return "PDU does not re-encode";
  if (!std::equal(again.value.begin() + 4, again.value.end(), in.begin() + 4) ||
      again.value[0] != in[0] || again.value[1] != in[1])
    return "re-encoded PDU differs outside the reserved word";
  if (const auto s = decode_setup_communication(pdu); s.ok()) {
    const auto e = pdu.header.type == kS7Job ? encode_setup_communication_request(0, s.value)
                                             : encode_setup_communication_response(0, s.value);
    const auto d = decode_s7_pdu(e.value);
    if (!d.ok() || decode_setup_communication(d.value).value != s.value)
      return "Setup Communication does not round-trip";
  }
  if (const char* why = check_read_var(pdu)) return why;
  if (const char* why = check_write_var(pdu)) return why;
  return check_userdata(pdu);
}

}  // namespace pbvbus::s7::test
