#include "pbvbus/captures/inspect.hpp"

#include <algorithm>
#include <cstdio>

#include "pbvbus/captures/event_record.hpp"
#include "pbvbus/captures/hsby_event.hpp"
#include "pbvbus/captures/pcapng_format.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "capture_names.hpp"
#include "timeline_mpi.hpp"

namespace pbvbus::captures {

namespace {

/// "40.000 ms": a takeover time in ms with µs digits (rounded down), exactly from the ns.
std::string inspect_ms(std::uint64_t ns) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%llu.%03llu ms", static_cast<unsigned long long>(ns / 1'000'000),
                static_cast<unsigned long long>(ns % 1'000'000 / 1'000));
  return buf;
}
__extension__ typedef __int128 i128;

using names::is_events_link;
using names::is_line_link;
using names::sap_service;

std::string frame_type_of(std::span<const std::uint8_t> b) {
  if (b.empty()) return "empty";
  switch (b[0]) {
    case fdl::kSD1:
      return "SD1";
    case fdl::kSD2:
      return "SD2";
    case fdl::kSD3:
      return "SD3";
    case fdl::kSD4:
      return "SD4";
    case fdl::kSC:
      return "SC";
    default:
      return "garbage";
  }
}

void add_flag_reasons(std::uint32_t flags, std::vector<std::string>& out) {
  for (std::string_view r : names::flag_reasons(flags)) out.emplace_back(r);
}


std::string format_speed(std::uint64_t s) {
  if (s == 0) return "speed unknown";
  char buf[48];
  if (s >= 1'000'000 && s % 1'000'000 == 0)
    std::snprintf(buf, sizeof buf, "%llu Mbit/s", static_cast<unsigned long long>(s / 1'000'000));
  else if (s >= 1'000'000)
    std::snprintf(buf, sizeof buf, "%llu.%llu Mbit/s",
                  static_cast<unsigned long long>(s / 1'000'000),
                  static_cast<unsigned long long>(s % 1'000'000 / 100'000));
  else if (s % 1000 == 0)
    std::snprintf(buf, sizeof buf, "%llu kbit/s", static_cast<unsigned long long>(s / 1000));
  else if (s >= 1000) {
    std::string frac = std::to_string(s % 1000);
    frac = std::string(3 - frac.size(), '0') + frac;
    while (!frac.empty() && frac.back() == '0') frac.pop_back();
    std::snprintf(buf, sizeof buf, "%llu.%s kbit/s", static_cast<unsigned long long>(s / 1000),
                  frac.c_str());
  } else
    std::snprintf(buf, sizeof buf, "%llu bit/s", static_cast<unsigned long long>(s));
  return buf;
}

std::string link_name(std::uint16_t lt) {
  switch (lt) {
    case 147:
      return "USER0";
    case 148:
      return "USER1";
    case 252:
      return "UPPER_PDU";
    case 257:
      return "PROFIBUS_DL";
    default:
      return "link type " + std::to_string(lt);
  }
}

std::string json_escape(std::string_view s) {
  std::string o;
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
      case '\r':
        o += "\\r";
        break;
      case '\t':
        o += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x",
                        static_cast<unsigned>(static_cast<unsigned char>(c)));
          o += buf;
        } else {
          o += c;
        }
    }
  }
  return o;
}

std::string json_map(const std::map<std::string, std::uint64_t>& m) {
  std::string o = "{";
  bool first = true;
  for (const auto& [k, v] : m) {
    if (!first) o += ",";
    first = false;
    o += "\"" + json_escape(k) + "\":" + std::to_string(v);
  }
  return o + "}";
}

template <class T>
std::string json_opt(const std::optional<T>& v) {
  return v ? std::to_string(*v) : "null";
}

std::string text_map(const std::map<std::string, std::uint64_t>& m) {
  std::string o;
  for (const auto& [k, v] : m) {
    if (!o.empty()) o += ", ";
    o += k + " " + std::to_string(v);
  }
  return o.empty() ? "none" : o;
}

struct Tracker {
  std::optional<std::int64_t> prev_start;
  std::uint64_t prev_len = 0;
};

void count_frame(InterfaceSummary& s, Tracker& tr, const PcapngRecord& r) {
  const std::span<const std::uint8_t> b(r.bytes);
  ++s.by_type[frame_type_of(b)];
  // Reasons for a bad frame.
  std::vector<std::string> reasons;
  if (!r.comment.empty()) {
    std::size_t pos = 0;
    while (pos <= r.comment.size()) {
      std::size_t end = r.comment.find(", ", pos);
      if (end == std::string::npos) end = r.comment.size();
      std::string part = r.comment.substr(pos, end - pos);
      const std::size_t colon = part.find(':');
      if (colon != std::string::npos) part.resize(colon);
      if (!part.empty()) reasons.push_back(part);
      pos = end + 2;
    }
  }
  fdl::Telegram t;
  const fdl::DecodeError err = fdl::decode(b, t);
  // A comment alone (an annotation added in Wireshark) does not make a frame bad.
  if ((r.flags & pcapng::kFlagErrorMask) != 0 || err != fdl::DecodeError::None) {
    ++s.bad_frames;
    if (reasons.empty()) {
      add_flag_reasons(r.flags & pcapng::kFlagErrorMask, reasons);
      if (err != fdl::DecodeError::None) reasons.emplace_back(fdl::to_string(err));
    }
    std::sort(reasons.begin(), reasons.end());
    reasons.erase(std::unique(reasons.begin(), reasons.end()), reasons.end());
    for (const auto& why : reasons) ++s.bad_by_reason[why];
  }
  if (err == fdl::DecodeError::None && t.type != fdl::FrameType::SC &&
      t.type != fdl::FrameType::SD4) {
    if (t.is_request()) {
      ++s.by_request[t.fc == fdl::kFcClockValue
                         ? std::string("CV")
                         : std::string(fdl::to_string(fdl::fc_request_fn(t.fc)))];
    } else {
      ++s.by_response[std::string(fdl::to_string(fdl::fc_status(t.fc)))];
    }
    const bool req = t.is_request();
    const std::optional<std::uint8_t> sap = req ? t.dsap : t.ssap;
    std::string service;
    const auto mpi = (r.flags & pcapng::kFlagErrorMask) == 0 && req
                         ? mpi_frame(b, is_mpi_description(s.description))
                         : std::nullopt;
    if (mpi) {
      ++s.by_mpi[std::string(mpi_pdu_name(mpi->pdu.type))];
    } else if (sap) {
      service = std::string(sap_service(*sap));
    } else if (req) {
      const auto fn = fdl::fc_request_fn(t.fc);
      if (fn == fdl::RequestFn::SrdHigh || fn == fdl::RequestFn::SrdLow) service = "Data_Exchange";
    } else {
      const auto st = fdl::fc_status(t.fc);
      if (st == fdl::ResponseStatus::DL || st == fdl::ResponseStatus::DH ||
          st == fdl::ResponseStatus::RDL || st == fdl::ResponseStatus::RDH)
        service = "Data_Exchange";
    }
    if (!service.empty()) ++s.by_service[service + (req ? ".req" : ".res")];
  }
  // Idle gap in bit times since the end of the previous frame of this interface.
  if (s.speed > 0) {
    if (tr.prev_start) {
      const i128 delta_bits =
          (static_cast<i128>(r.ts_ns - *tr.prev_start) * static_cast<i128>(s.speed) + 500'000'000) /
          1'000'000'000;
      const i128 gap = delta_bits - static_cast<i128>(tr.prev_len) * 11;
      if (gap < 0) {
        ++s.overlaps;
      } else {
        const auto g = static_cast<std::int64_t>(gap);
        if (!s.min_idle_bits || g < *s.min_idle_bits) s.min_idle_bits = g;
      }
    }
    tr.prev_start = r.ts_ns;
    tr.prev_len = b.size();
  }
}
}  // namespace

std::optional<CaptureSummary> summarize(PcapngReader& reader, PcapngError& error) {
  CaptureSummary s;
  std::vector<Tracker> trackers;
  PcapngRecord r;
  auto sync_interfaces = [&] {
    const auto& ifs = reader.interfaces();
    while (s.interfaces.size() < ifs.size()) {
      const PcapngInterface& i = ifs[s.interfaces.size()];
      InterfaceSummary is;
      is.name = i.name;
      is.description = i.description;
      is.link_type = i.link_type;
      is.speed = i.speed;
      s.interfaces.push_back(std::move(is));
      trackers.emplace_back();
    }
  };
  while (reader.next(r)) {
    sync_interfaces();
    ++s.records;
    if (!s.first_ns || r.ts_ns < *s.first_ns) s.first_ns = r.ts_ns;
    if (!s.last_ns || r.ts_ns > *s.last_ns) s.last_ns = r.ts_ns;
    InterfaceSummary& is = s.interfaces[r.interface];
    ++is.frames;
    is.octets += r.bytes.size();
    if (!is.first_ns || r.ts_ns < *is.first_ns) is.first_ns = r.ts_ns;
    if (!is.last_ns || r.ts_ns > *is.last_ns) is.last_ns = r.ts_ns;
    if (is_line_link(is.link_type)) {
      count_frame(is, trackers[r.interface], r);
    } else if (is_events_link(is.link_type)) {
      auto e = decode_event(r.bytes);
      if (!e) {
        ++s.bad_event_records;
        continue;
      }
      EventSummary es;
      es.ts_ns = r.ts_ns;
      es.interface = r.interface;
      es.category = std::string(to_string(e->category));
      es.code = e->code;
      es.line = e->line;
      es.a = e->a;
      es.b = e->b;
      es.value = e->value;
      if (e->category == EventCategory::Hsby) {
        ++s.hsby_records;
        const auto h = hsby_event_fields(*e);
        if (h && h->kind == HsbyEventKind::Switchover)
          s.hsby_switchovers.push_back({r.ts_ns, h->rack, h->takeover_ns, h->text});
      }
      es.text = std::move(e->text);
      s.events.push_back(std::move(es));
    }
  }
  sync_interfaces();
  if (reader.error()) {
    error = *reader.error();
    return std::nullopt;
  }
  return s;
}

std::optional<CaptureSummary> inspect_file(const std::string& path, PcapngError& error) {
  auto reader = PcapngReader::open(path, error);
  if (!reader) return std::nullopt;
  return summarize(*reader, error);
}

std::string to_text(const CaptureSummary& s) {
  std::string o;
  o += "Records: " + std::to_string(s.records) + " (" + std::to_string(s.events.size()) +
       " events)\n";
  if (s.first_ns)
    o += "Time span: " + names::format_time_ns(*s.first_ns) + " .. " + names::format_time_ns(*s.last_ns) + " (" +
         names::format_time_ns(*s.last_ns - *s.first_ns) + ")\n";
  for (std::size_t i = 0; i < s.interfaces.size(); ++i) {
    const InterfaceSummary& is = s.interfaces[i];
    o += "Interface " + std::to_string(i) + " '" + is.name + "' (" + link_name(is.link_type) +
         ", " + format_speed(is.speed) + "): " + std::to_string(is.frames) + " records, " +
         std::to_string(is.octets) + " octets\n";
    if (is.first_ns)
      o += "  time span: " + names::format_time_ns(*is.first_ns) + " .. " + names::format_time_ns(*is.last_ns) + "\n";
    if (!is_line_link(is.link_type)) continue;
    o += "  frame types: " + text_map(is.by_type) + "\n";
    o += "  requests: " + text_map(is.by_request) + "\n";
    o += "  responses: " + text_map(is.by_response) + "\n";
    o += "  DP services: " + text_map(is.by_service) + "\n";
    if (!is.by_mpi.empty()) o += "  MPI PDUs: " + text_map(is.by_mpi) + "\n";
    o += "  bad frames: " + std::to_string(is.bad_frames);
    if (is.bad_frames) o += " (" + text_map(is.bad_by_reason) + ")";
    o += "\n";
    o += "  min idle gap: " +
         (is.min_idle_bits ? std::to_string(*is.min_idle_bits) + " bit times" : std::string("n/a"));
    if (is.overlaps) o += ", " + std::to_string(is.overlaps) + " overlapping frames";
    o += "\n";
  }
  o += "Events: " + std::to_string(s.events.size()) + "\n";
  for (const EventSummary& e : s.events)
    o += "  " + names::format_time_ns(e.ts_ns) + "  [" + e.category + "] " + e.text + "\n";
  if (s.bad_event_records)
    o += "Unreadable event records: " + std::to_string(s.bad_event_records) + "\n";
  if (s.hsby_records) {
    o += "Quantum Hot Standby: " + std::to_string(s.hsby_records) + " records, " +
         std::to_string(s.hsby_switchovers.size()) + " switchovers\n";
    for (const HsbySwitchoverSummary& w : s.hsby_switchovers) {
      o += "  " + names::format_time_ns(w.ts_ns) + "  to rack " + std::to_string(w.rack) + ", ";
      if (w.takeover_ns == 0)
        o += "no takeover time";
      else
        o += "takeover " + inspect_ms(w.takeover_ns);
      o += ": " + w.text + "\n";
    }
  }
  return o;
}

std::string to_json(const CaptureSummary& s) {
  std::string o = "{\"records\":" + std::to_string(s.records) +
                  ",\"first_ns\":" + json_opt(s.first_ns) + ",\"last_ns\":" + json_opt(s.last_ns) +
                  ",\"interfaces\":[";
  for (std::size_t i = 0; i < s.interfaces.size(); ++i) {
    const InterfaceSummary& is = s.interfaces[i];
    if (i) o += ",";
    o += "{\"id\":" + std::to_string(i) + ",\"name\":\"" + json_escape(is.name) +
         "\",\"description\":\"" + json_escape(is.description) +
         "\",\"link_type\":" + std::to_string(is.link_type) +
         ",\"speed\":" + std::to_string(is.speed) + ",\"records\":" + std::to_string(is.frames) +
         ",\"octets\":" + std::to_string(is.octets) + ",\"first_ns\":" + json_opt(is.first_ns) +
         ",\"last_ns\":" + json_opt(is.last_ns);
    if (is_line_link(is.link_type)) {
      o += ",\"frame_types\":" + json_map(is.by_type) + ",\"requests\":" + json_map(is.by_request) +
           ",\"responses\":" + json_map(is.by_response) +
           ",\"services\":" + json_map(is.by_service) + ",\"mpi_pdus\":" + json_map(is.by_mpi) +
           ",\"bad_frames\":" + std::to_string(is.bad_frames) +
           ",\"bad_by_reason\":" + json_map(is.bad_by_reason) +
           ",\"min_idle_bits\":" + json_opt(is.min_idle_bits) +
           ",\"overlaps\":" + std::to_string(is.overlaps);
    }
    o += "}";
  }
  o += "],\"hsby\":{\"records\":" + std::to_string(s.hsby_records) + ",\"switchovers\":[";
  for (std::size_t i = 0; i < s.hsby_switchovers.size(); ++i) {
    const HsbySwitchoverSummary& w = s.hsby_switchovers[i];
    o += std::string(i ? "," : "") + "{\"ts_ns\":" + std::to_string(w.ts_ns) +
         ",\"rack\":" + std::to_string(w.rack) + ",\"takeover_ns\":" + std::to_string(w.takeover_ns) +
         ",\"text\":\"" + json_escape(w.text) + "\"}";
  }
  o += "]},\"events\":[";
  for (std::size_t i = 0; i < s.events.size(); ++i) {
    const EventSummary& e = s.events[i];
    if (i) o += ",";
    o += "{\"ts_ns\":" + std::to_string(e.ts_ns) + ",\"category\":\"" + json_escape(e.category) +
         "\",\"code\":" + std::to_string(e.code) + ",\"line\":" + std::to_string(e.line) +
         ",\"a\":" + std::to_string(e.a) + ",\"b\":" + std::to_string(e.b) +
         ",\"value\":" + std::to_string(e.value) + ",\"text\":\"" + json_escape(e.text) + "\"}";
  }
  o += "],\"bad_event_records\":" + std::to_string(s.bad_event_records) + "}";
  return o;
}

}  // namespace pbvbus::captures
