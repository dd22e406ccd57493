#include "pbvbus/simulation/capture_probes.hpp"

#include <charconv>

#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::tools {

std::optional<ProbeDefault> parse_probe_default(std::string_view text) {
  if (text == "first") return ProbeDefault{ProbeDefault::Kind::First, 0};
  if (text == "last") return ProbeDefault{ProbeDefault::Kind::Last, 0};
  unsigned v = 0;
  const auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || p != text.data() + text.size() || v > 126)
    return std::nullopt;
  return ProbeDefault{ProbeDefault::Kind::Address, static_cast<std::uint8_t>(v)};
}

namespace {

std::string where_of(const PlanStation& s) {
  if (s.address) return "station " + std::to_string(*s.address);
  return std::string(to_string(s.kind));  // a serial monitor has no address
}

}  // namespace

std::optional<std::vector<CaptureProbe>> plan_capture_probes(const ScenarioPlan& plan,
                                                             const ProbeDefault& def,
                                                             std::string* error) {
  std::vector<CaptureProbe> out;
  for (std::size_t li = 0; li < plan.lines.size(); ++li) {
    const PlanLine& line = plan.lines[li];
    if (line.stations.empty()) continue;
    std::vector<int> positions;
    std::vector<PlanProbe> wanted = line.probes;
    if (wanted.empty()) wanted.push_back({});
    for (const PlanProbe& p : wanted) {
      int pos = p.position;
      if (pos < 0) {
        switch (def.kind) {
          case ProbeDefault::Kind::First: pos = 0; break;
          case ProbeDefault::Kind::Last: pos = static_cast<int>(line.stations.size()) - 1; break;
          case ProbeDefault::Kind::Address:
            pos = line.position_of(def.address);
            if (pos < 0) {
              if (error)
                *error = "--probe " + std::to_string(def.address) + ": no station " +
                         std::to_string(def.address) + " on line \"" + line.name +
                         "\" (a scenario entry capture { line: \"" + line.name +
                         "\" at: N } places that line's probe)";
              return std::nullopt;
            }
            break;
        }
      }
      bool dup = false;
      for (int q : positions) dup |= q == pos;
      if (!dup) positions.push_back(pos);
    }
    for (int pos : positions) {
      const PlanStation& st = line.stations[static_cast<std::size_t>(pos)];
      CaptureProbe cp;
      cp.line = li;
      cp.position = pos;
      cp.where = where_of(st);
      cp.name = line.name;
      if (positions.size() > 1)
        cp.name += "@" + (st.address ? std::to_string(*st.address) : cp.where);
      out.push_back(std::move(cp));
    }
  }
  return out;
}

void attach_capture(captures::PcapngWriter& writer, bus::Line& line, std::size_t li,
                    const std::vector<CaptureProbe>& probes) {
  bool any = false;
  for (const CaptureProbe& p : probes) {
    if (p.line != li) continue;
    writer.add_probe(line, p.position, p.name, p.where);
    line.add_tap(writer, bus::ProbePoint{p.position});
    any = true;
  }
  if (!any) writer.add_line(line);  // nothing attached: nothing to hear, but keep the id order
}

}  // namespace pbvbus::tools
