// The H-system part of the report in text and JSON (h_report.hpp).
#include "pbvbus/reports/h_report.hpp"

#include <cstdio>
#include <sstream>

#include "pbvbus/reports/json_text.hpp"

namespace pbvbus::tools {

namespace {

std::string hex_byte(std::uint8_t b) {
  static const char* d = "0123456789ABCDEF";
  return {d[b >> 4], d[b & 0xF]};
}

using devices::CpuRole;
using devices::CpuState;
using devices::HEvent;
using devices::HProfile;
using devices::Redf;
using devices::SystemMode;

std::string_view profile_name(HProfile p) { return p == HProfile::S7_1500RH ? "S7-1500R/H" : "S7-400H"; }

std::string_view kind_name(HEvent::Kind k) {
  switch (k) {
    case HEvent::Kind::State: return "state";
    case HEvent::Kind::Role: return "role";
    case HEvent::Kind::SystemMode: return "system_mode";
    case HEvent::Kind::Ob: return "ob";
  }
  return "?";
}

std::string hex16(std::uint16_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "W#16#%04X", static_cast<unsigned>(v));
  return b;
}

/// Milliseconds with three decimals (µs resolution, rounded down), a valid JSON number.
std::string ms3(bus::Ticks t) {
  const std::int64_t us = t / bus::kTicksPerUs;
  char b[40];
  std::snprintf(b, sizeof b, "%lld.%03lld", static_cast<long long>(us / 1000),
                static_cast<long long>(us % 1000));
  return b;
}

std::string pad(std::string_view s, std::size_t w) {
  std::string r(s);
  if (r.size() < w) r.append(w - r.size(), ' ');
  else r += ' ';
  return r;
}

std::string ob_cell(int ob, std::uint16_t code) {
  if (ob == 0) return {};
  std::string s = "OB " + std::to_string(ob);
  if (code != 0) s += " " + hex16(code);
  return s;
}

std::string cpu_name(int rack) {
  return "CPU " + std::to_string(rack) + " (rack " + std::to_string(rack) + ")";
}

void json_time(std::ostream& os, const char* key, bus::Ticks t) {
  os << "\"" << key << "_ns\":" << bus::ticks_to_ns(t) << ",\"" << key << "_ms\":" << ms3(t);
}
void json_opt_time(std::ostream& os, const char* key, const std::optional<bus::Ticks>& t) {
  if (t) {
    json_time(os, key, *t);
  } else {
    os << "\"" << key << "_ns\":null,\"" << key << "_ms\":null";
  }
}

struct WindowCheck {
  std::optional<bus::Ticks> measured;
  std::optional<bus::Ticks> planned;
  std::string verdict;  ///< "within", "EXCEEDED", "not measured", "not planned"
};
WindowCheck check_window(const HUpdateWindow& w, const std::optional<bus::Ticks>& start,
                         const std::optional<bus::Ticks>& planned) {
  WindowCheck c;
  c.planned = planned;
  if (start) c.measured = w.t5 - *start;
  if (!c.measured) c.verdict = "not measured";
  else if (!planned) c.verdict = "not planned";
  else c.verdict = std::string(window_verdict(*c.measured, *planned));
  return c;
}

}  // namespace
std::string format_s_ms(bus::Ticks t) {
  const std::int64_t ms = t / bus::kTicksPerMs;
  char b[40];
  std::snprintf(b, sizeof b, "%lld.%03lld", static_cast<long long>(ms / 1000),
                static_cast<long long>(ms % 1000));
  return b;
}

std::string_view window_verdict(bus::Ticks measured, bus::Ticks planned) {
  return measured <= planned ? "within" : "EXCEEDED";
}

void write_h_text(const std::vector<HSystemReport>& systems, std::ostream& os) {
  for (const HSystemReport& s : systems) {
    const HProfile p = s.profile;
    os << "H-system \"" << s.name << "\" (" << profile_name(p) << "): system mode "
       << devices::to_string(s.mode, p) << "\n";
    for (const HCpuReport& c : s.cpus) {
      const auto& l = c.leds;
      os << "  " << cpu_name(c.rack) << ": " << devices::to_string(c.state) << ", "
         << devices::to_string(c.role, p) << ", sees " << devices::to_string(c.mode, p)
         << "; LEDs MSTR " << (l.mstr ? "on" : "off") << ", RACK" << c.rack << " "
         << ((c.rack == 0 ? l.rack0 : l.rack1) ? "on" : "off") << ", REDF " << devices::to_string(l.redf)
         << ", IFM1F " << (l.ifm1f ? "on" : "off") << ", IFM2F " << (l.ifm2f ? "on" : "off");
      for (std::size_t k = 0; k < c.busf.size(); ++k) os << ", BUS" << (k + 1) << "F " << c.busf[k];
      os << "\n";
    }
    for (const HCpuReport& c : s.cpus) {
      os << "  " << cpu_name(c.rack) << " timeline:\n";
      os << "    " << pad("time [s]", 10) << pad("state", 13) << pad("role", 9) << pad("system mode", 14)
         << pad("REDF", 7) << pad("MSTR", 5) << pad("OB", 16) << "event\n";
      for (const HTimelineRow& t : c.timeline)
        os << "    " << pad(format_s_ms(t.at), 10) << pad(devices::to_string(t.state), 13)
           << pad(devices::to_string(t.role, p), 9) << pad(devices::to_string(t.mode, p), 14)
           << pad(devices::to_string(t.redf), 7) << pad(t.mstr ? "on" : "off", 5)
           << pad(ob_cell(t.ob, t.code), 16) << t.change << "\n";
    }
    for (const HCpuReport& c : s.cpus) {
      os << "  " << cpu_name(c.rack) << " diagnostic buffer (" << c.diag.size() << " entries):\n";
      for (const auto& d : c.diag) {
        os << "    " << pad(format_s_ms(d.at), 10) << pad(devices::to_string(d.role, p), 9);
        if (d.code != 0) os << hex16(d.code) << " ";
        os << d.text << "\n";
      }
    }
    if (!s.io_map.empty()) {
      os << "  process images (IB = inputs, QB = outputs):\n";
      for (const HIoMapRow& m : s.io_map) {
        if (m.rack != 0) os << "    expansion rack " << m.rack << " module " << m.module << ":";
        else os << "    station " << static_cast<int>(m.address) << " module " << m.module << ":";
        if (m.in_len != 0)
          os << " IB " << m.in_addr << ".." << (m.in_addr + m.in_len - 1);
        if (m.out_len != 0)
          os << " QB " << m.out_addr << ".." << (m.out_addr + m.out_len - 1);
        os << "\n";
      }
    }
    if (!s.racks.empty()) {
      os << "  expansion racks:\n";
      for (const HRackReport& r : s.racks) {
        os << "    rack " << r.number << " on CPU " << r.side << ": " << (r.on ? "on" : "OFF") << ", "
           << (r.reachable ? "reachable" : "not reachable") << (r.ob85 ? ", OB 85 episode open" : "");
        for (const auto& m : r.modules) {
          if (m.outputs.empty()) continue;
          os << "; " << m.name << " outputs";
          for (std::uint8_t b : m.outputs) os << " " << hex_byte(b);
        }
        os << "\n";
      }
      os << "  OB 80 calls: " << s.ob80 << "\n";
    }
    if (!s.faults.empty()) {
      os << "  H faults:\n";
      for (const auto& [at, text] : s.faults) os << "    " << pad(format_s_ms(at), 10) << text << "\n";
    }
    if (!s.connections.empty()) {  // F4 connections
      os << "  connections:\n";
      for (const HConnectionRow& c : s.connections) {
        os << "    " << c.name << " (" << c.kind << "): " << c.state;
        if (!c.active.empty()) os << ", active path " << c.active;
        os << "\n";
        for (const auto& [at, text] : c.events) os << "      " << pad(format_s_ms(at), 10) << text << "\n";
      }
    }
    if (s.io_events.empty()) {
      os << "  I/O events: none\n";
    } else {
      os << "  I/O events:\n";
      for (const HIoEvent& e : s.io_events) {
        std::string racks;
        for (int k : e.racks) racks += (racks.empty() ? "CPU " : "+") + std::to_string(k);
        os << "    " << pad(format_s_ms(e.at), 10) << pad(racks, 10) << pad(ob_cell(e.ob, e.code), 16)
           << e.text << "\n";
      }
    }
    if (s.updates.empty()) {
      os << "  updates: none\n";
    } else {
      os << "  updates:\n";
      for (const HUpdateWindow& w : s.updates) {
        os << "    CPU " << w.rack << ": t1 " << format_s_ms(w.t1) << " s, t5 " << format_s_ms(w.t5) << " s ("
           << bus::format_duration(w.t5 - w.t1) << (w.completed ? "" : ", aborted") << ")";
        const WindowCheck p15 = check_window(w, w.t3, s.planned_t_p15);
        const WindowCheck ph = check_window(w, w.t4, s.planned_t_ph);
        for (const auto& [name, c] : {std::pair{"T_P15", &p15}, std::pair{"T_PH", &ph}}) {
          os << "; " << name << " window ";
          if (c->measured) os << bus::format_duration(*c->measured);
          else os << "-";
          os << " / planned ";
          if (c->planned) os << bus::format_duration(*c->planned);
          else os << "-";
          os << ": " << c->verdict;
        }
        if (w.last_io_before && w.first_io_after) {
          const bus::Ticks gap = *w.first_io_after - *w.last_io_before;
          os << "; no I/O update for " << bus::format_duration(gap) << " (OB 1 at "
             << format_s_ms(*w.last_io_before) << " s and " << format_s_ms(*w.first_io_after) << " s)";
          if (s.planned_t_p15)
            os << ": " << window_verdict(gap, *s.planned_t_p15 + w.scan_time) << " T_P15 + scan time";
        }
        os << "\n";
      }
    }
  }
}

void write_h_json(const std::vector<HSystemReport>& systems, std::ostream& os) {
  if (systems.empty()) return;
  const auto b = [](bool v) { return v ? "true" : "false"; };
  os << ",\"h_systems_run\":[";
  for (std::size_t i = 0; i < systems.size(); ++i) {
    const HSystemReport& s = systems[i];
    os << (i ? "," : "") << "{\"name\":" << json_quote(s.name) << ",\"profile\":"
       << json_quote(profile_name(s.profile)) << ",\"system_mode\":" << json_quote(devices::to_string(s.mode))
       << ",\"cpus\":[";
    for (std::size_t k = 0; k < 2; ++k) {
      const HCpuReport& c = s.cpus[k];
      const auto& l = c.leds;
      os << (k ? "," : "") << "{\"rack\":" << c.rack << ",\"state\":" << json_quote(devices::to_string(c.state))
         << ",\"role\":" << json_quote(devices::to_string(c.role))
         << ",\"system_mode\":" << json_quote(devices::to_string(c.mode)) << ",\"leds\":{\"mstr\":" << b(l.mstr)
         << ",\"rack0\":" << b(l.rack0) << ",\"rack1\":" << b(l.rack1)
         << ",\"redf\":" << json_quote(devices::to_string(l.redf)) << ",\"ifm1f\":" << b(l.ifm1f)
         << ",\"ifm2f\":" << b(l.ifm2f) << ",\"busf\":[";
      for (std::size_t x = 0; x < c.busf.size(); ++x) os << (x ? "," : "") << json_quote(c.busf[x]);
      os << "]},\"diag\":[";
      for (std::size_t d = 0; d < c.diag.size(); ++d) {
        const auto& e = c.diag[d];
        os << (d ? "," : "") << "{";
        json_time(os, "time", e.at);
        os << ",\"role\":" << json_quote(devices::to_string(e.role)) << ",\"code\":" << e.code
           << ",\"text\":" << json_quote(e.text) << "}";
      }
      os << "],\"timeline\":[";
      for (std::size_t t = 0; t < c.timeline.size(); ++t) {
        const auto& e = c.timeline[t];
        os << (t ? "," : "") << "{";
        json_time(os, "time", e.at);
        os << ",\"kind\":" << json_quote(kind_name(e.kind)) << ",\"change\":" << json_quote(e.change)
           << ",\"state\":" << json_quote(devices::to_string(e.state))
           << ",\"role\":" << json_quote(devices::to_string(e.role))
           << ",\"system_mode\":" << json_quote(devices::to_string(e.mode))
           << ",\"redf\":" << json_quote(devices::to_string(e.redf)) << ",\"mstr\":" << b(e.mstr)
           << ",\"ob\":" << e.ob << ",\"code\":" << e.code
           << ",\"reason\":" << json_quote(devices::to_string(e.reason)) << "}";
      }
      os << "]}";
    }
    os << "],\"faults\":[";
    for (std::size_t k = 0; k < s.faults.size(); ++k) {
      os << (k ? "," : "") << "{";
      json_time(os, "time", s.faults[k].first);
      os << ",\"text\":" << json_quote(s.faults[k].second) << "}";
    }
    os << "],\"io_map\":[";
    for (std::size_t k = 0; k < s.io_map.size(); ++k) {
      const HIoMapRow& m = s.io_map[k];
      os << (k ? "," : "") << "{\"station\":" << static_cast<int>(m.address) << ",\"module\":" << m.module
         << ",\"in_addr\":" << m.in_addr << ",\"in_len\":" << m.in_len << ",\"out_addr\":" << m.out_addr
         << ",\"out_len\":" << m.out_len;
      if (m.rack != 0) os << ",\"rack\":" << m.rack;  // central (F8) rows only
      os << "}";
    }
    if (!s.racks.empty()) {
      os << "],\"ob80\":" << s.ob80 << ",\"expansion_racks\":[";
      for (std::size_t k = 0; k < s.racks.size(); ++k) {
        const HRackReport& r = s.racks[k];
        os << (k ? "," : "") << "{\"number\":" << r.number << ",\"side\":" << r.side
           << ",\"on\":" << (r.on ? "true" : "false") << ",\"reachable\":" << (r.reachable ? "true" : "false")
           << ",\"ob85\":" << (r.ob85 ? "true" : "false") << ",\"modules\":[";
        for (std::size_t m = 0; m < r.modules.size(); ++m) {
          os << (m ? "," : "") << "{\"name\":" << json_quote(r.modules[m].name) << ",\"outputs\":[";
          for (std::size_t o = 0; o < r.modules[m].outputs.size(); ++o)
            os << (o ? "," : "") << static_cast<int>(r.modules[m].outputs[o]);
          os << "]}";
        }
        os << "]}";
      }
    }
    os << "],\"io_events\":[";
    for (std::size_t k = 0; k < s.io_events.size(); ++k) {
      const auto& e = s.io_events[k];
      os << (k ? "," : "") << "{";
      json_time(os, "time", e.at);
      os << ",\"racks\":[";
      for (std::size_t x = 0; x < e.racks.size(); ++x) os << (x ? "," : "") << e.racks[x];
      os << "],\"ob\":" << e.ob << ",\"code\":" << e.code;
      if (e.mdl_addr) os << ",\"mdl_addr\":" << *e.mdl_addr << ",\"mdl_stop\":" << (e.mdl_stop ? "true" : "false");
      os << ",\"text\":" << json_quote(e.text) << "}";
    }
    os << "],\"updates\":[";
    for (std::size_t k = 0; k < s.updates.size(); ++k) {
      const auto& w = s.updates[k];
      os << (k ? "," : "") << "{\"rack\":" << w.rack << ",";
      json_time(os, "t1", w.t1);
      os << ",";
      json_opt_time(os, "t3", w.t3);
      os << ",";
      json_opt_time(os, "t4", w.t4);
      os << ",";
      json_time(os, "t5", w.t5);
      os << ",\"completed\":" << b(w.completed);
      const WindowCheck p15 = check_window(w, w.t3, s.planned_t_p15);
      const WindowCheck ph = check_window(w, w.t4, s.planned_t_ph);
      os << ",";
      json_opt_time(os, "t_p15_window", p15.measured);
      os << ",";
      json_opt_time(os, "planned_t_p15", p15.planned);
      os << ",\"t_p15_verdict\":" << json_quote(p15.verdict) << ",";
      json_opt_time(os, "t_ph_window", ph.measured);
      os << ",";
      json_opt_time(os, "planned_t_ph", ph.planned);
      os << ",\"t_ph_verdict\":" << json_quote(ph.verdict) << ",";
      json_opt_time(os, "last_io_before", w.last_io_before);
      os << ",";
      json_opt_time(os, "first_io_after", w.first_io_after);
      os << "}";
    }
    os << "],\"connections\":[";  // F4 connections (last: the keys before keep their order)
    for (std::size_t k = 0; k < s.connections.size(); ++k) {
      const HConnectionRow& c = s.connections[k];
      os << (k ? "," : "") << "{\"name\":" << json_quote(c.name) << ",\"kind\":" << json_quote(c.kind)
         << ",\"state\":" << json_quote(c.state) << ",\"active\":" << json_quote(c.active) << ",\"events\":[";
      for (std::size_t x = 0; x < c.events.size(); ++x) {
        os << (x ? "," : "") << "{";
        json_time(os, "time", c.events[x].first);
        os << ",\"text\":" << json_quote(c.events[x].second) << "}";
      }
      os << "]}";
    }
    os << "]}";
  }
  os << "]";
}

}  // namespace pbvbus::tools
