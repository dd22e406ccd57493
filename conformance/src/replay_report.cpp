// Text and JSON reports of a replay (replay.hpp: "Report").

#include <cstdio>
#include <sstream>

#include "pbvbus/conformance/replay.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::conformance {

namespace {

std::string replay_hex(const std::vector<std::uint8_t>& b) {
  std::string s;
  char buf[4];
  for (std::size_t i = 0; i < b.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%02X", b[i]);
    if (i) s += ' ';
    s += buf;
  }
  return s;
}

std::string replay_json_str(const std::string& s) {
  std::string o = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      o += '\\';
      o += static_cast<char>(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      o += buf;
    } else {
      o += static_cast<char>(c);
    }
  }
  return o + "\"";
}

std::string time_text(bus::Ticks t) {
  char buf[48];
  const std::int64_t ns = bus::ticks_to_ns(t);
  std::snprintf(buf, sizeof buf, "%lld.%06lld ms", static_cast<long long>(ns / 1'000'000),
                static_cast<long long>(ns % 1'000'000));
  return buf;
}

constexpr std::size_t kCol = 5;  // "DSAP " is the widest field name

std::string row(const char* label, const std::vector<std::string>& cells) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "    %-9s", label);
  std::string s = buf;
  for (const auto& c : cells) {
    s += c;
    s.append(kCol > c.size() ? kCol - c.size() : 1, ' ');
  }
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s + "\n";
}

std::vector<std::string> hex_cells(const std::vector<std::uint8_t>& b) {
  std::vector<std::string> c;
  char buf[4];
  for (std::uint8_t x : b) {
    std::snprintf(buf, sizeof buf, "%02X", x);
    c.emplace_back(buf);
  }
  return c;
}

void diff_text(std::ostringstream& o, const ReplayDiff& d, std::size_t n) {
  o << "  #" << n << "  " << time_text(d.time) << "  station " << int(d.station) << "  "
    << d.service << "  " << diff_kind_name(d.kind);
  if (!d.du_offsets.empty()) {
    o << " (DU octet" << (d.du_offsets.size() > 1 ? "s" : "");
    for (std::size_t k : d.du_offsets) o << ' ' << k;
    o << ')';
  }
  if (d.tsdr_bits) o << "  TSDR " << *d.tsdr_bits << " bit times";
  o << "\n";
  o << row("request", hex_cells(d.request));
  const std::vector<std::uint8_t>& shape = d.recorded ? *d.recorded : d.replayed ? *d.replayed : d.request;
  std::vector<std::string> fields = frame_field_names(shape);
  const std::size_t width = std::max(d.recorded ? d.recorded->size() : 0, d.replayed ? d.replayed->size() : 0);
  while (fields.size() < width) fields.emplace_back("+");
  o << row("field", fields);
  o << row("recorded", d.recorded ? hex_cells(*d.recorded) : std::vector<std::string>{"(none)"});
  o << row("replayed", d.replayed ? hex_cells(*d.replayed) : std::vector<std::string>{"(none)"});
  if (!d.frame_offsets.empty()) {
    std::vector<std::string> mark(width);
    for (std::size_t k : d.frame_offsets)
      if (k < width) mark[k] = "^^";
    o << row("", mark);
  }
}

}  // namespace

std::vector<std::string> frame_field_names(const std::vector<std::uint8_t>& b) {
  std::vector<std::string> f;
  if (b.empty()) return f;
  const std::uint8_t sd = b[0];
  std::size_t i = 0;
  auto push = [&](const char* name) {
    if (i < b.size()) {
      f.emplace_back(name);
      ++i;
    }
  };
  if (sd == fdl::kSC) {
    push("SC");
  } else if (sd == fdl::kSD4) {
    push("SD");
    push("DA");
    push("SA");
  } else if (sd == fdl::kSD1 || sd == fdl::kSD2 || sd == fdl::kSD3) {
    push("SD");
    if (sd == fdl::kSD2) {
      push("LE");
      push("LEr");
      push("SD");
    }
    const bool dae = i < b.size() && (b[i] & fdl::kExt);
    push("DA");
    const bool sae = i < b.size() && (b[i] & fdl::kExt);
    push("SA");
    push("FC");
    // Extension chains: each octet with bit 7 set is followed by another of the same chain.
    for (int chain = 0; chain < 2; ++chain) {
      if (!(chain == 0 ? dae : sae)) continue;
      while (i + 2 < b.size()) {
        const std::uint8_t x = b[i];
        push((x & fdl::kExtSegment) ? (chain == 0 ? "DSEG" : "SSEG") : (chain == 0 ? "DSAP" : "SSAP"));
        if (!(x & fdl::kExt)) break;
      }
    }
    while (i + 2 < b.size()) push("DU");
    push("FCS");
    push("ED");
  }
  while (f.size() < b.size()) f.emplace_back("?");
  return f;
}

std::string replay_text(const ReplayResult& r, std::size_t max_diffs) {
  std::ostringstream o;
  o << "replay of line " << r.line << " (" << bus::baud_name(r.baud) << "bit/s), target "
    << (r.station ? "station " + std::to_string(*r.station) : std::string("all stations"))
    << ", pacing " << replay_pacing_name(r.pacing) << "\n";
  o << "  recorded frames      " << r.recorded_frames << " (" << r.unusable.size() << " unusable)\n";
  o << "  requests replayed    " << r.requests_replayed << " (+ " << r.tokens_replayed << " tokens)\n";
  o << "  compared             " << r.compared;
  if (r.not_compared_unusable) o << " (" << r.not_compared_unusable << " not compared: recorded reply unusable)";
  o << "\n  matches              " << r.matches << "\n";
  o << "  differences          " << r.diffs.size() << "\n";
  for (int k = 0; k < 5; ++k)
    o << "    " << diff_kind_name(static_cast<DiffKind>(k)) << std::string(17 - std::string(diff_kind_name(static_cast<DiffKind>(k))).size(), ' ')
      << r.by_kind[k] << "\n";
  o << "  TSDR window          [" << r.min_tsdr << ", " << r.max_tsdr << "] bit times\n";
  o << "  pacing slips         " << r.pacing_slips << "\n";
  if (r.masks.empty()) {
    o << "  masks                none\n";
  } else {
    for (const auto& [rule, n] : r.masks) o << "  mask " << rule << ": " << n << " octets masked\n";
  }
  if (!r.read_error.empty()) o << "  reading stopped early: " << r.read_error << "\n";
  if (!r.unusable.empty()) {
    o << "unusable recorded frames:\n";
    for (const ReplayFrame* f : r.unusable)
      o << "  record " << f->record << " (file offset " << f->offset << ", " << time_text(f->start)
        << "): " << f->unusable_reason << "\n";
  }
  if (!r.diffs.empty()) {
    const std::size_t n = std::min(max_diffs, r.diffs.size());
    o << "differences (first " << n << " of " << r.diffs.size() << "):\n";
    for (std::size_t i = 0; i < n; ++i) diff_text(o, r.diffs[i], i + 1);
  }
  o << (r.diffs.empty() ? "result: no differences\n" : "result: DIFFERENCES\n");
  return o.str();
}

std::string replay_json(const ReplayResult& r, std::size_t max_diffs) {
  std::ostringstream o;
  o << "{\"schema\":\"pbvbus.replay/1\",\"line\":" << replay_json_str(r.line)
    << ",\"baud\":" << static_cast<std::uint32_t>(r.baud) << ",\"target\":"
    << (r.station ? std::to_string(*r.station) : std::string("\"all\"")) << ",\"pacing\":\""
    << replay_pacing_name(r.pacing) << "\",\"totals\":{\"recorded_frames\":" << r.recorded_frames
    << ",\"requests_replayed\":" << r.requests_replayed << ",\"tokens_replayed\":" << r.tokens_replayed
    << ",\"compared\":" << r.compared << ",\"matches\":" << r.matches
    << ",\"differences\":" << r.diffs.size() << ",\"by_kind\":{";
  for (int k = 0; k < 5; ++k)
    o << (k ? "," : "") << '"' << diff_kind_key(static_cast<DiffKind>(k)) << "\":" << r.by_kind[k];
  o << "},\"not_compared_reply_unusable\":" << r.not_compared_unusable
    << ",\"unusable\":" << r.unusable.size() << ",\"pacing_slips\":" << r.pacing_slips << "}";
  o << ",\"tsdr_window\":[" << r.min_tsdr << "," << r.max_tsdr << "],\"masks\":[";
  for (std::size_t i = 0; i < r.masks.size(); ++i)
    o << (i ? "," : "") << "{\"rule\":" << replay_json_str(r.masks[i].first)
      << ",\"octets_masked\":" << r.masks[i].second << "}";
  o << "],\"unusable\":[";
  for (std::size_t i = 0; i < r.unusable.size(); ++i) {
    const ReplayFrame* f = r.unusable[i];
    o << (i ? "," : "") << "{\"record\":" << f->record << ",\"offset\":" << f->offset
      << ",\"time_ns\":" << bus::ticks_to_ns(f->start) << ",\"reason\":" << replay_json_str(f->unusable_reason) << "}";
  }
  o << "]";
  if (!r.read_error.empty()) o << ",\"read_error\":" << replay_json_str(r.read_error);
  o << ",\"differences\":[";
  const std::size_t n = std::min(max_diffs, r.diffs.size());
  for (std::size_t i = 0; i < n; ++i) {
    const ReplayDiff& d = r.diffs[i];
    o << (i ? "," : "") << "{\"kind\":\"" << diff_kind_key(d.kind) << "\",\"time_ns\":"
      << bus::ticks_to_ns(d.time) << ",\"station\":" << int(d.station)
      << ",\"service\":" << replay_json_str(d.service) << ",\"request\":\"" << replay_hex(d.request) << "\""
      << ",\"recorded\":" << (d.recorded ? "\"" + replay_hex(*d.recorded) + "\"" : std::string("null"))
      << ",\"replayed\":" << (d.replayed ? "\"" + replay_hex(*d.replayed) + "\"" : std::string("null"))
      << ",\"frame_offsets\":[";
    for (std::size_t k = 0; k < d.frame_offsets.size(); ++k) o << (k ? "," : "") << d.frame_offsets[k];
    o << "],\"du_offsets\":[";
    for (std::size_t k = 0; k < d.du_offsets.size(); ++k) o << (k ? "," : "") << d.du_offsets[k];
    o << "],\"tsdr_bits\":" << (d.tsdr_bits ? std::to_string(*d.tsdr_bits) : std::string("null")) << "}";
  }
  o << "]}\n";
  return o.str();
}

}  // namespace pbvbus::conformance
