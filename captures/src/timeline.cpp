#include "pbvbus/captures/timeline.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <system_error>

#include "pbvbus/bus/tap.hpp"
#include "pbvbus/captures/cpu_event.hpp"
#include "pbvbus/captures/hsby_event.hpp"
#include "pbvbus/captures/pcapng_format.hpp"
#include "saturate.hpp"
#include "capture_names.hpp"
#include "timeline_mpi.hpp"

namespace pbvbus::captures {

namespace {

constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();
/// if_speed values above this are treated as unknown (keeps every product inside i128).
constexpr std::uint64_t kMaxSpeed = 1'000'000'000'000ULL;

std::int64_t sat_sub(std::int64_t a, std::int64_t b) {
  return saturate(static_cast<i128>(a) - static_cast<i128>(b));
}

using names::is_events_link;
using names::is_line_link;
using names::sap_service;

bool is_srd(const TimelineFrame& f) {
  const auto fn = fdl::fc_request_fn(f.fc);
  return fn == fdl::RequestFn::SrdHigh || fn == fdl::RequestFn::SrdLow;
}

bool is_data_exchange_request(const TimelineFrame& f) {
  return f.kind == FrameKind::Request && f.fc != fdl::kFcClockValue && is_srd(f) && !f.dsap &&
         f.da != fdl::kBroadcast;
}

bool is_data_response(const TimelineFrame& f) {
  if (f.kind != FrameKind::Response) return false;
  const auto st = fdl::fc_status(f.fc);
  return st == fdl::ResponseStatus::DL || st == fdl::ResponseStatus::DH ||
         st == fdl::ResponseStatus::RDL || st == fdl::ResponseStatus::RDH;
}

/// The frames after a request that are searched for its answer ...
constexpr std::size_t kAnswerLookahead = 32;
/// ... and how far after its end (more than the longest slot time, 16383 bit times).
constexpr std::int64_t kAnswerWindowBits = 65536;

/// Index of the frame that answers the request frames[i], if any (timeline.hpp).
std::optional<std::size_t> find_answer(const std::vector<TimelineFrame>& frames, std::size_t i,
                                       std::uint64_t speed) {
  const TimelineFrame& req = frames[i];
  const std::int64_t window =
      speed ? frame_duration_ns(static_cast<std::size_t>(kAnswerWindowBits), speed) / 11
            : std::int64_t{1'000'000'000};
  // A reply starts TSDR >= 11 bit times after the request; allow one bit for ns rounding.
  const std::int64_t min_gap = speed ? frame_duration_ns(10, speed) / 11 : 0;
  bool other_request = false;
  for (std::size_t k = i + 1; k < frames.size() && k <= i + kAnswerLookahead; ++k) {
    const TimelineFrame& f = frames[k];
    const std::int64_t gap = sat_sub(f.start_ns, req.end_ns);
    if (gap > window) break;
    const bool in_time = gap >= min_gap;
    if (f.kind == FrameKind::Sc && in_time && !other_request) return k;
    if (f.kind == FrameKind::Response && in_time && f.sa == req.da && f.da == req.sa) return k;
    if ((f.kind == FrameKind::Request || f.kind == FrameKind::Token) && f.sa == req.sa) break;
    if (f.kind == FrameKind::Request) other_request = true;
  }
  return std::nullopt;
}

void flag_reasons(std::uint32_t flags, std::string& out) {
  for (std::string_view r : names::flag_reasons(flags)) {
    if (!out.empty()) out += ", ";
    out += r;
  }
}

TimelineFrame make_frame(const PcapngRecord& r, std::uint64_t speed, bool mpi_marked) {
  TimelineFrame f;
  f.start_ns = r.ts_ns;
  f.end_ns = saturate(static_cast<i128>(r.ts_ns) + frame_duration_ns(r.bytes.size(), speed));
  f.bytes = r.bytes;
  f.flags = r.flags;
  f.comment = r.comment;
  fdl::Telegram t;
  const fdl::DecodeError err = fdl::decode(f.bytes, t);
  if (err == fdl::DecodeError::None) {
    f.decoded = true;
    f.type = t.type;
    f.da = t.da;
    f.sa = t.sa;
    f.fc = t.fc;
    f.dsap = t.dsap;
    f.ssap = t.ssap;
    f.data_len = t.data.size();
  }
  const bool flagged = (r.flags & pcapng::kFlagErrorMask) != 0;
  if (flagged || !f.decoded) {
    f.kind = FrameKind::Bad;
    if (!r.comment.empty())
      f.problem = r.comment;
    else
      flag_reasons(r.flags & pcapng::kFlagErrorMask, f.problem);
    if (!f.decoded) {
      const std::string why(fdl::to_string(err));
      if (f.problem.find(why) == std::string::npos) {
        if (!f.problem.empty()) f.problem += "; ";
        f.problem += "decoder: " + why;
      }
    }
  } else if (t.type == fdl::FrameType::SD4) {
    f.kind = FrameKind::Token;
  } else if (t.type == fdl::FrameType::SC) {
    f.kind = FrameKind::Sc;
  } else {
    f.kind = fdl::fc_is_request(t.fc) ? FrameKind::Request : FrameKind::Response;
    if (f.kind == FrameKind::Request)
      if (const auto m = mpi_frame(f.bytes, mpi_marked)) f.mpi = mpi_pdu_words(m->pdu);
  }
  return f;
}

EventStyle style_of(const EventRecord& e) {
  if (e.category != EventCategory::Line) return EventStyle::Event;
  switch (static_cast<bus::LineEventKind>(e.code)) {
    case bus::LineEventKind::CableCut:
    case bus::LineEventKind::ShortCircuit:
    case bus::LineEventKind::NoiseOn:
    case bus::LineEventKind::PowerOff:
    case bus::LineEventKind::TransceiverFailed:
    case bus::LineEventKind::BabbleOn:
      return EventStyle::Fault;
    case bus::LineEventKind::CableRepaired:
    case bus::LineEventKind::ShortRepaired:
    case bus::LineEventKind::NoiseOff:
    case bus::LineEventKind::PowerOn:
    case bus::LineEventKind::TransceiverRepaired:
    case bus::LineEventKind::BabbleOff:
      return EventStyle::Repair;
  }
  return EventStyle::Event;
}

/// Everything of one lane over the whole capture, before the window is applied.
struct LaneWork {
  TimelineLane lane;
  std::vector<TimelineFrame> frames;
};

/// The window is [from, to) with `to` in i128: a default window ends 1 ns after the last
/// frame, which may lie beyond the int64 range.
void finish_lane(LaneWork& w, std::int64_t from, i128 to) {
  TimelineLane& lane = w.lane;
  auto& frames = w.frames;
  std::stable_sort(frames.begin(), frames.end(), [](const TimelineFrame& a, const TimelineFrame& b) {
    return a.start_ns < b.start_ns;
  });
  // Idle gaps, token spans, Data_Exchange polls: on the whole lane.
  std::int64_t lane_end = kMin;
  std::vector<TokenSpan> spans;
  std::map<std::uint8_t, std::vector<DxPoll>> polls;
  std::set<std::uint8_t> answering;
  std::map<std::uint8_t, std::int64_t> last_poll;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    TimelineFrame& f = frames[i];
    if (i > 0) {
      f.idle_ns = sat_sub(f.start_ns, frames[i - 1].end_ns);
      f.idle_bits = ns_to_bits(*f.idle_ns, lane.speed);
    }
    if (f.kind == FrameKind::Token) {
      if (!spans.empty()) spans.back().end_ns = std::max(spans.back().start_ns, f.start_ns);
      spans.push_back({f.end_ns, f.end_ns, f.da, f.sa});
    }
    if (is_data_exchange_request(f)) {
      DxPoll p;
      p.start_ns = f.start_ns;
      p.master = f.sa;
      if (const auto k = find_answer(frames, i, lane.speed)) {
        p.answered = true;
        if (is_data_response(frames[*k]) || frames[*k].kind == FrameKind::Sc) answering.insert(f.da);
      }
      const auto it = last_poll.find(f.da);
      if (it != last_poll.end()) p.cycle_ns = sat_sub(f.start_ns, it->second);
      last_poll[f.da] = f.start_ns;
      polls[f.da].push_back(p);
    }
    lane_end = std::max(lane_end, f.end_ns);
  }
  if (!spans.empty()) spans.back().end_ns = std::max(spans.back().start_ns, lane_end);
  lane.mpi = mpi_connections(frames, lane.mpi_marked, lane_end, from, to);

  // The window.
  auto overlaps = [&](std::int64_t s, std::int64_t e) {
    return s < to && (e > from || (e == s && s >= from));
  };
  for (TimelineFrame& f : frames) {
    if (!overlaps(f.start_ns, f.end_ns)) continue;
    if (f.kind == FrameKind::Bad) ++lane.bad_frames;
    lane.frames.push_back(std::move(f));
  }
  frames.clear();
  for (const TokenSpan& s : spans)
    if (overlaps(s.start_ns, s.end_ns)) lane.token.push_back(s);
  for (auto& [addr, list] : polls) {
    if (!answering.count(addr)) continue;
    SlaveCycles sc;
    sc.address = addr;
    std::vector<std::int64_t> cycles;
    for (const DxPoll& p : list) {
      if (p.start_ns < from || p.start_ns >= to) continue;
      sc.polls.push_back(p);
      if (!p.answered) ++sc.unanswered;
      if (p.cycle_ns) cycles.push_back(*p.cycle_ns);
    }
    if (!cycles.empty()) {
      std::sort(cycles.begin(), cycles.end());
      sc.cycle.count = cycles.size();
      sc.cycle.min_ns = cycles.front();
      sc.cycle.max_ns = cycles.back();
      sc.cycle.median_ns = cycles[(cycles.size() - 1) / 2];
    }
    lane.slaves.push_back(std::move(sc));
  }
}

/// Line index -> lane index as timeline.hpp ("Active channel") says, for the line indices that
/// Redundancy records name. One pass over the events and the lanes.
class LineLanes {
 public:
  LineLanes(const std::vector<TimelineEvent>& events, const std::vector<LaneWork>& lanes)
      : m_lanes(lanes) {
    for (const TimelineEvent& e : events) {
      if (e.record.category != EventCategory::Line || e.record.line < 0) continue;
      const auto colon = e.record.text.find(": ");
      if (colon == std::string::npos || colon == 0) continue;
      m_names.try_emplace(e.record.line, e.record.text.substr(0, colon));
    }
    for (std::size_t i = 0; i < lanes.size(); ++i)
      if (i == 0 || stem(lanes[i].lane.name) != stem(lanes[i - 1].lane.name))
        m_groups.push_back(static_cast<int>(i));
  }
  int lane(int line) const {
    if (line < 0) return -1;
    const auto it = m_names.find(line);
    if (it != m_names.end()) {
      const std::string& name = it->second;
      for (std::size_t i = 0; i < m_lanes.size(); ++i) {
        const std::string& n = m_lanes[i].lane.name;
        if (n == name || (n.size() > name.size() && n.compare(0, name.size(), name) == 0 &&
                          n[name.size()] == '@'))
          return static_cast<int>(i);
      }
      return -1;  // the line's name is known but no lane carries it
    }
    const auto g = static_cast<std::size_t>(line);
    return g < m_groups.size() ? m_groups[g] : -1;
  }

 private:
  static std::string stem(const std::string& n) { return n.substr(0, n.find('@')); }
  const std::vector<LaneWork>& m_lanes;
  std::map<int, std::string> m_names;
  std::vector<int> m_groups;  ///< first lane of each group of lanes of one line
};

/// The active-channel spans of the switched stations over the whole capture (timeline.hpp);
/// `events` in time order.
std::vector<ActiveChannelSpan> active_channels(const std::vector<TimelineEvent>& events,
                                               const std::vector<LaneWork>& lanes,
                                               std::int64_t end) {
  constexpr std::uint16_t kStationFailure = 2, kSwitchover = 6;
  auto redundancy = [](const EventRecord& r) {
    return r.category == EventCategory::Redundancy && r.a >= 0;
  };
  std::map<int, std::vector<ActiveChannelSpan>> rows;  // the switched stations
  for (const TimelineEvent& e : events)
    if (redundancy(e.record) && e.record.code == kSwitchover) rows.try_emplace(e.record.a);
  if (rows.empty()) return {};
  const LineLanes line_lanes(events, lanes);
  std::map<int, int> lane_cache;
  auto lane_for = [&](int line) {
    auto it = lane_cache.find(line);
    if (it == lane_cache.end()) it = lane_cache.emplace(line, line_lanes.lane(line)).first;
    return it->second;
  };
  for (const TimelineEvent& e : events) {
    const EventRecord& r = e.record;
    if (!redundancy(r)) continue;
    const auto it = rows.find(r.a);
    if (it == rows.end()) continue;
    std::vector<ActiveChannelSpan>& row = it->second;
    int line;
    if (r.code == kSwitchover)
      line = r.line < 0 ? -1 : r.line;
    else if (r.code == kStationFailure || row.empty())
      line = -1;
    else
      continue;
    if (!row.empty()) {
      ActiveChannelSpan& cur = row.back();
      if (cur.line == line) continue;
      cur.end_ns = std::max(cur.start_ns, e.ts_ns);
      if (cur.end_ns == cur.start_ns) row.pop_back();   // replaced at the same instant
      if (!row.empty() && row.back().line == line) continue;  // back to the one before
    }
    row.push_back({r.a, line, line < 0 ? -1 : lane_for(line), e.ts_ns, e.ts_ns});
  }
  std::vector<ActiveChannelSpan> out;
  for (auto& [station, row] : rows) {
    if (!row.empty()) row.back().end_ns = std::max(row.back().start_ns, end);
    out.insert(out.end(), row.begin(), row.end());
  }
  return out;
}

/// The H system's name in a Cpu record's text (timeline.hpp "CPU rows"): the part before
/// ": CPU <who>: ", or "" when the text starts with "CPU <who>: " or names no CPU that way.
std::string cpu_system_of(const std::string& text, int rack) {
  const std::string who = "CPU " + (rack < 0 ? std::string("0+1") : std::to_string(rack)) + ": ";
  if (text.compare(0, who.size(), who) == 0) return "";
  const auto p = text.find(": " + who);
  return p == std::string::npos ? std::string() : text.substr(0, p);
}

struct CpuRows {
  std::vector<CpuStateSpan> spans;
  std::vector<CpuObMark> obs;
};

/// The CPU state spans and OB marks over the whole capture (timeline.hpp); `events` in time
/// order.
CpuRows cpu_rows(const std::vector<TimelineEvent>& events, std::int64_t end) {
  using Key = std::pair<std::string, int>;  // (system, rack)
  std::map<Key, std::vector<CpuStateSpan>> rows;
  std::map<Key, std::vector<CpuObMark>> marks;
  std::vector<std::optional<CpuEventFields>> fields(events.size());
  for (std::size_t i = 0; i < events.size(); ++i) {
    if (events[i].record.category != EventCategory::Cpu) continue;
    fields[i] = cpu_event_fields(events[i].record);
    const auto& f = fields[i];
    if (f && f->kind == CpuEventKind::State && f->rack >= 0)
      rows.try_emplace(Key{cpu_system_of(f->text, f->rack), f->rack});
  }
  CpuRows out;
  if (rows.empty()) return out;
  for (std::size_t i = 0; i < events.size(); ++i) {
    if (!fields[i]) continue;
    const CpuEventFields& f = *fields[i];
    const std::int64_t ts = events[i].ts_ns;
    const std::string system = cpu_system_of(f.text, f.rack);
    if (f.kind == CpuEventKind::Ob) {
      CpuObMark m{system, f.rack, ts, f.ob, f.event_id, f.reason, f.text};
      if (f.rack >= 0) {
        if (rows.count(Key{system, f.rack})) marks[Key{system, f.rack}].push_back(std::move(m));
      } else if (f.rack == -1) {  // both CPUs: a mark on each row of the system
        for (auto it = rows.lower_bound(Key{system, 0});
             it != rows.end() && it->first.first == system; ++it) {
          m.rack = it->first.second;
          marks[it->first].push_back(m);
        }
      }
      continue;
    }
    if (f.kind != CpuEventKind::State && f.kind != CpuEventKind::Role) continue;
    const auto it = rows.find(Key{system, f.rack});
    if (it == rows.end()) continue;
    std::vector<CpuStateSpan>& row = it->second;
    int state, role;
    if (f.kind == CpuEventKind::State) {
      state = f.to;
      role = f.role;
    } else if (row.empty()) {
      continue;  // before the first State record
    } else {
      state = row.back().state;
      role = f.to;
    }
    if (!row.empty()) {
      CpuStateSpan& cur = row.back();
      if (cur.state == state && cur.role == role) continue;
      cur.end_ns = std::max(cur.start_ns, ts);
      if (cur.end_ns == cur.start_ns) row.pop_back();  // replaced at the same instant
      if (!row.empty() && row.back().state == state && row.back().role == role)
        continue;  // back to the one before
    }
    row.push_back({system, f.rack, state, role, ts, ts});
  }
  for (auto& [key, row] : rows) {
    if (!row.empty()) row.back().end_ns = std::max(row.back().start_ns, end);
    out.spans.insert(out.spans.end(), row.begin(), row.end());
    const auto m = marks.find(key);
    if (m != marks.end()) out.obs.insert(out.obs.end(), m->second.begin(), m->second.end());
  }
  return out;
}

struct HsbyRows {
  std::vector<HsbyStateSpan> spans;
  std::vector<HsbySwitchoverMark> marks;
};

/// The Quantum racks' state spans and switchover marks over the whole capture (timeline.hpp
/// "Quantum Hot Standby rows"); `events` in time order.
HsbyRows hsby_rows(const std::vector<TimelineEvent>& events, std::int64_t end) {
  using Key = std::pair<std::string, int>;  // (pair, rack)
  std::map<Key, std::vector<HsbyStateSpan>> rows;
  std::map<Key, std::vector<HsbySwitchoverMark>> marks;
  for (const TimelineEvent& e : events) {
    if (e.record.category != EventCategory::Hsby) continue;
    const auto f = hsby_event_fields(e.record);
    if (!f || f->rack < 0) continue;
    const Key key{hsby_pair_name(f->text, f->rack), f->rack};
    if (f->state >= 0) {
      std::vector<HsbyStateSpan>& row = rows[key];
      bool add = true;
      if (!row.empty()) {
        HsbyStateSpan& cur = row.back();
        if (cur.state == f->state) {
          add = false;
        } else {
          cur.end_ns = std::max(cur.start_ns, e.ts_ns);
          if (cur.end_ns == cur.start_ns) row.pop_back();  // replaced at the same instant
          if (!row.empty() && row.back().state == f->state) add = false;  // back to the one before
        }
      }
      if (add) row.push_back({key.first, f->rack, f->state, e.ts_ns, e.ts_ns});
    }
    if (f->kind == HsbyEventKind::Switchover)
      marks[key].push_back({key.first, f->rack, e.ts_ns, f->takeover_ns, f->text});
  }
  HsbyRows out;
  for (auto& [key, row] : rows) {
    if (row.empty()) continue;
    row.back().end_ns = std::max(row.back().start_ns, end);
    out.spans.insert(out.spans.end(), row.begin(), row.end());
    const auto m = marks.find(key);
    if (m != marks.end()) out.marks.insert(out.marks.end(), m->second.begin(), m->second.end());
  }
  return out;
}

}  // namespace

std::string_view to_string(FrameKind k) {
  switch (k) {
    case FrameKind::Token:
      return "token";
    case FrameKind::Request:
      return "request";
    case FrameKind::Response:
      return "response";
    case FrameKind::Sc:
      return "SC";
    case FrameKind::Bad:
      return "bad";
  }
  return "?";
}

std::string_view to_string(MpiState s) {
  switch (s) {
    case MpiState::Connecting:
      return "connecting";
    case MpiState::Connected:
      return "connected";
  }
  return "?";
}

std::string_view to_string(EventStyle s) {
  switch (s) {
    case EventStyle::Fault:
      return "fault";
    case EventStyle::Repair:
      return "repair";
    case EventStyle::Event:
      return "event";
  }
  return "?";
}

std::int64_t frame_duration_ns(std::size_t octets, std::uint64_t speed) {
  if (speed == 0 || speed > kMaxSpeed) return 0;
  return saturate(static_cast<i128>(octets) * 11 * 1'000'000'000 / static_cast<i128>(speed));
}

std::optional<std::int64_t> ns_to_bits(std::int64_t ns, std::uint64_t speed) {
  if (speed == 0 || speed > kMaxSpeed) return std::nullopt;
  const i128 p = static_cast<i128>(ns) * static_cast<i128>(speed);
  const i128 half = 500'000'000;
  return saturate(p >= 0 ? (p + half) / 1'000'000'000 : (p - half) / 1'000'000'000);
}

std::optional<Timeline> build_timeline(PcapngReader& reader, const TimelineOptions& opts,
                                       std::string& error) {
  if (opts.from_ns && opts.to_ns && *opts.from_ns >= *opts.to_ns) {
    error = "the window start " + format_time_ns(*opts.from_ns) + " is not before its end " +
            format_time_ns(*opts.to_ns);
    return std::nullopt;
  }
  Timeline tl;
  std::vector<LaneWork> lanes;
  std::vector<int> lane_of;  // per interface: index into lanes, -1 events, -2 skipped
  std::vector<TimelineEvent> events;
  std::optional<std::int64_t> first, last;
  auto note = [&](std::int64_t s, std::int64_t e) {
    if (!first || s < *first) first = s;
    if (!last || e > *last) last = e;
  };
  auto sync = [&] {
    const auto& ifs = reader.interfaces();
    while (lane_of.size() < ifs.size()) {
      const PcapngInterface& i = ifs[lane_of.size()];
      if (is_line_link(i.link_type)) {
        LaneWork w;
        w.lane.interface = static_cast<std::uint32_t>(lane_of.size());
        w.lane.name = i.name;
        w.lane.description = i.description;
        w.lane.link_type = i.link_type;
        w.lane.speed = i.speed <= kMaxSpeed ? i.speed : 0;
        w.lane.mpi_marked = is_mpi_description(i.description);
        lane_of.push_back(static_cast<int>(lanes.size()));
        lanes.push_back(std::move(w));
      } else if (is_events_link(i.link_type)) {
        lane_of.push_back(-1);
      } else {
        lane_of.push_back(-2);
        ++tl.skipped_interfaces;
      }
    }
  };
  PcapngRecord r;
  while (reader.next(r)) {
    sync();
    ++tl.records;
    if (r.interface >= lane_of.size()) continue;  // the reader guarantees this; stay safe
    const int l = lane_of[r.interface];
    if (l >= 0) {
      LaneWork& w = lanes[static_cast<std::size_t>(l)];
      w.frames.push_back(make_frame(r, w.lane.speed, w.lane.mpi_marked));
      note(w.frames.back().start_ns, w.frames.back().end_ns);
    } else if (l == -1) {
      auto e = decode_event(r.bytes);
      if (!e) {
        ++tl.bad_event_records;
        continue;
      }
      TimelineEvent ev;
      ev.ts_ns = r.ts_ns;
      ev.interface = r.interface;
      ev.style = style_of(*e);
      ev.record = std::move(*e);
      note(ev.ts_ns, ev.ts_ns);
      events.push_back(std::move(ev));
    }
  }
  sync();
  if (reader.error()) {
    error = reader.error()->to_string();
    return std::nullopt;
  }
  if (tl.records == 0) {
    error = "the capture holds no records (no frames and no events)";
    return std::nullopt;
  }
  if (lanes.empty()) {
    error = "the capture has no line interface (link type 147 USER0 or 257 PROFIBUS_DL)";
    return std::nullopt;
  }
  tl.first_ns = first.value_or(0);
  tl.last_ns = last.value_or(tl.first_ns);
  tl.from_ns = opts.from_ns.value_or(tl.first_ns);
  const i128 to = opts.to_ns ? static_cast<i128>(*opts.to_ns) : static_cast<i128>(tl.last_ns) + 1;
  if (tl.from_ns >= to) {
    error = "the window start " + format_time_ns(tl.from_ns) + " is not before its end " +
            format_time_ns(saturate(to)) + " (the capture ends at " + format_time_ns(tl.last_ns) +
            ")";
    return std::nullopt;
  }
  tl.to_ns = saturate(to);
  std::stable_sort(events.begin(), events.end(), [](const TimelineEvent& a, const TimelineEvent& b) {
    return a.ts_ns < b.ts_ns;
  });
  for (const ActiveChannelSpan& s : active_channels(events, lanes, tl.last_ns))
    if (s.start_ns < to &&
        (s.end_ns > tl.from_ns || (s.end_ns == s.start_ns && s.start_ns >= tl.from_ns)))
      tl.active_channels.push_back(s);
  CpuRows cpu = cpu_rows(events, tl.last_ns);
  for (CpuStateSpan& s : cpu.spans)
    if (s.start_ns < to &&
        (s.end_ns > tl.from_ns || (s.end_ns == s.start_ns && s.start_ns >= tl.from_ns)))
      tl.cpu_states.push_back(std::move(s));
  for (CpuObMark& m : cpu.obs)
    if (m.ts_ns >= tl.from_ns && m.ts_ns < to) tl.cpu_obs.push_back(std::move(m));
  HsbyRows hsby = hsby_rows(events, tl.last_ns);
  for (HsbyStateSpan& s : hsby.spans)
    if (s.start_ns < to &&
        (s.end_ns > tl.from_ns || (s.end_ns == s.start_ns && s.start_ns >= tl.from_ns)))
      tl.hsby_states.push_back(std::move(s));
  for (HsbySwitchoverMark& m : hsby.marks)
    if (m.ts_ns >= tl.from_ns && m.ts_ns < to) tl.hsby_switchovers.push_back(std::move(m));
  for (LaneWork& w : lanes) {
    finish_lane(w, tl.from_ns, to);
    tl.lanes.push_back(std::move(w.lane));
  }
  for (TimelineEvent& e : events)
    if (e.ts_ns >= tl.from_ns && e.ts_ns < to) tl.events.push_back(std::move(e));
  return tl;
}

std::optional<Timeline> build_timeline(std::span<const std::uint8_t> data,
                                       const TimelineOptions& opts, std::string& error) {
  if (data.empty()) {
    error = "offset 0: empty file, not a pcapng capture";
    return std::nullopt;
  }
  PcapngReader reader(std::vector<std::uint8_t>(data.begin(), data.end()));
  return build_timeline(reader, opts, error);
}

std::optional<Timeline> read_timeline_file(const std::string& path, const TimelineOptions& opts,
                                           std::string& error) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec) && std::filesystem::file_size(path, ec) == 0 &&
      !ec) {
    error = "offset 0: empty file, not a pcapng capture";
    return std::nullopt;
  }
  PcapngError perr;
  auto reader = PcapngReader::open(path, perr);
  if (!reader) {
    error = perr.to_string();
    return std::nullopt;
  }
  return build_timeline(*reader, opts, error);
}

std::string describe(const TimelineFrame& f) {
  std::string o;
  char buf[160];
  const std::size_t n = f.bytes.size();
  if (f.kind == FrameKind::Bad) {
    o += "BAD FRAME: " + (f.problem.empty() ? std::string("error flags") : f.problem) + "\n";
  }
  if (!f.decoded) {
    if (n == 0) {
      o += "no octets";
    } else {
      std::snprintf(buf, sizeof buf, "first octet 0x%02X, %zu octets", f.bytes[0], n);
      o += buf;
    }
    return o;
  }
  switch (f.type) {
    case fdl::FrameType::SD4:
      std::snprintf(buf, sizeof buf, "SD4 token %u \u2192 %u", unsigned{f.sa}, unsigned{f.da});
      o += buf;
      return o;
    case fdl::FrameType::SC:
      o += "SC short acknowledgement (0xE5)";
      return o;
    default:
      break;
  }
  const bool req = fdl::fc_is_request(f.fc);
  std::snprintf(buf, sizeof buf, "%s %s %u \u2192 %u\n", std::string(fdl::to_string(f.type)).c_str(),
                req ? "request" : "response", unsigned{f.sa}, unsigned{f.da});
  o += buf;
  if (req) {
    const std::string fn = f.fc == fdl::kFcClockValue
                               ? std::string("Clock_Value")
                               : std::string(fdl::to_string(fdl::fc_request_fn(f.fc)));
    std::snprintf(buf, sizeof buf, "FC 0x%02X: %s, FCV=%d FCB=%d\n", unsigned{f.fc}, fn.c_str(),
                  fdl::fc_fcv(f.fc) ? 1 : 0, fdl::fc_fcb(f.fc) ? 1 : 0);
  } else {
    std::snprintf(buf, sizeof buf, "FC 0x%02X: %s, %s\n", unsigned{f.fc},
                  std::string(fdl::to_string(fdl::fc_status(f.fc))).c_str(),
                  std::string(fdl::to_string(fdl::fc_station_type(f.fc))).c_str());
  }
  o += buf;
  o += "DSAP " + (f.dsap ? std::to_string(*f.dsap) : std::string("-")) + ", SSAP " +
       (f.ssap ? std::to_string(*f.ssap) : std::string("-"));
  const std::optional<std::uint8_t> sap = req ? f.dsap : f.ssap;
  std::string service;
  if (!f.mpi.empty()) {
    service = "MPI " + f.mpi;
  } else if (sap) {
    service = std::string(sap_service(*sap));
  } else if (req ? (f.fc != fdl::kFcClockValue && is_srd(f)) : is_data_response(f)) {
    service = "Data_Exchange";
  }
  if (!f.mpi.empty())
    o += " (" + service + ")";
  else if (!service.empty())
    o += " (" + service + (req ? ".req" : ".res") + ")";
  o += "\n";
  std::snprintf(buf, sizeof buf, "%zu octets, %zu data octets", n, f.data_len);
  o += buf;
  return o;
}

std::optional<std::int64_t> parse_time_ns(std::string_view s) {
  std::size_t i = 0;
  i128 whole = 0;
  bool digits = false;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
    whole = whole * 10 + (s[i] - '0');
    if (whole > kMax) return std::nullopt;
    ++i;
    digits = true;
  }
  i128 frac = 0;
  int frac_digits = 0;
  if (i < s.size() && s[i] == '.') {
    ++i;
    bool any = false;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
      if (frac_digits >= 18) return std::nullopt;
      frac = frac * 10 + (s[i] - '0');
      ++frac_digits;
      ++i;
      any = true;
    }
    if (!any) return std::nullopt;
    digits = true;
  }
  if (!digits) return std::nullopt;
  const std::string_view unit = s.substr(i);
  int exp = 0;  // ns per unit = 10^exp
  if (unit == "s")
    exp = 9;
  else if (unit == "ms")
    exp = 6;
  else if (unit == "us" || unit == "\u00b5s")
    exp = 3;
  else if (unit == "ns")
    exp = 0;
  else
    return std::nullopt;
  if (frac_digits > exp) {
    // Finer than 1 ns only if the extra digits are not all zero.
    for (int k = exp; k < frac_digits; ++k) {
      if (frac % 10 != 0) return std::nullopt;
      frac /= 10;
    }
    frac_digits = exp;
  }
  i128 scale = 1;
  for (int k = 0; k < exp; ++k) scale *= 10;
  i128 frac_scale = 1;
  for (int k = 0; k < exp - frac_digits; ++k) frac_scale *= 10;
  const i128 v = whole * scale + frac * frac_scale;
  if (v > kMax) return std::nullopt;
  return static_cast<std::int64_t>(v);
}

std::string format_time_ns(std::int64_t ns) { return names::format_time_ns(ns); }

}  // namespace pbvbus::captures
