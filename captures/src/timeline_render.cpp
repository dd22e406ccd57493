#include "pbvbus/captures/timeline_render.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <string_view>
#include <unordered_map>

#include "pbvbus/captures/cpu_event.hpp"
#include "pbvbus/captures/hsby_event.hpp"
#include "timeline_page.hpp"

namespace pbvbus::captures {

namespace {
__extension__ typedef __int128 i128;

constexpr std::int64_t kNsPerS = 1'000'000'000;

/// b - a without overflow (times from a file can be anything).
std::int64_t diff(std::int64_t a, std::int64_t b) {
  const i128 v = static_cast<i128>(b) - a;
  if (v > std::numeric_limits<std::int64_t>::max()) return std::numeric_limits<std::int64_t>::max();
  if (v < std::numeric_limits<std::int64_t>::min()) return std::numeric_limits<std::int64_t>::min();
  return static_cast<std::int64_t>(v);
}
/// Relative times in the page are JavaScript numbers: exact up to 2^53 ns (104 days).
constexpr std::int64_t kJsExact = std::int64_t{1} << 53;

// ---- escaping ---------------------------------------------------------------------------

std::string json_str(std::string_view raw) {
  const std::string s = sanitize_utf8(raw);
  std::string o = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        o += "\\\"";
        break;
      case '\\':
        o += "\\\\";
        break;
      case '\n':
        o += "\\n";
        break;
      case '\t':
        o += "\\t";
        break;
      // Never "</script>" or "<!--" inside the data block.
      case '<':
        o += "\\u003c";
        break;
      case '>':
        o += "\\u003e";
        break;
      case '&':
        o += "\\u0026";
        break;
      default:
        o += c;
    }
  }
  return o + "\"";
}

std::string xml(std::string_view raw) {
  const std::string s = sanitize_utf8(raw);
  std::string o;
  o.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&':
        o += "&amp;";
        break;
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '"':
        o += "&quot;";
        break;
      case '\'':
        o += "&#39;";
        break;
      case '\n':
        o += "&#10;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

// ---- text -------------------------------------------------------------------------------

std::string hex(const std::vector<std::uint8_t>& b, bool spaced) {
  static const char* d = "0123456789abcdef";
  std::string o;
  o.reserve(b.size() * 3);
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (spaced && i) o += ' ';
    o += d[b[i] >> 4];
    o += d[b[i] & 15];
  }
  return o;
}

std::string label_of(const TimelineFrame& f) {
  const std::string dir = std::to_string(f.sa) + "\u2192" + std::to_string(f.da);
  switch (f.kind) {
    case FrameKind::Token:
      return "tok " + dir;
    case FrameKind::Sc:
      return "SC";
    case FrameKind::Bad:
      return "bad";
    case FrameKind::Request: {
      // The function without its priority: the box is small.
      std::string fn = f.fc == fdl::kFcClockValue
                           ? std::string("CV")
                           : std::string(fdl::to_string(fdl::fc_request_fn(f.fc)));
      for (const char* suffix : {"_low", "_high"}) {
        const std::string_view sv(suffix);
        if (fn.size() > sv.size() && fn.compare(fn.size() - sv.size(), sv.size(), sv) == 0)
          fn.resize(fn.size() - sv.size());
      }
      if (fn == "FDL_Status") fn = "Status";
      return fn + " " + dir;
    }
    case FrameKind::Response:
      return std::string(fdl::to_string(fdl::fc_status(f.fc))) + " " + dir;
  }
  return "?";
}

std::string speed_text(std::uint64_t s) {
  if (s == 0) return "speed unknown";
  char buf[48];
  auto trim = [](std::string v) {
    if (v.find('.') != std::string::npos) {
      while (!v.empty() && v.back() == '0') v.pop_back();
      if (!v.empty() && v.back() == '.') v.pop_back();
    }
    return v;
  };
  if (s >= 1'000'000) {
    std::snprintf(buf, sizeof buf, "%llu.%06llu", static_cast<unsigned long long>(s / 1'000'000),
                  static_cast<unsigned long long>(s % 1'000'000));
    return trim(buf) + " Mbit/s";
  }
  if (s >= 1000) {
    std::snprintf(buf, sizeof buf, "%llu.%03llu", static_cast<unsigned long long>(s / 1000),
                  static_cast<unsigned long long>(s % 1000));
    return trim(buf) + " kbit/s";
  }
  return std::to_string(s) + " bit/s";
}

/// Absolute time in seconds with `dec` decimals, digits after the point grouped by three.
std::string fmt_abs(std::int64_t ns, int dec) {
  const bool neg = ns < 0;
  const std::uint64_t a =
      neg ? static_cast<std::uint64_t>(-(ns + 1)) + 1 : static_cast<std::uint64_t>(ns);
  char frac[16];
  std::snprintf(frac, sizeof frac, "%09llu", static_cast<unsigned long long>(a % kNsPerS));
  std::string o = (neg ? "-" : "") + std::to_string(a / kNsPerS);
  if (dec > 0) {
    o += '.';
    for (int i = 0; i < dec && i < 9; ++i) {
      if (i && i % 3 == 0) o += "\u2009";
      o += frac[i];
    }
  }
  return o + " s";
}

std::string fmt_dur(std::int64_t ns) {
  char buf[48];
  const double v = static_cast<double>(ns);
  const double a = std::fabs(v);
  if (a < 1e3)
    std::snprintf(buf, sizeof buf, "%lld ns", static_cast<long long>(ns));
  else if (a < 1e6)
    std::snprintf(buf, sizeof buf, "%.3f \u00b5s", v / 1e3);
  else if (a < 1e9)
    std::snprintf(buf, sizeof buf, "%.3f ms", v / 1e6);
  else
    std::snprintf(buf, sizeof buf, "%.6f s", v / 1e9);
  return buf;
}

std::string fmt_bits(std::int64_t ns, std::uint64_t speed) {
  const auto b = ns_to_bits(ns, speed);
  return b ? " = " + std::to_string(*b) + " bit times" : std::string();
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

/// The page's time 0: the capture's own 0 when its times are small (pbvbus virtual time), else
/// its first record (captures with wall-clock timestamps).
std::int64_t page_origin(const Timeline& tl) {
  if (tl.first_ns >= 0 && tl.last_ns < kJsExact) return 0;
  return tl.first_ns;
}

std::int64_t rel(std::int64_t t, std::int64_t origin) {
  const i128 v = static_cast<i128>(t) - origin;
  if (v > kJsExact) return kJsExact;
  if (v < -kJsExact) return -kJsExact;
  return static_cast<std::int64_t>(v);
}

const char* const kKindColour[] = {"#8446c2", "#2468c9", "#2f9e48", "#13a3b4", "#e03131"};
const char* const kHolderColour[] = {"#f6bd60", "#90caf9", "#b8e0a0", "#f7a8c4", "#cdb4f0", "#ffe08a",
                                     "#9fd8cb", "#f4a582", "#c7d2fe", "#d9ed92", "#e5c3a6", "#a5d8ff"};
/// Colours of the lanes in the active-channel rows (as the page's LANE_COLOURS).
const char* const kLaneColour[] = {"#1c7ed6", "#f59f00", "#0ca678", "#ae3ec9", "#d6336c", "#74b816"};
const char* lane_colour(int lane) { return kLaneColour[static_cast<std::size_t>(lane) % 6]; }
/// CPU states (cpu_event.hpp numbers; as the page's CPU_STATE_COLOURS); others grey.
const char* const kCpuStateColour[] = {"#ced4da", "#e03131", "#fab005", "#2f9e44", "#74c0fc",
                                       "#1971c2", "#f76707", "#9c36b5", "#5c0a0a", "#15aabf"};
const char* cpu_state_colour(int state) {
  return state >= 0 && state < 10 ? kCpuStateColour[state] : "#868e96";
}
/// Dark text on the light state colours (OFF, STARTUP, LINK-UP), white on the others.
const char* cpu_text_colour(int state) {
  return state == 0 || state == 2 || state == 4 ? "#1d2126" : "#fff";
}
constexpr const char* kObColour = "#212529";
/// Quantum rack states (hsby_event.hpp numbers; as the page's HSBY_STATE_COLOURS): off grey,
/// offline amber, primary green, standby blue; others grey.
const char* const kHsbyStateColour[] = {"#ced4da", "#fab005", "#2f9e44", "#1971c2"};
const char* hsby_state_colour(int state) {
  return state >= 0 && state < kHsbyRackStates ? kHsbyStateColour[state] : "#868e96";
}
const char* hsby_text_colour(int state) { return state == 0 || state == 1 ? "#1d2126" : "#fff"; }
constexpr const char* kSwitchoverColour = "#c2255c";

// MPI connection rows (timeline.hpp "MPI connections").
const char* mpi_span_colour(MpiState s) {
  return s == MpiState::Connected ? "#a5d8ff" : "#dee2e6";
}
/// Connect request/confirm purple, connection acks grey, data from the initiator blue, data
/// from the responder green, data acks light grey, disconnect orange.
const char* mpi_mark_colour(const MpiMark& m) {
  switch (m.pdu) {
    case 0xE0:
    case 0xD0:
      return "#7048e8";
    case 0x05:
      return "#868e96";
    case 0xF1:
      return m.from_initiator ? "#1971c2" : "#2b8a3e";
    case 0xB0:
      return "#adb5bd";
    case 0x80:
      return "#e8590c";
    default:
      return "#495057";
  }
}

/// The CPU rows of a Timeline: (system, rack) in the order of cpu_states / cpu_obs (both by
/// system, then rack), and whether several systems share the picture (then the labels name it).
struct CpuRowIndex {
  std::map<std::pair<std::string, int>, int> row;
  bool several_systems = false;
  explicit CpuRowIndex(const Timeline& tl) {
    std::set<std::pair<std::string, int>> keys;
    std::set<std::string> systems;
    for (const CpuStateSpan& s : tl.cpu_states) keys.emplace(s.system, s.rack);
    for (const CpuObMark& m : tl.cpu_obs) keys.emplace(m.system, m.rack);
    int i = 0;
    for (const auto& k : keys) {
      row.emplace(k, i++);
      systems.insert(k.first);
    }
    several_systems = systems.size() > 1;
  }
  int of(const std::string& system, int rack) const { return row.at({system, rack}); }
  std::string label(const std::string& system, int rack) const {
    const std::string cpu = "CPU " + std::to_string(rack) + " (rack " + std::to_string(rack) + ")";
    return several_systems && !system.empty() ? sanitize_utf8(system) + ": " + cpu : cpu;
  }
};

/// The Quantum rows of a Timeline: (pair, rack) in the order of hsby_states (by pair, then
/// rack); a label names the pair only when several pairs share the picture.
struct HsbyRowIndex {
  std::map<std::pair<std::string, int>, int> row;
  bool several_pairs = false;
  explicit HsbyRowIndex(const Timeline& tl) {
    std::set<std::pair<std::string, int>> keys;
    std::set<std::string> pairs;
    for (const HsbyStateSpan& s : tl.hsby_states) keys.emplace(s.pair, s.rack);
    for (const HsbySwitchoverMark& m : tl.hsby_switchovers) keys.emplace(m.pair, m.rack);
    int i = 0;
    for (const auto& k : keys) {
      row.emplace(k, i++);
      pairs.insert(k.first);
    }
    several_pairs = pairs.size() > 1;
  }
  int of(const std::string& pair, int rack) const { return row.at({pair, rack}); }
  std::string label(const std::string& pair, int rack) const {
    const std::string r = "Quantum rack " + std::to_string(rack);
    return several_pairs && !pair.empty() ? sanitize_utf8(pair) + ": " + r : r;
  }
};

/// "RUN master", "STOP" (no role shown for none).
std::string cpu_span_label(const CpuStateSpan& s) {
  return cpu_state_name(s.state) + (s.role == 0 ? std::string() : " " + cpu_role_name(s.role));
}

const char* event_colour(EventStyle s) {
  switch (s) {
    case EventStyle::Fault:
      return "#e8590c";
    case EventStyle::Repair:
      return "#2b8a3e";
    case EventStyle::Event:
      break;
  }
  return "#5f3dc4";
}

// ---- JSON data of the page ----------------------------------------------------------------

class Tables {
 public:
  std::size_t str(const std::string& s) {
    auto [it, fresh] = m_str_index.try_emplace(s, m_strs.size());
    if (fresh) m_strs.push_back(s);
    return it->second;
  }
  std::size_t entry(const TimelineFrame& f) {
    std::string key(f.bytes.begin(), f.bytes.end());
    key += '\0';
    key += std::to_string(f.flags);
    key += '\0';
    key += f.comment;
    auto it = m_ent_index.find(key);
    if (it != m_ent_index.end()) return it->second;
    const std::size_t d = str(describe(f));
    const std::size_t l = str(label_of(f));
    std::string e = "[\"" + hex(f.bytes, false) + "\"," + std::to_string(static_cast<int>(f.kind)) +
                    "," + std::to_string(d) + "," + std::to_string(l) + "]";
    m_ents.push_back(std::move(e));
    m_ent_index.emplace(std::move(key), m_ents.size() - 1);
    return m_ents.size() - 1;
  }
  void write(std::string& o) const {
    o += "\"desc\":[";
    for (std::size_t i = 0; i < m_strs.size(); ++i) {
      if (i) o += ',';
      o += json_str(m_strs[i]);
    }
    o += "],\"ent\":[";
    for (std::size_t i = 0; i < m_ents.size(); ++i) {
      if (i) o += ',';
      o += m_ents[i];
    }
    o += "]";
  }

 private:
  std::vector<std::string> m_strs;
  std::unordered_map<std::string, std::size_t> m_str_index;
  std::vector<std::string> m_ents;
  std::unordered_map<std::string, std::size_t> m_ent_index;
};

std::string page_json(const Timeline& tl, std::int64_t origin, std::int64_t view_from,
                      std::int64_t view_to) {
  Tables tables;
  std::string lanes = "[";
  for (std::size_t li = 0; li < tl.lanes.size(); ++li) {
    const TimelineLane& L = tl.lanes[li];
    if (li) lanes += ',';
    lanes += "{\"name\":" + json_str(L.name) + ",\"desc\":" + json_str(L.description) +
             ",\"speed\":" + std::to_string(L.speed) + ",\"if\":" + std::to_string(L.interface);
    std::string t = ",\"t\":[", e = ",\"e\":[";
    std::int64_t prev = 0;
    for (std::size_t i = 0; i < L.frames.size(); ++i) {
      const TimelineFrame& f = L.frames[i];
      const std::int64_t r = rel(f.start_ns, origin);
      if (i) {
        t += ',';
        e += ',';
      }
      t += std::to_string(r - prev);
      prev = r;
      e += std::to_string(tables.entry(f));
    }
    lanes += t + "]" + e + "]";
    std::string tk = ",\"tk\":[", tlen = ",\"tl\":[", th = ",\"th\":[", tp = ",\"tp\":[";
    prev = 0;
    for (std::size_t i = 0; i < L.token.size(); ++i) {
      const TokenSpan& s = L.token[i];
      const std::int64_t r = rel(s.start_ns, origin);
      if (i) {
        tk += ',';
        tlen += ',';
        th += ',';
        tp += ',';
      }
      tk += std::to_string(r - prev);
      prev = r;
      tlen += std::to_string(rel(s.end_ns, origin) - r);
      th += std::to_string(s.holder);
      tp += std::to_string(s.passed_by);
    }
    lanes += tk + "]" + tlen + "]" + th + "]" + tp + "]";
    lanes += ",\"dx\":[";
    for (std::size_t si = 0; si < L.slaves.size(); ++si) {
      const SlaveCycles& S = L.slaves[si];
      if (si) lanes += ',';
      lanes += "{\"a\":" + std::to_string(S.address) + ",\"t\":[";
      std::string un;
      std::set<int> masters;
      prev = 0;
      for (std::size_t i = 0; i < S.polls.size(); ++i) {
        const DxPoll& p = S.polls[i];
        const std::int64_t r = rel(p.start_ns, origin);
        if (i) lanes += ',';
        lanes += std::to_string(r - prev);
        prev = r;
        masters.insert(p.master);
        if (!p.answered) {
          if (!un.empty()) un += ',';
          un += std::to_string(i);
        }
      }
      const std::int64_t c0 =
          !S.polls.empty() && S.polls.front().cycle_ns ? *S.polls.front().cycle_ns : -1;
      lanes += "],\"c0\":" + std::to_string(c0) + ",\"m\":[";
      bool first = true;
      for (int m : masters) {
        if (!first) lanes += ',';
        first = false;
        lanes += std::to_string(m);
      }
      lanes += "],\"un\":[" + un + "]}";
    }
    // MPI connections (timeline.hpp): "l" label, spans "s" [start, end, state 0 connecting /
    // 1 connected], marks "m" [time, first PDU octet, 1 = from the initiator, text index].
    lanes += "],\"mpi\":[";
    for (std::size_t ci = 0; ci < L.mpi.size(); ++ci) {
      const MpiConnection& C = L.mpi[ci];
      if (ci) lanes += ',';
      lanes += "{\"l\":" + json_str(mpi_connection_label(C)) + ",\"s\":[";
      for (std::size_t k = 0; k < C.spans.size(); ++k) {
        const MpiSpan& sp = C.spans[k];
        lanes += std::string(k ? "," : "") + "[" + std::to_string(rel(sp.start_ns, origin)) + "," +
                 std::to_string(rel(sp.end_ns, origin)) + "," +
                 std::to_string(static_cast<int>(sp.state)) + "]";
      }
      lanes += "],\"m\":[";
      for (std::size_t k = 0; k < C.marks.size(); ++k) {
        const MpiMark& m = C.marks[k];
        lanes += std::string(k ? "," : "") + "[" + std::to_string(rel(m.ts_ns, origin)) + "," +
                 std::to_string(m.pdu) + "," + (m.from_initiator ? "1" : "0") + "," +
                 std::to_string(tables.str(m.text)) + "]";
      }
      lanes += "]}";
    }
    lanes += "]}";
  }
  lanes += "]";
  std::string ev = "[";
  for (std::size_t i = 0; i < tl.events.size(); ++i) {
    const TimelineEvent& e = tl.events[i];
    if (i) ev += ',';
    ev += "[" + std::to_string(rel(e.ts_ns, origin)) + ",\"" + std::string(to_string(e.style)) +
          "\"," + json_str(to_string(e.record.category)) + "," + json_str(e.record.text) + "]";
  }
  ev += "]";
  // Active channels (timeline.hpp): one row per switched station, spans [start, end, lane,
  // line] in page time; lane -1 = none (or no lane for the line), line -1 = none.
  std::string ac = "[";
  for (std::size_t i = 0; i < tl.active_channels.size(); ++i) {
    const ActiveChannelSpan& s = tl.active_channels[i];
    const bool fresh = i == 0 || tl.active_channels[i - 1].station != s.station;
    if (fresh) ac += std::string(i ? "]}," : "") + "{\"a\":" + std::to_string(s.station) + ",\"s\":[";
    else ac += ',';
    ac += "[" + std::to_string(rel(s.start_ns, origin)) + "," + std::to_string(rel(s.end_ns, origin)) +
          "," + std::to_string(s.line_lane) + "," + std::to_string(s.line) + "]";
  }
  if (!tl.active_channels.empty()) ac += "]}";
  ac += "]";
  // CPU rows (timeline.hpp "CPU rows"): per row its label, system and rack, spans [start, end,
  // state, role] and OB marks [time, ob, event id, reason, text] in page time; the names of the
  // state and role numbers once.
  std::string cpu = "{\"states\":[";
  for (int k = 0; k < 10; ++k) cpu += std::string(k ? "," : "") + json_str(cpu_state_name(k));
  cpu += "],\"roles\":[";
  for (int k = 0; k < 3; ++k) cpu += std::string(k ? "," : "") + json_str(cpu_role_name(k));
  cpu += "],\"rows\":[";
  {
    const CpuRowIndex rows(tl);
    std::vector<std::string> spans(rows.row.size()), obs(rows.row.size());
    for (const CpuStateSpan& s : tl.cpu_states) {
      std::string& o = spans[static_cast<std::size_t>(rows.of(s.system, s.rack))];
      o += std::string(o.empty() ? "" : ",") + "[" + std::to_string(rel(s.start_ns, origin)) + "," +
           std::to_string(rel(s.end_ns, origin)) + "," + std::to_string(s.state) + "," +
           std::to_string(s.role) + "]";
    }
    for (const CpuObMark& m : tl.cpu_obs) {
      std::string& o = obs[static_cast<std::size_t>(rows.of(m.system, m.rack))];
      o += std::string(o.empty() ? "" : ",") + "[" + std::to_string(rel(m.ts_ns, origin)) + "," +
           std::to_string(m.ob) + "," + std::to_string(m.event_id) + "," +
           std::to_string(m.reason) + "," + json_str(m.text) + "]";
    }
    bool first = true;
    for (const auto& [key, i] : rows.row) {
      const auto u = static_cast<std::size_t>(i);
      cpu += std::string(first ? "" : ",") + "{\"label\":" + json_str(rows.label(key.first, key.second)) +
             ",\"sys\":" + json_str(key.first) + ",\"r\":" + std::to_string(key.second) +
             ",\"s\":[" + spans[u] + "],\"ob\":[" + obs[u] + "]}";
      first = false;
    }
  }
  cpu += "]}";
  // Quantum rows (timeline.hpp "Quantum Hot Standby rows"): per row its label, pair and rack,
  // spans [start, end, state] and switchovers [time, takeover ns, text] in page time; the state
  // names once. Left out (the page takes no rows) when the capture has no Quantum pair.
  std::string hsby = "{\"states\":[";
  for (int k = 0; k < kHsbyRackStates; ++k) hsby += std::string(k ? "," : "") + json_str(hsby_state_name(k));
  hsby += "],\"rows\":[";
  {
    const HsbyRowIndex rows(tl);
    std::vector<std::string> spans(rows.row.size()), sws(rows.row.size());
    for (const HsbyStateSpan& s : tl.hsby_states) {
      std::string& o = spans[static_cast<std::size_t>(rows.of(s.pair, s.rack))];
      o += std::string(o.empty() ? "" : ",") + "[" + std::to_string(rel(s.start_ns, origin)) + "," +
           std::to_string(rel(s.end_ns, origin)) + "," + std::to_string(s.state) + "]";
    }
    for (const HsbySwitchoverMark& m : tl.hsby_switchovers) {
      std::string& o = sws[static_cast<std::size_t>(rows.of(m.pair, m.rack))];
      o += std::string(o.empty() ? "" : ",") + "[" + std::to_string(rel(m.ts_ns, origin)) + "," +
           std::to_string(m.takeover_ns) + "," + json_str(m.text) + "]";
    }
    bool first = true;
    for (const auto& [key, i] : rows.row) {
      const auto u = static_cast<std::size_t>(i);
      hsby += std::string(first ? "" : ",") + "{\"label\":" + json_str(rows.label(key.first, key.second)) +
              ",\"pair\":" + json_str(key.first) + ",\"r\":" + std::to_string(key.second) +
              ",\"s\":[" + spans[u] + "],\"sw\":[" + sws[u] + "]}";
      first = false;
    }
  }
  hsby += "]}";
  std::string o = "{\"v\":1,\"origin\":\"" + std::to_string(origin) + "\",\"span\":[" +
                  std::to_string(rel(tl.from_ns, origin)) + "," + std::to_string(rel(tl.to_ns, origin)) +
                  "],\"view\":[" + std::to_string(rel(view_from, origin)) + "," +
                  std::to_string(rel(view_to, origin)) + "],";
  tables.write(o);
  o += ",\"lanes\":" + lanes + ",\"ev\":" + ev + ",\"cpu\":" + cpu + ",\"ac\":" + ac + (tl.hsby_states.empty() && tl.hsby_switchovers.empty() ? std::string() : ",\"hsby\":" + hsby) + "}";
  return o;
}

std::uint64_t count_frames(const Timeline& tl) {
  std::uint64_t n = 0;
  for (const auto& L : tl.lanes) n += L.frames.size();
  return n;
}

// ---- static SVG ---------------------------------------------------------------------------

constexpr int kLabelW = 210, kPadR = 18, kHeadH = 52, kAxisH = 34, kEvH = 46;
constexpr int kRowFrames = 30, kRowToken = 18, kRowRuler = 20, kRowDx = 14, kLaneGap = 18;
constexpr int kRowAc = 14, kRowCpu = 22, kRowMpi = 16;

std::int64_t nice_step(double raw) {
  if (!(raw > 1)) return 1;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double m = raw / p;
  const double f = m <= 1 ? 1 : m <= 2 ? 2 : m <= 5 ? 5 : 10;
  const double v = f * p;
  return v > 9e18 ? std::int64_t{9'000'000'000'000'000'000} : static_cast<std::int64_t>(v);
}

struct SvgCtx {
  std::string o;
  double plot_x = kLabelW;
  double plot_w = 0;
  std::int64_t from = 0;
  std::int64_t to = 0;
  double scale = 0;
  double x(std::int64_t t) const {
    return plot_x + static_cast<double>(static_cast<i128>(t) - from) * scale;
  }
  double clampx(double v) const { return std::max(plot_x, std::min(plot_x + plot_w, v)); }
};

void svg_frames(SvgCtx& c, const TimelineLane& L, int y) {
  c.o += "<rect x=\"" + num(c.plot_x) + "\" y=\"" + std::to_string(y) + "\" width=\"" +
         num(c.plot_w) + "\" height=\"" + std::to_string(kRowFrames) +
         "\" fill=\"#fbfbfc\" stroke=\"#e2e5e9\"/>\n";
  if (L.frames.size() <= 2500) {
    const TimelineFrame* prev = nullptr;
    for (const TimelineFrame& f : L.frames) {
      const double xa = c.clampx(c.x(f.start_ns)), xb = c.clampx(c.x(f.end_ns));
      const double w = std::max(1.0, xb - xa);
      std::string title(to_string(f.kind));
      title += " at " + fmt_abs(f.start_ns, 9) + ", " + fmt_dur(diff(f.start_ns, f.end_ns)) +
               fmt_bits(diff(f.start_ns, f.end_ns), L.speed);
      if (f.idle_ns && prev)
        title += "\nidle before: " + fmt_dur(*f.idle_ns) + fmt_bits(*f.idle_ns, L.speed);
      title += "\n" + describe(f) + "\nhex " + hex(f.bytes, true);
      c.o += "<rect x=\"" + num(xa) + "\" y=\"" + std::to_string(y + 3) + "\" width=\"" + num(w) +
             "\" height=\"" + std::to_string(kRowFrames - 6) + "\" fill=\"" +
             kKindColour[static_cast<int>(f.kind)] + "\"><title>" + xml(title) + "</title></rect>\n";
      if (w > 40) {
        std::string label = label_of(f);
        const auto fit = static_cast<std::size_t>((w - 6) / 6.4);
        // Cut to `fit` characters (labels are ASCII but for the arrow).
        std::size_t chars = 0, n = 0;
        while (n < label.size() && chars < fit) {
          ++n;
          while (n < label.size() && (static_cast<unsigned char>(label[n]) & 0xC0) == 0x80) ++n;
          ++chars;
        }
        label.resize(n);
        if (fit >= 3)
          c.o += "<text x=\"" + num(xa + 3) + "\" y=\"" + std::to_string(y + kRowFrames / 2 + 4) +
                 "\" font-size=\"11\" fill=\"#fff\">" + xml(label) + "</text>\n";
      }
      prev = &f;
    }
    return;
  }
  const auto W = static_cast<std::size_t>(std::ceil(c.plot_w));
  std::vector<double> occ(W * 5, 0.0);
  for (const TimelineFrame& f : L.frames) {
    const double a = c.x(f.start_ns) - c.plot_x, b = c.x(f.end_ns) - c.plot_x;
    const auto k = static_cast<std::size_t>(f.kind);
    const double lo = std::max(0.0, std::floor(a));
    if (lo >= static_cast<double>(W)) continue;
    auto p = static_cast<std::size_t>(lo);
    if (a == b) {
      occ[p * 5 + k] += 0.15;
      continue;
    }
    for (; p < W && static_cast<double>(p) <= b; ++p) {
      const double ov = std::min(b, static_cast<double>(p) + 1) - std::max(a, static_cast<double>(p));
      if (ov > 0) occ[p * 5 + k] += ov;
    }
  }
  std::string run_key;
  std::size_t run_start = 0;
  auto flush = [&](std::size_t end) {
    if (run_key.empty()) return;
    const auto slash = run_key.find('/');
    c.o += "<rect x=\"" + num(c.plot_x + static_cast<double>(run_start)) + "\" y=\"" +
           std::to_string(y + 3) + "\" width=\"" + std::to_string(end - run_start) + "\" height=\"" +
           std::to_string(kRowFrames - 6) + "\" fill=\"" +
           kKindColour[std::stoi(run_key.substr(0, slash))] + "\" fill-opacity=\"" +
           run_key.substr(slash + 1) + "\"/>\n";
  };
  for (std::size_t p = 0; p < W; ++p) {
    double tot = 0, bv = 0;
    int best = -1;
    for (int k = 0; k < 5; ++k) {
      const double v = occ[p * 5 + static_cast<std::size_t>(k)];
      tot += v;
      if (v > bv) {
        bv = v;
        best = k;
      }
    }
    if (occ[p * 5 + 4] > 0) best = 4;
    std::string key;
    if (best >= 0) {
      char buf[16];
      std::snprintf(buf, sizeof buf, "%d/%.1f", best, 0.3 + 0.7 * std::min(1.0, tot));
      key = buf;
    }
    if (key != run_key) {
      flush(p);
      run_key = key;
      run_start = p;
    }
  }
  flush(W);
}

void svg_token(SvgCtx& c, const TimelineLane& L, int y, const std::map<int, std::string>& colour) {
  c.o += "<rect x=\"" + num(c.plot_x) + "\" y=\"" + std::to_string(y) + "\" width=\"" +
         num(c.plot_w) + "\" height=\"" + std::to_string(kRowToken) +
         "\" fill=\"#fbfbfc\" stroke=\"#e2e5e9\"/>\n";
  long bucket = -1;
  std::map<int, double> acc;
  auto flush = [&] {
    if (bucket < 0) return;
    int best = 0;
    double bv = -1;
    for (const auto& [h, v] : acc)
      if (v > bv) {
        bv = v;
        best = h;
      }
    c.o += "<rect x=\"" + num(c.plot_x + static_cast<double>(bucket)) + "\" y=\"" +
           std::to_string(y + 2) + "\" width=\"1\" height=\"" + std::to_string(kRowToken - 4) +
           "\" fill=\"" + colour.at(best) + "\"/>\n";
    bucket = -1;
    acc.clear();
  };
  for (const TokenSpan& s : L.token) {
    const double xa = c.clampx(c.x(s.start_ns)), xb = c.clampx(c.x(s.end_ns));
    const double w = xb - xa;
    if (w >= 1) {
      flush();
      c.o += "<rect x=\"" + num(xa) + "\" y=\"" + std::to_string(y + 2) + "\" width=\"" + num(w) +
             "\" height=\"" + std::to_string(kRowToken - 4) + "\" fill=\"" + colour.at(s.holder) +
             "\"><title>token holder " + std::to_string(s.holder) + " (passed by " +
             std::to_string(s.passed_by) + "), " + xml(fmt_dur(diff(s.start_ns, s.end_ns))) +
             "</title></rect>\n";
      const std::string label = w >= 26 ? std::to_string(s.passed_by) + "\u2192" + std::to_string(s.holder)
                                : w >= 12 ? std::to_string(s.holder)
                                          : std::string();
      if (!label.empty())
        c.o += "<text x=\"" + num((xa + xb) / 2) + "\" y=\"" + std::to_string(y + kRowToken / 2 + 4) +
               "\" text-anchor=\"middle\" font-size=\"11\" fill=\"#1d2126\">" + label +
               "</text>\n";
    } else {
      const auto p = static_cast<long>(std::floor(xa - c.plot_x));
      if (p != bucket) {
        flush();
        bucket = p;
      }
      acc[s.holder] += w;
    }
  }
  flush();
}

void svg_ruler(SvgCtx& c, const TimelineLane& L, int y) {
  if (L.speed == 0) return;
  const double bit_ns = 1e9 / static_cast<double>(L.speed);
  const double span_bits = static_cast<double>(diff(c.from, c.to)) / bit_ns;
  if (span_bits > 6000) {
    c.o += "<text x=\"" + num(c.plot_x + 4) + "\" y=\"" + std::to_string(y + 13) +
           "\" font-size=\"10\" fill=\"#9aa3ad\">a bit-time axis appears for windows below " +
           xml(fmt_dur(static_cast<std::int64_t>(6000 * bit_ns))) + "</text>\n";
    return;
  }
  const std::int64_t step = nice_step(span_bits / std::max(2.0, c.plot_w / 90));
  c.o += "<line x1=\"" + num(c.plot_x) + "\" y1=\"" + std::to_string(y + 3) + "\" x2=\"" +
         num(c.plot_x + c.plot_w) + "\" y2=\"" + std::to_string(y + 3) + "\" stroke=\"#495057\"/>\n";
  for (std::int64_t b = 0; static_cast<double>(b) <= span_bits; b += step) {
    const double x = c.plot_x + static_cast<double>(b) * bit_ns * c.scale;
    c.o += "<line x1=\"" + num(x) + "\" y1=\"" + std::to_string(y + 3) + "\" x2=\"" + num(x) +
           "\" y2=\"" + std::to_string(y + 8) + "\" stroke=\"#495057\"/><text x=\"" + num(x) +
           "\" y=\"" + std::to_string(y + 18) +
           "\" text-anchor=\"middle\" font-size=\"10\" fill=\"#343a40\">" + std::to_string(b) +
           "</text>\n";
  }
}

void svg_dx(SvgCtx& c, const TimelineLane& L, int y0) {
  for (std::size_t j = 0; j < L.slaves.size(); ++j) {
    const SlaveCycles& S = L.slaves[j];
    const int y = y0 + static_cast<int>(j) * kRowDx;
    c.o += "<rect x=\"" + num(c.plot_x) + "\" y=\"" + std::to_string(y) + "\" width=\"" +
           num(c.plot_w) + "\" height=\"" + std::to_string(kRowDx - 1) + "\" fill=\"" +
           (j % 2 ? "#fbfbfc" : "#f4f6f8") + "\"/>\n";
    const bool dense = static_cast<double>(S.polls.size()) > c.plot_w / 3;
    double last = -1e9;
    for (std::size_t i = 0; i < S.polls.size(); ++i) {
      const DxPoll& p = S.polls[i];
      const double x = c.x(p.start_ns);
      if (dense && p.answered && x - last < 1) continue;
      last = x;
      c.o += "<rect x=\"" + num(x - 0.5) + "\" y=\"" + std::to_string(y + 2) + "\" width=\"" +
             (dense ? "1" : "2") + "\" height=\"" + std::to_string(kRowDx - 5) + "\" fill=\"" +
             (p.answered ? "#3f9b57" : "#e03131") + "\">";
      if (!dense) {
        c.o += "<title>Data_Exchange to " + std::to_string(S.address) + " from " +
               std::to_string(p.master) + (p.answered ? "" : ", not answered");
        if (p.cycle_ns) c.o += ", cycle " + xml(fmt_dur(*p.cycle_ns) + fmt_bits(*p.cycle_ns, L.speed));
        c.o += "</title>";
      }
      c.o += "</rect>\n";
      if (!dense && i + 1 < S.polls.size() && S.polls[i + 1].cycle_ns) {
        const double x2 = c.x(S.polls[i + 1].start_ns);
        if (x2 - x > 70)
          c.o += "<text x=\"" + num((x + std::min(x2, c.plot_x + c.plot_w)) / 2) + "\" y=\"" +
                 std::to_string(y + kRowDx - 4) +
                 "\" text-anchor=\"middle\" font-size=\"10\" fill=\"#495057\">" +
                 xml(fmt_dur(*S.polls[i + 1].cycle_ns)) + "</text>\n";
      }
    }
  }
}

/// One row per MPI connection of a lane from y0 (timeline.hpp "MPI connections"): a band for
/// the span (lighter while connecting), a tick per PDU coloured by its kind.
void svg_mpi(SvgCtx& c, const TimelineLane& L, int y0) {
  for (std::size_t j = 0; j < L.mpi.size(); ++j) {
    const MpiConnection& C = L.mpi[j];
    const int y = y0 + static_cast<int>(j) * kRowMpi;
    const std::string label = mpi_connection_label(C);
    c.o += "<g class=\"mpi-conn\" data-conn=\"" + xml(label) + "\">\n<rect x=\"" + num(c.plot_x) +
           "\" y=\"" + std::to_string(y) + "\" width=\"" + num(c.plot_w) + "\" height=\"" +
           std::to_string(kRowMpi - 1) + "\" fill=\"" + (j % 2 ? "#fbfbfc" : "#f4f6f8") + "\"/>\n";
    for (const MpiSpan& s : C.spans) {
      const double xa = c.clampx(c.x(s.start_ns)), xb = c.clampx(c.x(s.end_ns));
      const double w = std::max(1.0, xb - xa);
      const std::string state(to_string(s.state));
      const std::string title = "MPI " + label + " " + state + "\nfrom " + fmt_abs(s.start_ns, 9) +
                                "\nto " + fmt_abs(s.end_ns, 9) + " (" +
                                fmt_dur(diff(s.start_ns, s.end_ns)) + ")";
      c.o += "<rect class=\"mpi-span\" data-state=\"" + state + "\" x=\"" + num(xa) + "\" y=\"" +
             std::to_string(y + 3) + "\" width=\"" + num(w) + "\" height=\"" +
             std::to_string(kRowMpi - 7) + "\" fill=\"" + mpi_span_colour(s.state) + "\"><title>" +
             xml(title) + "</title></rect>\n";
    }
    const bool dense = static_cast<double>(C.marks.size()) > c.plot_w / 3;
    double last = -1e9;
    for (const MpiMark& m : C.marks) {
      const double x = c.x(m.ts_ns);
      if (dense && x - last < 1) continue;
      last = x;
      c.o += "<rect class=\"mpi-mark\" data-pdu=\"" + std::to_string(m.pdu) + "\" x=\"" +
             num(x - 0.5) + "\" y=\"" + std::to_string(y + 1) + "\" width=\"" +
             (dense ? "1" : "2") + "\" height=\"" + std::to_string(kRowMpi - 3) + "\" fill=\"" +
             mpi_mark_colour(m) + "\"><title>" + xml(fmt_abs(m.ts_ns, 9) + " " + m.text) +
             "</title></rect>\n";
    }
    c.o += "</g>\n";
  }
}

void svg_events(SvgCtx& c, const Timeline& tl, int y_top, int y_bottom) {
  struct Group {
    double x;
    std::vector<const TimelineEvent*> items;
  };
  std::vector<Group> groups;
  for (const TimelineEvent& e : tl.events) {
    const double x = c.x(e.ts_ns);
    if (!groups.empty() && x - groups.back().x < 4)
      groups.back().items.push_back(&e);
    else
      groups.push_back({x, {&e}});
  }
  double row_end[3] = {-1e9, -1e9, -1e9};
  for (const Group& g : groups) {
    EventStyle style = g.items.front()->style;
    std::string title;
    for (const TimelineEvent* e : g.items) {
      if (e->style == EventStyle::Fault) style = EventStyle::Fault;
      if (!title.empty()) title += "\n";
      title += fmt_abs(e->ts_ns, 9) + " [" + std::string(to_string(e->record.category)) + "] " +
               e->record.text;
    }
    const char* col = event_colour(style);
    c.o += "<line x1=\"" + num(g.x) + "\" y1=\"" + std::to_string(y_top) + "\" x2=\"" + num(g.x) +
           "\" y2=\"" + std::to_string(y_bottom) + "\" stroke=\"" + col +
           "\" stroke-width=\"2\" stroke-opacity=\"0.85\"" +
           (style == EventStyle::Fault ? "" : " stroke-dasharray=\"5,3\"") + "><title>" +
           xml(title) + "</title></line>\n";
    std::string label = sanitize_utf8(g.items.front()->record.text);
    if (label.size() > 60) {
      std::size_t n = 59;
      while (n > 0 && (static_cast<unsigned char>(label[n]) & 0xC0) == 0x80) --n;
      label = label.substr(0, n) + "\u2026";
    }
    if (g.items.size() > 1) label += " (+" + std::to_string(g.items.size() - 1) + ")";
    const double w = static_cast<double>(label.size()) * 6.2 + 8;
    int row = -1;
    for (int r = 0; r < 3; ++r)
      if (g.x + 4 > row_end[r]) {
        row = r;
        break;
      }
    if (row < 0) continue;
    row_end[row] = g.x + 4 + w;
    c.o += "<text x=\"" + num(g.x + 4) + "\" y=\"" + std::to_string(y_top + 11 + row * 14) +
           "\" font-size=\"11\" font-weight=\"600\" fill=\"" + col + "\">" + xml(label) +
           "</text>\n";
  }
}

std::string ac_line_name(const Timeline& tl, const ActiveChannelSpan& s) {
  if (s.line < 0) return "none";
  if (s.line_lane < 0 || static_cast<std::size_t>(s.line_lane) >= tl.lanes.size())
    return "line " + std::to_string(s.line) + " (no lane)";
  const std::string& n = tl.lanes[static_cast<std::size_t>(s.line_lane)].name;
  return n.empty() ? "line " + std::to_string(s.line) : sanitize_utf8(n);
}

/// One row per switched station from y0 (timeline.hpp "Active channel").
void svg_active(SvgCtx& c, const Timeline& tl, int y0) {
  int row = -1;
  for (std::size_t i = 0; i < tl.active_channels.size(); ++i) {
    const ActiveChannelSpan& s = tl.active_channels[i];
    if (i == 0 || tl.active_channels[i - 1].station != s.station) {
      if (row >= 0) c.o += "</g></g>\n";
      ++row;
      const int yr = y0 + row * kRowAc;
      c.o += "<g class=\"active-channel\" data-station=\"" + std::to_string(s.station) + "\">\n";
      c.o += "<text x=\"" + std::to_string(kLabelW - 12) + "\" y=\"" + std::to_string(yr + 11) +
             "\" text-anchor=\"end\" font-size=\"11\" fill=\"#495057\">station " +
             std::to_string(s.station) + " active</text>\n<g clip-path=\"url(#plotclip)\">\n";
      c.o += "<rect x=\"" + num(c.plot_x) + "\" y=\"" + std::to_string(yr) + "\" width=\"" +
             num(c.plot_w) + "\" height=\"" + std::to_string(kRowAc - 1) + "\" fill=\"" +
             (row % 2 ? "#fbfbfc" : "#f4f6f8") + "\"/>\n";
    }
    const int yr = y0 + row * kRowAc;
    const double xa = c.clampx(c.x(s.start_ns)), xb = c.clampx(c.x(s.end_ns));
    const double w = std::max(1.0, xb - xa);
    const std::string name = ac_line_name(tl, s);
    const std::string title = "station " + std::to_string(s.station) + " active channel: " + name +
                              "\nfrom " + fmt_abs(s.start_ns, 9) + "\nto " + fmt_abs(s.end_ns, 9) +
                              " (" + fmt_dur(diff(s.start_ns, s.end_ns)) + ")";
    c.o += "<rect class=\"ac-span\" x=\"" + num(xa) + "\" y=\"" + std::to_string(yr + 2) +
           "\" width=\"" + num(w) + "\" height=\"" + std::to_string(kRowAc - 5) + "\" fill=\"" +
           (s.line_lane >= 0 ? std::string(lane_colour(s.line_lane)) : std::string("url(#achatch)")) +
           "\"><title>" + xml(title) + "</title></rect>\n";
    if (w > static_cast<double>(name.size()) * 6.2 + 8)
      c.o += "<text x=\"" + num(xa + 4) + "\" y=\"" + std::to_string(yr + kRowAc - 4) +
             "\" font-size=\"10\" fill=\"" + (s.line_lane >= 0 ? "#fff" : "#495057") + "\">" +
             xml(name) + "</text>\n";
  }
  if (row >= 0) c.o += "</g></g>\n";
}

/// One row per CPU from y0 (timeline.hpp "CPU rows"): spans coloured by state (a standby's
/// lighter), labelled "RUN master"; OB marks as ticks with the OB number below.
void svg_cpu(SvgCtx& c, const Timeline& tl, const CpuRowIndex& rows, int y0) {
  std::vector<std::string> body(rows.row.size());
  for (const CpuStateSpan& s : tl.cpu_states) {
    const int row = rows.of(s.system, s.rack);
    const int yr = y0 + row * kRowCpu;
    std::string& o = body[static_cast<std::size_t>(row)];
    const double xa = c.clampx(c.x(s.start_ns)), xb = c.clampx(c.x(s.end_ns));
    const double w = std::max(1.0, xb - xa);
    const std::string label = cpu_span_label(s);
    const std::string title = rows.label(s.system, s.rack) + ": " + label + "\nfrom " +
                              fmt_abs(s.start_ns, 9) + "\nto " + fmt_abs(s.end_ns, 9) + " (" +
                              fmt_dur(diff(s.start_ns, s.end_ns)) + ")";
    o += "<rect class=\"cpu-span\" data-state=\"" + xml(cpu_state_name(s.state)) +
         "\" data-role=\"" + xml(cpu_role_name(s.role)) + "\" x=\"" + num(xa) + "\" y=\"" +
         std::to_string(yr + 1) + "\" width=\"" + num(w) + "\" height=\"13\" fill=\"" +
         cpu_state_colour(s.state) + "\"" + (s.role == 2 ? " fill-opacity=\"0.6\"" : "") +
         "><title>" + xml(title) + "</title></rect>\n";
    if (w > static_cast<double>(label.size()) * 6.2 + 8)
      o += "<text x=\"" + num(xa + 4) + "\" y=\"" + std::to_string(yr + 11) +
           "\" font-size=\"10\" fill=\"" + cpu_text_colour(s.state) + "\">" + xml(label) +
           "</text>\n";
  }
  for (const CpuObMark& m : tl.cpu_obs) {
    const int row = rows.of(m.system, m.rack);
    const int yr = y0 + row * kRowCpu;
    const double x = c.x(m.ts_ns);
    const std::string title = fmt_abs(m.ts_ns, 9) + " OB " + std::to_string(m.ob) + "\n" + m.text;
    body[static_cast<std::size_t>(row)] +=
        "<g class=\"cpu-ob\" data-ob=\"" + std::to_string(m.ob) + "\"><line x1=\"" + num(x) +
        "\" y1=\"" + std::to_string(yr) + "\" x2=\"" + num(x) + "\" y2=\"" +
        std::to_string(yr + kRowCpu - 2) + "\" stroke=\"" + kObColour +
        "\" stroke-width=\"1.5\"/><text x=\"" + num(x + 2) + "\" y=\"" +
        std::to_string(yr + kRowCpu - 1) + "\" font-size=\"8\" fill=\"" + kObColour + "\">" +
        std::to_string(m.ob) + "</text><title>" + xml(title) + "</title></g>\n";
  }
  for (const auto& [key, row] : rows.row) {
    const int yr = y0 + row * kRowCpu;
    c.o += "<g class=\"cpu-row\" data-system=\"" + xml(key.first) + "\" data-rack=\"" +
           std::to_string(key.second) + "\">\n<text x=\"" + std::to_string(kLabelW - 12) +
           "\" y=\"" + std::to_string(yr + 12) +
           "\" text-anchor=\"end\" font-size=\"11\" fill=\"#495057\">" +
           xml(rows.label(key.first, key.second)) + "</text>\n<g clip-path=\"url(#plotclip)\">\n";
    c.o += "<rect x=\"" + num(c.plot_x) + "\" y=\"" + std::to_string(yr) + "\" width=\"" +
           num(c.plot_w) + "\" height=\"" + std::to_string(kRowCpu - 1) + "\" fill=\"" +
           (row % 2 ? "#fbfbfc" : "#f4f6f8") + "\"/>\n";
    c.o += body[static_cast<std::size_t>(row)];
    c.o += "</g></g>\n";
  }
}

/// "takeover 40.000 ms" or "no takeover time" (value 0).
std::string takeover_text(std::uint64_t ns) {
  constexpr auto kMaxNs = std::numeric_limits<std::int64_t>::max();
  if (ns == 0) return "no takeover time";
  return "takeover " +
         fmt_dur(ns > static_cast<std::uint64_t>(kMaxNs) ? kMaxNs : static_cast<std::int64_t>(ns));
}

/// One row per Quantum rack from y0 (timeline.hpp "Quantum Hot Standby rows"): spans coloured
/// by state and labelled with it; switchovers as ticks with the takeover time in the tooltip.
void svg_hsby(SvgCtx& c, const Timeline& tl, const HsbyRowIndex& rows, int y0) {
  std::vector<std::string> body(rows.row.size());
  for (const HsbyStateSpan& s : tl.hsby_states) {
    const int row = rows.of(s.pair, s.rack);
    const int yr = y0 + row * kRowCpu;
    std::string& o = body[static_cast<std::size_t>(row)];
    const double xa = c.clampx(c.x(s.start_ns)), xb = c.clampx(c.x(s.end_ns));
    const double w = std::max(1.0, xb - xa);
    const std::string label = hsby_state_name(s.state);
    const std::string title = rows.label(s.pair, s.rack) + ": " + label + "\nfrom " +
                              fmt_abs(s.start_ns, 9) + "\nto " + fmt_abs(s.end_ns, 9) + " (" +
                              fmt_dur(diff(s.start_ns, s.end_ns)) + ")";
    o += "<rect class=\"hsby-span\" data-state=\"" + xml(label) + "\" x=\"" + num(xa) + "\" y=\"" +
         std::to_string(yr + 1) + "\" width=\"" + num(w) + "\" height=\"13\" fill=\"" +
         hsby_state_colour(s.state) + "\"><title>" + xml(title) + "</title></rect>\n";
    if (w > static_cast<double>(label.size()) * 6.2 + 8)
      o += "<text x=\"" + num(xa + 4) + "\" y=\"" + std::to_string(yr + 11) +
           "\" font-size=\"10\" fill=\"" + hsby_text_colour(s.state) + "\">" + xml(label) +
           "</text>\n";
  }
  for (const HsbySwitchoverMark& m : tl.hsby_switchovers) {
    const int row = rows.of(m.pair, m.rack);
    const int yr = y0 + row * kRowCpu;
    const double x = c.x(m.ts_ns);
    const std::string title = fmt_abs(m.ts_ns, 9) + " switchover to rack " + std::to_string(m.rack) +
                              ", " + takeover_text(m.takeover_ns) + "\n" + m.text;
    body[static_cast<std::size_t>(row)] +=
        "<g class=\"hsby-switchover\" data-takeover-ns=\"" + std::to_string(m.takeover_ns) +
        "\"><line x1=\"" + num(x) + "\" y1=\"" + std::to_string(yr) + "\" x2=\"" + num(x) +
        "\" y2=\"" + std::to_string(yr + kRowCpu - 2) + "\" stroke=\"" + kSwitchoverColour +
        "\" stroke-width=\"2\"/><path d=\"M" + num(x - 4) + " " + std::to_string(yr) + "h8l-4 5z\" fill=\"" +
        kSwitchoverColour + "\"/><title>" + xml(title) + "</title></g>\n";
  }
  for (const auto& [key, row] : rows.row) {
    const int yr = y0 + row * kRowCpu;
    c.o += "<g class=\"hsby-row\" data-pair=\"" + xml(key.first) + "\" data-rack=\"" +
           std::to_string(key.second) + "\">\n<text x=\"" + std::to_string(kLabelW - 12) +
           "\" y=\"" + std::to_string(yr + 12) +
           "\" text-anchor=\"end\" font-size=\"11\" fill=\"#495057\">" +
           xml(rows.label(key.first, key.second)) + "</text>\n<g clip-path=\"url(#plotclip)\">\n";
    c.o += "<rect x=\"" + num(c.plot_x) + "\" y=\"" + std::to_string(yr) + "\" width=\"" +
           num(c.plot_w) + "\" height=\"" + std::to_string(kRowCpu - 1) + "\" fill=\"" +
           (row % 2 ? "#fbfbfc" : "#f4f6f8") + "\"/>\n";
    c.o += body[static_cast<std::size_t>(row)];
    c.o += "</g></g>\n";
  }
}

std::string cycle_text(const SlaveCycles& S, std::uint64_t speed) {
  std::set<int> masters;
  for (const DxPoll& p : S.polls) masters.insert(p.master);
  std::string m;
  for (int a : masters) m += (m.empty() ? "" : ", ") + std::to_string(a);
  std::string o = "slave " + std::to_string(S.address) + " (master " + (m.empty() ? "-" : m) +
                  "): " + std::to_string(S.polls.size()) + " Data_Exchange polls, " +
                  std::to_string(S.unanswered) + " not answered";
  if (S.cycle.count) {
    o += "; DP cycle min / median / max " + fmt_dur(S.cycle.min_ns) + " / " +
         fmt_dur(S.cycle.median_ns) + " / " + fmt_dur(S.cycle.max_ns);
    const auto a = ns_to_bits(S.cycle.min_ns, speed), b = ns_to_bits(S.cycle.median_ns, speed),
               c = ns_to_bits(S.cycle.max_ns, speed);
    if (a && b && c)
      o += " = " + std::to_string(*a) + " / " + std::to_string(*b) + " / " + std::to_string(*c) +
           " bit times";
  }
  return o;
}

}  // namespace

std::string sanitize_utf8(std::string_view s) {
  std::string o;
  o.reserve(s.size());
  const char* kBad = "\xEF\xBF\xBD";
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      if (c < 0x20 && c != '\n' && c != '\t')
        o += kBad;
      else if (c == 0x7F)
        o += kBad;
      else
        o += static_cast<char>(c);
      ++i;
      continue;
    }
    std::size_t n = 0;
    std::uint32_t cp = 0;
    if ((c & 0xE0) == 0xC0) {
      n = 2;
      cp = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      n = 3;
      cp = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      n = 4;
      cp = c & 0x07;
    }
    bool ok = n != 0 && i + n <= s.size();
    for (std::size_t k = 1; ok && k < n; ++k) {
      const auto cc = static_cast<unsigned char>(s[i + k]);
      if ((cc & 0xC0) != 0x80) ok = false;
      cp = (cp << 6) | (cc & 0x3F);
    }
    // Overlong forms, surrogates, beyond U+10FFFF, and C1 controls are not accepted.
    if (ok && ((n == 2 && cp < 0x80) || (n == 3 && cp < 0x800) || (n == 4 && cp < 0x10000) ||
               (cp >= 0xD800 && cp <= 0xDFFF) || cp > 0x10FFFF || (cp >= 0x80 && cp < 0xA0)))
      ok = false;
    if (!ok) {
      o += kBad;
      ++i;
      continue;
    }
    o.append(s.substr(i, n));
    i += n;
  }
  return o;
}

std::string to_html(const Timeline& tl, const TimelineHtmlOptions& opts) {
  const std::int64_t origin = page_origin(tl);
  std::int64_t vf = opts.view_from_ns.value_or(tl.from_ns);
  std::int64_t vt = opts.view_to_ns.value_or(tl.to_ns);
  if (vf >= vt) {
    vf = tl.from_ns;
    vt = tl.to_ns;
  }
  const std::string title = opts.title.empty() ? std::string("capture") : opts.title;
  std::string info = std::to_string(tl.lanes.size()) + (tl.lanes.size() == 1 ? " lane" : " lanes") +
                     " \u00b7 " + std::to_string(count_frames(tl)) + " frames \u00b7 " +
                     std::to_string(tl.events.size()) + " events \u00b7 " + fmt_abs(tl.from_ns, 6) +
                     " \u2013 " + fmt_abs(tl.to_ns, 6);
  if (origin != 0) info += " \u00b7 times relative to " + std::to_string(origin) + " ns";
  if (tl.skipped_interfaces)
    info += " \u00b7 " + std::to_string(tl.skipped_interfaces) + " interfaces of other link types skipped";
  if (tl.bad_event_records)
    info += " \u00b7 " + std::to_string(tl.bad_event_records) + " unreadable event records";
  std::string o;
  o.reserve(count_frames(tl) * 16 + 64 * 1024);
  o += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
       "<meta name=\"generator\" content=\"pbvbus timeline\">\n<title>pbvbus timeline \u2014 ";
  o += xml(title);
  o += "</title>\n<style>";
  o += detail::kTimelineCss;
  o += "</style>\n</head>\n<body>\n<header>\n<h1>pbvbus timeline <span class=\"file\">";
  o += xml(title);
  o += "</span></h1>\n<div id=\"info\">";
  o += xml(info);
  o += "</div>\n";
  if (!opts.note.empty()) o += "<p id=\"note\" class=\"note\"><strong>" + xml(opts.note) + "</strong></p>\n";
  o += "<div class=\"bar\"><span class=\"controls\">"
       "<button data-act=\"out\" title=\"zoom out (-)\">\u2212</button>"
       "<button data-act=\"in\" title=\"zoom in (+)\">+</button>"
       "<button data-act=\"left\" title=\"pan left (\u2190)\">\u25c0</button>"
       "<button data-act=\"right\" title=\"pan right (\u2192)\">\u25b6</button>"
       "<button data-act=\"all\" title=\"whole capture (Home)\">all</button>"
       "<button data-act=\"reset\" title=\"first view (r)\">start view</button>"
       "</span><span id=\"status\"></span></div>\n"
       "<div class=\"bar legend\" id=\"legend\"></div>\n</header>\n"
       "<div id=\"chart\"><svg id=\"svg\" xmlns=\"http://www.w3.org/2000/svg\" width=\"1200\" "
       "height=\"200\"></svg></div>\n<div id=\"tip\" hidden></div>\n"
       "<section><h2>DP cycle per slave (Data_Exchange polls in view)</h2>\n<table><thead><tr>"
       "<th>lane / slave</th><th>masters</th><th>polls</th><th>no answer</th>"
       "<th>cycle min</th><th>median</th><th>max (bit times)</th></tr></thead>"
       "<tbody id=\"dxbody\"></tbody></table></section>\n"
       "<p class=\"help\">Mouse wheel over the lanes: zoom at the pointer \u00b7 drag or shift+wheel: pan \u00b7 "
       "double click: zoom in \u00b7 keys + / \u2212 zoom, \u2190 / \u2192 pan, Home whole capture, "
       "r first view \u00b7 click a frame: count bit times from its end (Esc: back to 0 s) \u00b7 "
       "hover for details. Times are the capture's (virtual time of the run); a frame lasts 11 "
       "bit times per octet at the lane's baud.</p>\n"
       "<script type=\"application/json\" id=\"pbvbus-data\">";
  o += page_json(tl, origin, vf, vt);
  o += "</script>\n<script>";
  o += detail::kTimelineJs;
  o += "</script>\n</body>\n</html>\n";
  return o;
}

std::string to_svg(const Timeline& tl, const TimelineSvgOptions& opts) {
  SvgCtx c;
  const int width = std::max(600, opts.width);
  c.plot_w = width - kLabelW - kPadR;
  c.from = tl.from_ns;
  c.to = tl.to_ns;
  c.scale = c.plot_w / static_cast<double>(std::max<std::int64_t>(1, diff(c.from, c.to)));

  // Holder colours in address order, as the page does.
  std::set<int> holder_set;
  for (const auto& L : tl.lanes)
    for (const auto& s : L.token) holder_set.insert(s.holder);
  std::map<int, std::string> holder_colour;
  {
    std::size_t i = 0;
    for (int h : holder_set) holder_colour[h] = kHolderColour[i++ % 12];
  }

  // Layout.
  // The CPU rows' legend takes a second line in the header.
  const CpuRowIndex cpu_rows(tl);
  bool any_mpi = false;
  for (const auto& L : tl.lanes) any_mpi |= !L.mpi.empty();
  const HsbyRowIndex hsby_index(tl);
  const int head_h = kHeadH + (cpu_rows.row.empty() ? 0 : 16) + (hsby_index.row.empty() ? 0 : 16) +
                     (any_mpi ? 16 : 0);
  int y = head_h + kAxisH + kEvH;
  std::vector<int> lane_y;
  for (const auto& L : tl.lanes) {
    lane_y.push_back(y);
    y += kRowFrames + 3 + kRowToken + 2 + kRowRuler + static_cast<int>(L.slaves.size()) * kRowDx +
         static_cast<int>(L.mpi.size()) * kRowMpi + kLaneGap;
  }
  const int ac_y = y;
  int ac_rows = 0;
  for (std::size_t i = 0; i < tl.active_channels.size(); ++i)
    if (i == 0 || tl.active_channels[i - 1].station != tl.active_channels[i].station) ++ac_rows;
  if (ac_rows) y += ac_rows * kRowAc + kLaneGap;
  const int cpu_y = y;
  if (!cpu_rows.row.empty()) y += static_cast<int>(cpu_rows.row.size()) * kRowCpu + kLaneGap;
  const int hsby_y = y;
  if (!hsby_index.row.empty()) y += static_cast<int>(hsby_index.row.size()) * kRowCpu + kLaneGap;
  const int lanes_end = y;
  std::vector<std::string> summary;
  for (const auto& L : tl.lanes) {
    std::uint64_t by_kind[5] = {0, 0, 0, 0, 0};
    for (const auto& f : L.frames) ++by_kind[static_cast<int>(f.kind)];
    std::string s = sanitize_utf8(L.name) + " (" + speed_text(L.speed) + "): ";
    for (int k = 0; k < 5; ++k)
      s += std::string(k ? ", " : "") + std::string(to_string(static_cast<FrameKind>(k))) + " " +
           std::to_string(by_kind[k]);
    summary.push_back(s);
    for (const auto& S : L.slaves) summary.push_back("    " + cycle_text(S, L.speed));
    for (const auto& C : L.mpi)
      summary.push_back("    MPI " + mpi_connection_label(C) + ": " +
                        std::to_string(C.data_messages) +
                        (C.data_messages == 1 ? " data message, " : " data messages, ") +
                        std::to_string(C.data_acks) +
                        (C.data_acks == 1 ? " data ack" : " data acks") +
                        (C.setup_seen ? "" : " (set-up not in the capture)"));
  }
  const int height = lanes_end + 24 + static_cast<int>(summary.size()) * 16 + 10;

  c.o.reserve(256 * 1024);
  c.o += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
         "width=\"" + std::to_string(width) + "\" height=\"" + std::to_string(height) +
         "\" viewBox=\"0 0 " + std::to_string(width) + " " + std::to_string(height) +
         "\" font-family=\"DejaVu Sans, Arial, sans-serif\">\n";
  c.o += "<rect x=\"0\" y=\"0\" width=\"" + std::to_string(width) + "\" height=\"" +
         std::to_string(height) + "\" fill=\"#ffffff\"/>\n";
  c.o += "<defs><clipPath id=\"plotclip\"><rect x=\"" + num(c.plot_x) + "\" y=\"0\" width=\"" +
         num(c.plot_w) + "\" height=\"" + std::to_string(height) +
         "\"/></clipPath><pattern id=\"achatch\" width=\"6\" height=\"6\" "
         "patternUnits=\"userSpaceOnUse\" patternTransform=\"rotate(45)\"><rect width=\"6\" "
         "height=\"6\" fill=\"#f1f3f5\"/><line x1=\"0\" y1=\"0\" x2=\"0\" y2=\"6\" "
         "stroke=\"#adb5bd\" stroke-width=\"2\"/></pattern></defs>\n";
  // Title and legend.
  c.o += "<text x=\"12\" y=\"20\" font-size=\"15\" font-weight=\"600\" fill=\"#1d2126\">pbvbus timeline \u2014 " +
         xml(opts.title.empty() ? std::string("capture") : opts.title) + "  <tspan font-weight=\"400\" fill=\"#68717d\">" +
         xml(fmt_abs(tl.from_ns, 6) + " \u2013 " + fmt_abs(tl.to_ns, 6) + " (" +
             fmt_dur(diff(tl.from_ns, tl.to_ns)) + ")") +
         "</tspan></text>\n";
  {
    double lx = 12;
    int ly = 40;
    auto sw = [&](const std::string& colour, const std::string& text, bool line) {
      if (line)
        c.o += "<rect x=\"" + num(lx) + "\" y=\"" + std::to_string(ly - 10) + "\" width=\"3\" height=\"12\" fill=\"" + colour + "\"/>";
      else
        c.o += "<rect x=\"" + num(lx) + "\" y=\"" + std::to_string(ly - 9) + "\" width=\"14\" height=\"10\" rx=\"2\" fill=\"" + colour + "\"/>";
      lx += line ? 7 : 18;
      c.o += "<text x=\"" + num(lx) + "\" y=\"" + std::to_string(ly) + "\" font-size=\"12\" fill=\"#1d2126\">" + xml(text) + "</text>\n";
      lx += static_cast<double>(text.size()) * 6.8 + 12;
    };
    auto head = [&](const std::string& text) {
      c.o += "<text x=\"" + num(lx) + "\" y=\"" + std::to_string(ly) + "\" font-size=\"12\" font-weight=\"600\" fill=\"#1d2126\">" + text + "</text>\n";
      lx += static_cast<double>(text.size()) * 7.2 + 8;
    };
    head("frames");
    for (int k = 0; k < 5; ++k) sw(kKindColour[k], std::string(to_string(static_cast<FrameKind>(k))), false);
    head("token holder");
    for (const auto& [h, col] : holder_colour) sw(col, std::to_string(h), false);
    head("DP cycle");
    sw("#3f9b57", "answered", true);
    sw("#e03131", "no answer", true);
    if (ac_rows) {
      head("active channel");
      for (std::size_t li = 0; li < tl.lanes.size(); ++li)
        sw(lane_colour(static_cast<int>(li)), tl.lanes[li].name, false);
      sw("url(#achatch)", "none", false);
    }
    if (!cpu_rows.row.empty()) {
      lx = 12;
      ly += 16;
      head("CPU state");
      std::set<int> states;
      for (const CpuStateSpan& s : tl.cpu_states) states.insert(s.state);
      for (int st : states) sw(cpu_state_colour(st), cpu_state_name(st), false);
      sw(kObColour, "OB", true);
      c.o += "<text x=\"" + num(lx) + "\" y=\"" + std::to_string(ly) +
             "\" font-size=\"12\" fill=\"#68717d\">(lighter: standby)</text>\n";
      lx += 18 * 6.8 + 12;
    }
    if (!hsby_index.row.empty()) {
      lx = 12;
      ly += 16;
      head("Quantum rack");
      lx += 8;  // the bold heading is wider than head() reckons
      std::set<int> states;
      for (const HsbyStateSpan& s : tl.hsby_states) states.insert(s.state);
      for (int st : states) sw(hsby_state_colour(st), hsby_state_name(st), false);
      sw(kSwitchoverColour, "switchover", true);
    }
    if (any_mpi) {
      lx = 12;
      ly += 16;
      head("MPI connection");
      sw(mpi_span_colour(MpiState::Connecting), "connecting", false);
      sw(mpi_span_colour(MpiState::Connected), "connected", false);
      MpiMark m;
      m.pdu = 0xE0;
      sw(mpi_mark_colour(m), "connect", true);
      m.pdu = 0xF1;
      sw(mpi_mark_colour(m), "data from PG", true);
      m.from_initiator = false;
      sw(mpi_mark_colour(m), "data to PG", true);
      m.pdu = 0xB0;
      sw(mpi_mark_colour(m), "data ack", true);
      m.pdu = 0x05;
      sw(mpi_mark_colour(m), "connection ack", true);
      m.pdu = 0x80;
      sw(mpi_mark_colour(m), "disconnect", true);
    }
    head("events");
    sw(event_colour(EventStyle::Fault), "fault", true);
    sw(event_colour(EventStyle::Repair), "repair", true);
    sw(event_colour(EventStyle::Event), "event", true);
  }
  // Time axis.
  {
    const int ay = head_h;
    const std::int64_t span = std::max<std::int64_t>(1, diff(c.from, c.to));
    const std::int64_t step = nice_step(static_cast<double>(span) / std::max(2.0, c.plot_w / 130));
    int dec = 0;
    for (std::int64_t s = kNsPerS; s > step && dec < 9; s /= 10) ++dec;
    c.o += "<rect x=\"0\" y=\"" + std::to_string(ay) + "\" width=\"" + std::to_string(width) +
           "\" height=\"" + std::to_string(kAxisH) + "\" fill=\"#f7f8fa\"/>\n";
    c.o += "<text x=\"" + std::to_string(kLabelW - 10) + "\" y=\"" + std::to_string(ay + 21) +
           "\" text-anchor=\"end\" font-size=\"12\" fill=\"#68717d\">time</text>\n";
    i128 first = static_cast<i128>(c.from) / step * step;
    if (first < c.from) first += step;
    int k = 0;
    for (i128 t = first; t <= c.to && k < 200; t += step, ++k) {
      const double x = c.x(static_cast<std::int64_t>(t));
      c.o += "<line x1=\"" + num(x) + "\" y1=\"" + std::to_string(ay + kAxisH - 8) + "\" x2=\"" +
             num(x) + "\" y2=\"" + std::to_string(lanes_end - kLaneGap) +
             "\" stroke=\"#e6e9ed\"/><line x1=\"" + num(x) + "\" y1=\"" +
             std::to_string(ay + kAxisH - 8) + "\" x2=\"" + num(x) + "\" y2=\"" +
             std::to_string(ay + kAxisH) + "\" stroke=\"#68717d\"/><text x=\"" + num(x) +
             "\" y=\"" + std::to_string(ay + kAxisH - 12) + "\" text-anchor=\"" +
             (x < c.plot_x + 40 ? "start" : x > c.plot_x + c.plot_w - 40 ? "end" : "middle") +
             "\" font-size=\"11\" fill=\"#1d2126\">" +
             xml(fmt_abs(static_cast<std::int64_t>(t), dec)) + "</text>\n";
    }
    c.o += "<line x1=\"" + num(c.plot_x) + "\" y1=\"" + std::to_string(ay + kAxisH) + "\" x2=\"" +
           num(c.plot_x + c.plot_w) + "\" y2=\"" + std::to_string(ay + kAxisH) +
           "\" stroke=\"#68717d\"/>\n";
  }
  // Lanes.
  for (std::size_t li = 0; li < tl.lanes.size(); ++li) {
    const TimelineLane& L = tl.lanes[li];
    const int ly = lane_y[li];
    const int yt = ly + kRowFrames + 3, yr = yt + kRowToken + 2, yd = yr + kRowRuler;
    const int ym = yd + static_cast<int>(L.slaves.size()) * kRowDx;
    const int lh = ym + static_cast<int>(L.mpi.size()) * kRowMpi - ly;
    c.o += "<g class=\"lane\" data-lane=\"" + xml(L.name) + "\">\n";
    c.o += "<rect x=\"0\" y=\"" + std::to_string(ly - 6) + "\" width=\"" +
           std::to_string(kLabelW - 8) + "\" height=\"" + std::to_string(lh + 12) +
           "\" fill=\"#f7f8fa\"><title>" +
           xml("interface " + std::to_string(L.interface) + ": " + L.name + " \u2014 " +
               (L.description.empty() ? std::string("no description") : L.description) + ", " +
               speed_text(L.speed)) +
           "</title></rect>\n";
    if (ac_rows)
      c.o += "<rect class=\"lane-colour\" x=\"3\" y=\"" + std::to_string(ly + 1) +
             "\" width=\"4\" height=\"" + std::to_string(kRowFrames - 2) + "\" fill=\"" +
             lane_colour(static_cast<int>(li)) + "\"/>\n";
    c.o += "<text x=\"12\" y=\"" + std::to_string(ly + 13) +
           "\" font-size=\"14\" font-weight=\"600\" fill=\"#1d2126\">" +
           xml(L.name.empty() ? std::string("(no name)") : L.name) + "</text>\n";
    c.o += "<text x=\"12\" y=\"" + std::to_string(ly + 27) + "\" font-size=\"11\" fill=\"#68717d\">" +
           xml(speed_text(L.speed) + " \u00b7 if " + std::to_string(L.interface)) + "</text>\n";
    auto row_label = [&](int yy, const std::string& t) {
      c.o += "<text x=\"" + std::to_string(kLabelW - 12) + "\" y=\"" + std::to_string(yy) +
             "\" text-anchor=\"end\" font-size=\"11\" fill=\"#495057\">" + xml(t) + "</text>\n";
    };
    row_label(yt + 13, "token holder");
    row_label(yr + 14, "bit times from left edge");
    for (std::size_t j = 0; j < L.slaves.size(); ++j)
      row_label(yd + static_cast<int>(j) * kRowDx + 11,
                "DX slave " + std::to_string(L.slaves[j].address));
    for (std::size_t j = 0; j < L.mpi.size(); ++j)
      row_label(ym + static_cast<int>(j) * kRowMpi + 12, "MPI " + mpi_connection_label(L.mpi[j]));
    c.o += "<g clip-path=\"url(#plotclip)\">\n";
    svg_frames(c, L, ly);
    svg_token(c, L, yt, holder_colour);
    svg_ruler(c, L, yr);
    svg_dx(c, L, yd);
    svg_mpi(c, L, ym);
    c.o += "</g>\n</g>\n";
  }
  if (ac_rows) {
    c.o += "<g class=\"active-channels\">\n";
    svg_active(c, tl, ac_y);
    c.o += "</g>\n";
  }
  if (!cpu_rows.row.empty()) {
    c.o += "<g class=\"cpu-rows\">\n";
    svg_cpu(c, tl, cpu_rows, cpu_y);
    c.o += "</g>\n";
  }
  if (!hsby_index.row.empty()) {
    c.o += "<g class=\"hsby-rows\">\n";
    svg_hsby(c, tl, hsby_index, hsby_y);
    c.o += "</g>\n";
  }
  c.o += "<g class=\"events\" clip-path=\"url(#plotclip)\">\n";
  svg_events(c, tl, head_h + kAxisH + 2, lanes_end - kLaneGap + 4);
  c.o += "</g>\n";
  // Summary.
  int sy = lanes_end + 14;
  c.o += "<text x=\"12\" y=\"" + std::to_string(sy) +
         "\" font-size=\"12\" font-weight=\"600\" fill=\"#1d2126\">In this window</text>\n";
  for (const std::string& s : summary) {
    sy += 16;
    c.o += "<text x=\"12\" y=\"" + std::to_string(sy) +
           "\" font-size=\"12\" fill=\"#1d2126\" xml:space=\"preserve\">" + xml(s) + "</text>\n";
  }
  c.o += "</svg>\n";
  return std::move(c.o);
}

}  // namespace pbvbus::captures
