#include "timeline_mpi.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <tuple>

#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::captures {

namespace {

/// DP SAPs (protocol-facts.md §D SAP table: the DP-V0/DP-V1 service SAPs 49..62, the class-2
/// master's SAP 50 on every MSAC_C2 frame) and the global SAP 63.
constexpr std::uint8_t kFirstDpSap = 49;

std::string_view s7_function_name(std::uint8_t f) {
  switch (f) {
    case 0xF0:
      return "Setup communication";
    case 0x04:
      return "Read Var";
    case 0x05:
      return "Write Var";
    case 0x00:
      return "CPU services";
    default:
      return {};
  }
}

std::string_view s7_rosctr_name(std::uint8_t r) {
  switch (r) {
    case 1:
      return "job";
    case 2:
      return "ack";
    case 3:
      return "ack-data";
    case 7:
      return "userdata";
    default:
      return {};
  }
}

std::string addr(std::uint8_t a, int sap) {
  return std::to_string(a) + ":" + (sap < 0 ? std::string("?") : std::to_string(sap));
}

}  // namespace

std::string mpi_pdu_words(const mpi::Pdu& p) {
  switch (p.type) {
    case mpi::PduType::ConnectRequest:
      return "connect request";
    case mpi::PduType::ConnectConfirm:
      return "connect confirm";
    case mpi::PduType::ConnectionAck:
      return "connection ack";
    case mpi::PduType::Data:
      return "data " + std::to_string(p.message_number);
    case mpi::PduType::DataAck:
      return "data ack " + std::to_string(p.message_number);
    case mpi::PduType::DisconnectRequest:
      return "disconnect request";
  }
  return "?";
}

namespace {

std::uint8_t first_octet(mpi::PduType t) {
  switch (t) {
    case mpi::PduType::ConnectRequest:
      return mpi::kConnectRequest;
    case mpi::PduType::ConnectConfirm:
      return mpi::kConnectConfirm;
    case mpi::PduType::ConnectionAck:
      return mpi::kConnectionAck;
    case mpi::PduType::Data:
      return mpi::kData;
    case mpi::PduType::DataAck:
      return mpi::kDataAck;
    case mpi::PduType::DisconnectRequest:
      return mpi::kDisconnectRequest;
  }
  return 0;
}

struct Work {
  MpiConnection c;
  bool open = false;  ///< a span is running (the last of c.spans)
};

void close_span(Work& w, std::int64_t at) {
  if (!w.open) return;
  w.c.spans.back().end_ns = std::max(w.c.spans.back().start_ns, at);
  w.open = false;
}

/// A new span from `at`, or from the end of the row's last span if that is later (a connect
/// confirm opens its span at the connect request, which may lie before PDUs already seen).
void open_span(Work& w, std::int64_t at, MpiState s) {
  close_span(w, at);
  // A span closed at the instant it opened says nothing.
  if (!w.c.spans.empty() && w.c.spans.back().end_ns == w.c.spans.back().start_ns)
    w.c.spans.pop_back();
  if (!w.c.spans.empty()) at = std::max(at, w.c.spans.back().end_ns);
  w.c.spans.push_back({at, at, s});
  w.open = true;
}

}  // namespace

std::string_view mpi_pdu_name(mpi::PduType t) {
  switch (t) {
    case mpi::PduType::ConnectRequest:
      return "Connect request";
    case mpi::PduType::ConnectConfirm:
      return "Connect confirm";
    case mpi::PduType::ConnectionAck:
      return "Connection ack";
    case mpi::PduType::Data:
      return "Data";
    case mpi::PduType::DataAck:
      return "Data ack";
    case mpi::PduType::DisconnectRequest:
      return "Disconnect request";
  }
  return "?";
}

bool is_mpi_description(std::string_view d) {
  return d.substr(0, 3) == "MPI";
}

std::optional<MpiFrame> mpi_frame(std::span<const std::uint8_t> bytes, bool marked) {
  fdl::Telegram t;
  if (fdl::decode(bytes, t) != fdl::DecodeError::None) return std::nullopt;
  if (t.type != fdl::FrameType::SD2 && t.type != fdl::FrameType::SD3) return std::nullopt;
  if (!t.is_request() || t.fc == fdl::kFcClockValue) return std::nullopt;
  const auto fn = fdl::fc_request_fn(t.fc);
  if (fn != fdl::RequestFn::SrdHigh && fn != fdl::RequestFn::SrdLow) return std::nullopt;
  if (!t.dsap || !t.ssap) return std::nullopt;
  if (!marked && (*t.dsap >= kFirstDpSap || *t.ssap >= kFirstDpSap)) return std::nullopt;
  MpiFrame f;
  if (mpi::decode(t.data, f.pdu) != mpi::DecodeError::None) return std::nullopt;
  if (f.pdu.type == mpi::PduType::ConnectRequest && *t.dsap != mpi::kConnectSap)
    return std::nullopt;
  f.sa = t.sa;
  f.ssap = *t.ssap;
  f.da = t.da;
  f.dsap = *t.dsap;
  return f;
}

std::string s7_summary(std::span<const std::uint8_t> s7) {
  if (s7.size() < 10 || s7[0] != 0x32) return {};
  const std::uint8_t rosctr = s7[1];
  const std::string_view rn = s7_rosctr_name(rosctr);
  std::string o = "S7 " + (rn.empty() ? "ROSCTR " + std::to_string(rosctr) : std::string(rn));
  const bool ack = rosctr == 2 || rosctr == 3;
  const std::size_t hl = ack ? 12 : 10;
  if (s7.size() < hl) return o;
  char buf[48];
  if (ack && (s7[10] != 0 || s7[11] != 0)) {
    std::snprintf(buf, sizeof buf, " error 0x%02X/0x%02X", unsigned{s7[10]}, unsigned{s7[11]});
    o += buf;
  }
  const std::size_t plen = (static_cast<std::size_t>(s7[6]) << 8) | s7[7];
  if (plen == 0 || s7.size() <= hl || rosctr == 7) return o;
  const std::uint8_t func = s7[hl];
  const std::string_view fname = s7_function_name(func);
  if (fname.empty()) {
    std::snprintf(buf, sizeof buf, " function 0x%02X", unsigned{func});
    o += buf;
  } else {
    o += " " + std::string(fname);
  }
  if ((func == 0x04 || func == 0x05) && plen >= 2 && s7.size() > hl + 1) {
    const unsigned n = s7[hl + 1];
    o += ", " + std::to_string(n) + (n == 1 ? " item" : " items");
  }
  return o;
}

std::string mpi_connection_label(const MpiConnection& c) {
  return addr(c.initiator, c.initiator_sap) + "\u2194" + addr(c.responder, c.responder_sap);
}

std::vector<MpiConnection> mpi_connections(const std::vector<TimelineFrame>& frames, bool marked,
                                           std::int64_t lane_end, std::int64_t from, i128 to) {
  using Key = std::tuple<int, int, int, int>;  // initiator, its SAP, responder, its SAP
  std::map<Key, Work> rows;
  struct Pending {
    std::int64_t ts;
    MpiMark mark;
  };
  std::map<std::tuple<int, int, int>, std::vector<Pending>> pending;  // unconfirmed requests
  auto row = [&](int a, int s, int b, int r, bool setup) -> Work& {
    auto [it, fresh] = rows.try_emplace(Key{a, s, b, r});
    if (fresh) {
      it->second.c.initiator = static_cast<std::uint8_t>(a);
      it->second.c.initiator_sap = static_cast<std::uint8_t>(s);
      it->second.c.responder = static_cast<std::uint8_t>(b);
      it->second.c.responder_sap = r;
    }
    if (setup) it->second.c.setup_seen = true;
    return it->second;
  };
  for (const TimelineFrame& f : frames) {
    if (f.kind != FrameKind::Request || f.mpi.empty()) continue;  // make_frame() found no MPI
    const auto m = mpi_frame(f.bytes, marked);
    if (!m) continue;
    const mpi::Pdu& p = m->pdu;
    MpiMark mark;
    mark.ts_ns = f.start_ns;
    mark.pdu = first_octet(p.type);
    if (p.type == mpi::PduType::Data || p.type == mpi::PduType::DataAck) mark.nr = p.message_number;
    mark.text = mpi_pdu_words(p) + " " + addr(m->sa, m->ssap) + "\u2192" + addr(m->da, m->dsap);
    if (p.type == mpi::PduType::Data) {
      const std::string s7 = s7_summary(p.data);
      if (!s7.empty()) mark.text += ": " + s7;
    }
    if (p.type == mpi::PduType::ConnectRequest) {
      // A new request of a connection that is up ends its span (the PG restarted).
      for (auto& [k, w] : rows)
        if (std::get<0>(k) == m->sa && std::get<1>(k) == m->ssap && std::get<2>(k) == m->da)
          close_span(w, f.start_ns);
      pending[{m->sa, m->ssap, m->da}].push_back({f.start_ns, std::move(mark)});
      continue;
    }
    if (p.type == mpi::PduType::ConnectConfirm) {
      Work& w = row(m->da, m->dsap, m->sa, m->ssap, true);
      auto pit = pending.find({m->da, m->dsap, m->sa});
      std::int64_t start = f.start_ns;
      if (pit != pending.end() && !pit->second.empty()) {
        start = pit->second.back().ts;
        // Earlier unanswered requests of the same PG SAP belong to this attempt as well.
        for (Pending& q : pit->second) w.c.marks.push_back(std::move(q.mark));
        pending.erase(pit);
      }
      open_span(w, start, MpiState::Connecting);
      mark.from_initiator = false;
      w.c.marks.push_back(std::move(mark));
      continue;
    }
    Work* w = nullptr;
    bool from_init = true;
    if (auto it = rows.find(Key{m->sa, m->ssap, m->da, m->dsap}); it != rows.end()) {
      w = &it->second;
    } else if (auto jt = rows.find(Key{m->da, m->dsap, m->sa, m->ssap}); jt != rows.end()) {
      w = &jt->second;
      from_init = false;
    } else {
      w = &row(m->sa, m->ssap, m->da, m->dsap, false);
    }
    mark.from_initiator = from_init;
    switch (p.type) {
      case mpi::PduType::ConnectionAck:
        if (!from_init && w->open && w->c.spans.back().state == MpiState::Connecting)
          open_span(*w, f.start_ns, MpiState::Connected);
        break;
      case mpi::PduType::Data:
      case mpi::PduType::DataAck:
        if (!w->open || w->c.spans.back().state != MpiState::Connected)
          open_span(*w, f.start_ns, MpiState::Connected);
        break;
      case mpi::PduType::DisconnectRequest:
        close_span(*w, f.start_ns);
        break;
      default:
        break;
    }
    w->c.marks.push_back(std::move(mark));
  }
  for (auto& [k, list] : pending) {
    Work& w = row(std::get<0>(k), std::get<1>(k), std::get<2>(k), -1, true);
    for (Pending& q : list) w.c.marks.push_back(std::move(q.mark));
  }
  std::vector<MpiConnection> out;
  for (auto& [k, w] : rows) {
    close_span(w, lane_end);
    MpiConnection c;
    c.initiator = w.c.initiator;
    c.initiator_sap = w.c.initiator_sap;
    c.responder = w.c.responder;
    c.responder_sap = w.c.responder_sap;
    c.setup_seen = w.c.setup_seen;
    for (const MpiSpan& s : w.c.spans)
      if (s.start_ns < to && (s.end_ns > from || (s.end_ns == s.start_ns && s.start_ns >= from)))
        c.spans.push_back(s);
    std::stable_sort(w.c.marks.begin(), w.c.marks.end(),
                     [](const MpiMark& a, const MpiMark& b) { return a.ts_ns < b.ts_ns; });
    for (MpiMark& m : w.c.marks) {
      if (m.ts_ns < from || m.ts_ns >= to) continue;
      if (m.pdu == mpi::kData) ++c.data_messages;
      if (m.pdu == mpi::kDataAck) ++c.data_acks;
      c.marks.push_back(std::move(m));
    }
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace pbvbus::captures
