#include "pbvbus/conformance/replay_input.hpp"

#include <algorithm>

#include "pbvbus/captures/pcapng_format.hpp"
#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/dp/sap.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::conformance {

namespace {

namespace pcapng = captures::pcapng;

bool is_line_interface(const captures::PcapngInterface& i) {
  return i.link_type == static_cast<std::uint16_t>(pcapng::LinkType::User0) ||
         i.link_type == static_cast<std::uint16_t>(pcapng::LinkType::ProfibusDl);
}

std::optional<bus::Baud> baud_of(std::uint64_t speed) {
  for (bus::Baud b : bus::kAllBauds)
    if (static_cast<std::uint64_t>(b) == speed) return b;
  return std::nullopt;
}

/// ns → ticks, rounded to the nearest whole bit time of `baud`; ns in [0, kMaxSpanNs]. Split
/// into whole seconds and the rest so that nothing overflows (rest · baud < 1.2e16).
bus::Ticks ns_to_ticks(std::int64_t ns, bus::Baud baud) {
  const std::int64_t b = static_cast<std::int64_t>(baud);
  const std::int64_t bits = (ns / 1'000'000'000) * b + ((ns % 1'000'000'000) * b + 500'000'000) / 1'000'000'000;
  return bus::bits_to_ticks(bits, baud);
}

std::string flag_reason(std::uint32_t flags) {
  std::string s;
  auto add = [&](std::uint32_t bit, const char* what) {
    if ((flags & bit) == 0) return;
    if (!s.empty()) s += ", ";
    s += what;
  };
  add(pcapng::kFlagSymbolError, "symbol error");
  add(pcapng::kFlagPreambleError, "preamble error");
  add(pcapng::kFlagStartDelimiterError, "start delimiter error");
  add(pcapng::kFlagUnalignedError, "unaligned frame error");
  add(pcapng::kFlagWrongIfg, "wrong inter-frame gap");
  add(pcapng::kFlagTooShort, "packet too short");
  add(pcapng::kFlagTooLong, "packet too long");
  add(pcapng::kFlagCrcError, "CRC error");
  if (s.empty()) s = "link-layer error bits";
  return s;
}

void decode_into(ReplayFrame& f) {
  fdl::Telegram t;
  const fdl::DecodeError e = fdl::decode(f.bytes, t);
  if (e != fdl::DecodeError::None) {
    f.role = ReplayRole::Unusable;
    f.unusable_reason = "not a valid telegram: " + std::string(fdl::to_string(e));
    return;
  }
  f.type = f.bytes[0];
  f.da = t.da;
  f.sa = t.sa;
  f.fc = t.fc;
  f.dsap = t.dsap;
  f.ssap = t.ssap;
  f.du_len = t.data.size();
  f.du_offset = t.data.empty() ? 0 : static_cast<std::size_t>(t.data.data() - f.bytes.data());
  if (t.type == fdl::FrameType::SD4) {
    f.role = ReplayRole::Token;
  } else if (t.is_request()) {
    f.role = ReplayRole::Request;
    f.expects_reply = fdl::fn_expects_reply(fdl::fc_request_fn(t.fc)) && t.da != fdl::kBroadcast;
  } else {
    f.role = ReplayRole::Response;
  }
}

}  // namespace

const char* replay_role_name(ReplayRole r) {
  switch (r) {
    case ReplayRole::Token: return "token";
    case ReplayRole::Request: return "request";
    case ReplayRole::Response: return "response";
    case ReplayRole::Unusable: return "unusable";
  }
  return "?";
}

std::size_t ReplayInput::count(ReplayRole r) const {
  return static_cast<std::size_t>(
      std::count_if(frames.begin(), frames.end(), [r](const ReplayFrame& f) { return f.role == r; }));
}

std::size_t ReplayInput::comparable_requests() const {
  return static_cast<std::size_t>(std::count_if(frames.begin(), frames.end(), [](const ReplayFrame& f) {
    return f.role == ReplayRole::Request && f.expects_reply && !f.reply_unusable;
  }));
}

std::optional<ReplayInput> build_replay_input(std::span<const std::uint8_t> data,
                                              const ReplayInputOptions& opts, std::string& error) {
  captures::PcapngReader reader(std::vector<std::uint8_t>(data.begin(), data.end()));
  ReplayInput in;
  captures::PcapngRecord r;
  std::vector<captures::PcapngRecord> records;
  std::size_t count = 0;
  bool have_line = false;
  std::optional<std::int64_t> first_ns;
  while (reader.next(r)) {
    const std::size_t index = count++;
    const auto& ifs = reader.interfaces();
    if (r.interface >= ifs.size()) {  // the reader guarantees this; be safe anyway
      ++in.ignored_records;
      continue;
    }
    const auto& itf = ifs[r.interface];
    if (!have_line && is_line_interface(itf) && (opts.line.empty() || itf.name == opts.line)) {
      have_line = true;
      in.line = itf.name;
      in.interface = r.interface;
    }
    if (!have_line || r.interface != in.interface) {
      ++in.ignored_records;
      continue;
    }
    ReplayFrame f;
    f.record = index;
    f.offset = r.offset;
    f.ts_ns = r.ts_ns;
    f.bytes = r.bytes;
    if (!first_ns) first_ns = r.ts_ns;
    // Relative time, checked before any arithmetic that could overflow.
    const bool ts_ok = r.ts_ns >= *first_ns && r.ts_ns - *first_ns <= kMaxSpanNs;
    const std::int64_t rel = ts_ok ? r.ts_ns - *first_ns : 0;
    f.start = rel;  // ns for now: the baud is known once the line's interface is
    if ((r.flags & pcapng::kFlagErrorMask) != 0) {
      f.unusable_reason = r.comment.empty() ? flag_reason(r.flags) : r.comment;
    } else if (r.orig_len > r.bytes.size()) {
      f.unusable_reason = "cut short: " + std::to_string(r.bytes.size()) + " of " +
                          std::to_string(r.orig_len) + " octets captured";
    } else if (!ts_ok) {
      f.unusable_reason = "timestamp out of order or out of range";
    } else if (!in.frames.empty() && f.start < in.frames.back().start) {
      f.unusable_reason = "timestamp before the previous frame's";
    }
    in.frames.push_back(std::move(f));
  }
  for (const auto& itf : reader.interfaces())
    if (is_line_interface(itf)) in.lines.push_back(itf.name);
  if (reader.error()) {
    if (in.frames.empty()) {
      error = reader.error()->to_string();
      return std::nullopt;
    }
    in.read_error = reader.error()->to_string();
  }
  if (!have_line) {
    if (!opts.line.empty()) {
      error = "the capture has no line '" + opts.line + "'";
      if (!in.lines.empty()) {
        error += " (lines:";
        for (const auto& n : in.lines) error += " " + n;
        error += ")";
      }
    } else {
      error = "the capture has no line (no USER0/147 or PROFIBUS_DL/257 interface with frames)";
    }
    return std::nullopt;
  }
  const auto& itf = reader.interfaces().at(in.interface);
  const auto baud = baud_of(itf.speed);
  if (!baud) {
    error = "line '" + in.line + "': if_speed " + std::to_string(itf.speed) +
            " is not a PROFIBUS baud rate";
    return std::nullopt;
  }
  in.baud = *baud;
  in.tsl = opts.tsl ? *opts.tsl : fdl::BusParams::defaults(*baud).tsl;
  const bus::Ticks bit = bus::ticks_per_bit(*baud);
  for (ReplayFrame& f : in.frames) {
    f.start = ns_to_ticks(f.start, *baud);
    f.end = f.start + static_cast<bus::Ticks>(f.bytes.size()) * bus::kBitsPerChar * bit;
    if (f.unusable_reason.empty()) decode_into(f);
  }
  // Pairing: only the frame immediately before can be the request a frame answers.
  for (std::size_t i = 1; i < in.frames.size(); ++i) {
    ReplayFrame& f = in.frames[i];
    ReplayFrame& q = in.frames[i - 1];
    if (q.role != ReplayRole::Request || !q.expects_reply || q.reply >= 0 || q.reply_unusable)
      continue;
    if (f.start < q.end || f.start - q.end > static_cast<bus::Ticks>(in.tsl) * bit) continue;
    if (f.role == ReplayRole::Unusable) {
      q.reply_unusable = true;
      f.request = static_cast<int>(i - 1);
      continue;
    }
    if (f.role != ReplayRole::Response) continue;
    if (f.type != fdl::kSC && (f.sa != q.da || f.da != q.sa)) continue;
    q.reply = static_cast<int>(i);
    f.request = static_cast<int>(i - 1);
  }
  bool any_usable = false;
  for (const ReplayFrame& f : in.frames) any_usable |= f.role != ReplayRole::Unusable;
  if (!any_usable) {
    error = "line '" + in.line + "' has no usable frame";
    return std::nullopt;
  }
  return in;
}

std::string replay_service_name(const ReplayFrame& q) {
  if (q.role == ReplayRole::Token) return "Token";
  if (q.role != ReplayRole::Request) return replay_role_name(q.role);
  const auto fn = fdl::fc_request_fn(q.fc);
  if (fn == fdl::RequestFn::FdlStatus) return "FDL_Status";
  if (fn == fdl::RequestFn::Ident) return "Ident";
  if (fn == fdl::RequestFn::LsapStatus) return "LSAP_Status";
  if (!q.dsap) {
    if (fn == fdl::RequestFn::SrdLow || fn == fdl::RequestFn::SrdHigh) return "Data_Exchange";
    return std::string(fdl::to_string(fn));
  }
  const std::uint8_t s = *q.dsap;
  switch (s) {
    case dp::kSapSetSlaveAdd: return "Set_Slave_Add";
    case dp::kSapRdInp: return "Rd_Inp";
    case dp::kSapRdOutp: return "Rd_Outp";
    case dp::kSapGlobalControl: return "Global_Control";
    case dp::kSapGetCfg: return "Get_Cfg";
    case dp::kSapSlaveDiag: return "Slave_Diag";
    case dp::kSapSetPrm: return "Set_Prm";
    case dp::kSapChkCfg: return "Chk_Cfg";
    case dp::kSapC1ReadWrite: return "MSAC_C1";
    case dp::kSapC1Alarm: return "Alarm_Ack";
    case dp::kSapC2ResourceManager: return "MSAC_C2_Initiate";
    case dp::kSapMm: return "Master_Master";
    case dp::kSapExtUserPrm: return "Ext_User_Prm";
    default: break;
  }
  if (s <= dp::kSapC2ConnectionHigh) return "MSAC_C2";
  return "SAP " + std::to_string(s);
}

}  // namespace pbvbus::conformance
