// Configured S7 connections over the CPs of an H-system (F4, R8); the rules are in
// h_connections.hpp and docs/h-system.md "Connections and CPs (F4, R8)".
#include "pbvbus/s7h/h_connections.hpp"

#include <algorithm>

namespace pbvbus::devices {

std::string_view to_string(CpKind k) { return k == CpKind::Cp443_1 ? "CP 443-1" : "CP 443-5"; }

std::string_view to_string(ConnectionKind k) {
  return k == ConnectionKind::Standard ? "standard" : "fault-tolerant";
}

std::string_view to_string(ConnectionState s) {
  switch (s) {
    case ConnectionState::Configured: return "configured";
    case ConnectionState::Established: return "established";
    case ConnectionState::Lost: return "lost";
  }
  return "?";
}

std::string_view to_string(CommEvent::Kind k) {
  switch (k) {
    case CommEvent::Kind::CpFailed: return "CP failed";
    case CommEvent::Kind::CpRepaired: return "CP replaced";
    case CommEvent::Kind::Established: return "established";
    case CommEvent::Kind::Reestablished: return "re-established";
    case CommEvent::Kind::PathSwitched: return "path switched";
    case CommEvent::Kind::PathLost: return "reserve path lost";
    case CommEvent::Kind::PathRegained: return "path regained";
    case CommEvent::Kind::Lost: return "lost";
  }
  return "?";
}

// ---- configuration ------------------------------------------------------------------------

std::string HConnections::add_cp(const CpConfig& cp) {
  if (cp.rack != 0 && cp.rack != 1) return "cp: rack must be 0 or 1";
  if (cp.index < 0) return "cp: index must be >= 0";
  if (cp_slot(cp.rack, cp.index) >= 0)
    return "cp: rack " + std::to_string(cp.rack) + " already has a CP " + std::to_string(cp.index);
  m_cps.push_back(cp);
  m_cp_failed.push_back(false);
  return {};
}

std::string HConnections::add_connection(const ConnectionConfig& c) {
  if (c.name.empty()) return "connection: name is empty";
  if (find(c.name) >= 0) return "connection: duplicate name \"" + c.name + "\"";
  Connection x;
  x.config = c;
  if (c.kind == ConnectionKind::Standard) {
    if (c.rack != 0 && c.rack != 1) return "connection \"" + c.name + "\": rack must be 0 or 1";
    if (cp_slot(c.rack, c.cp) < 0)
      return "connection \"" + c.name + "\": rack " + std::to_string(c.rack) + " has no CP " +
             std::to_string(c.cp);
    x.paths.push_back({c.rack, c.cp, false});
  } else {
    // The CP `cp` on either rack gives the kind; every CP of that kind on both racks is a path.
    int slot = cp_slot(0, c.cp);
    if (slot < 0) slot = cp_slot(1, c.cp);
    if (slot < 0) return "connection \"" + c.name + "\": no CP " + std::to_string(c.cp);
    const CpKind kind = m_cps[static_cast<std::size_t>(slot)].kind;
    std::size_t per_rack[2] = {0, 0};
    for (int r = 0; r < 2; ++r) {
      std::vector<int> idx;
      for (const CpConfig& p : m_cps)
        if (p.rack == r && p.kind == kind) idx.push_back(p.index);
      std::sort(idx.begin(), idx.end());
      per_rack[r] = idx.size();
      for (int i : idx) x.paths.push_back({r, i, false});
    }
    if (per_rack[0] == 0 || per_rack[1] == 0 || per_rack[0] != per_rack[1] || per_rack[0] > 2)
      return "connection \"" + c.name + "\": a fault-tolerant connection needs one or two " +
             std::string(to_string(kind)) + " in each rack, the same number (found " +
             std::to_string(per_rack[0]) + " and " + std::to_string(per_rack[1]) + ")";
  }
  m_conns.push_back(std::move(x));
  return {};
}

int HConnections::cp_slot(int rack, int cp) const {
  for (std::size_t i = 0; i < m_cps.size(); ++i)
    if (m_cps[i].rack == rack && m_cps[i].index == cp) return static_cast<int>(i);
  return -1;
}

bool HConnections::cp_ok(int rack, int cp) const {
  const int s = cp_slot(rack, cp);
  return s >= 0 && !m_cp_failed[static_cast<std::size_t>(s)];
}

int HConnections::find(std::string_view name) const {
  for (std::size_t i = 0; i < m_conns.size(); ++i)
    if (m_conns[i].config.name == name) return static_cast<int>(i);
  return -1;
}

// ---- the rules ----------------------------------------------------------------------------

bool HConnections::carries(const HCpuPair& pair, int r) {
  const CpuState s = pair.state(r);
  if (s == CpuState::Off || s == CpuState::ErrorSearch || s == CpuState::Defective) return false;
  // R8: the standby's connections are broken at link-up and none exist until the update ends.
  if (pair.role(r) == CpuRole::Standby && (s == CpuState::LinkUp || s == CpuState::Update))
    return false;
  return true;
}

bool HConnections::keep(const HCpuPair& pair, const ConnectionPath& p) const {
  return cp_ok(p.rack, p.cp) && carries(pair, p.rack);
}

bool HConnections::can_establish(const HCpuPair& pair, const ConnectionPath& p) const {
  return keep(pair, p) && pair.state(p.rack) == CpuState::Run &&
         pair.accepts_connections(p.rack);
}

std::string HConnections::why_down(const HCpuPair& pair, const ConnectionPath& p) const {
  if (!cp_ok(p.rack, p.cp)) return "CP failed";
  const CpuState s = pair.state(p.rack);
  if (s == CpuState::Off) return "CPU off";
  if (s == CpuState::LinkUp || s == CpuState::Update) return "link-up of the standby (R8)";
  return "CPU " + std::string(to_string(s));
}

std::string HConnections::path_name(const ConnectionPath& p) const {
  const int s = cp_slot(p.rack, p.cp);
  const std::string kind = s >= 0 ? std::string(to_string(m_cps[static_cast<std::size_t>(s)].kind))
                                  : std::string("CP");
  return kind + " rack " + std::to_string(p.rack) + " CP " + std::to_string(p.cp);
}

int HConnections::next_path(const Connection& c, int from) const {
  const ConnectionPath& f = c.paths[static_cast<std::size_t>(from)];
  int best = -1, best_rank = 0;
  for (std::size_t i = 0; i < c.paths.size(); ++i) {
    const ConnectionPath& p = c.paths[i];
    if (static_cast<int>(i) == from || !p.up) continue;
    // Same CPU first (ascending CP index), then the partner's CP with the same index, then the
    // partner's others (ascending); paths are stored by rack and ascending index.
    const int rank = p.rack == f.rack ? 0 : (p.cp == f.cp ? 1 : 2);
    if (best < 0 || rank < best_rank) {
      best = static_cast<int>(i);
      best_rank = rank;
    }
  }
  return best;
}

bool HConnections::establish(std::size_t i, const HCpuPair& pair, bus::Ticks now,
                             CommEvent::Kind kind) {
  Connection& c = m_conns[i];
  bool any = false;
  for (ConnectionPath& p : c.paths)
    if (!p.up && can_establish(pair, p)) p.up = any = true;
  if (!any) return false;
  c.active = -1;
  if (c.config.kind == ConnectionKind::FaultTolerant) {
    // The first active path: the master's CP `cp`, else in switch order from it.
    const int m = pair.master() >= 0 ? pair.master() : 0;
    int pref = -1;
    for (std::size_t k = 0; k < c.paths.size(); ++k)
      if (c.paths[k].rack == m && c.paths[k].cp == c.config.cp) pref = static_cast<int>(k);
    if (pref < 0) pref = 0;
    c.active = c.paths[static_cast<std::size_t>(pref)].up ? pref : next_path(c, pref);
  } else {
    c.active = 0;
  }
  c.state = ConnectionState::Established;
  c.lost_at = bus::kNever;
  const ConnectionPath& a = c.paths[static_cast<std::size_t>(c.active)];
  emit({now, kind, static_cast<int>(i), a.rack, a.cp, -1, -1,
        "connection " + c.config.name + " " + std::string(to_string(kind)) + " over " +
            path_name(a)});
  return true;
}

void HConnections::update_one(std::size_t i, const HCpuPair& pair, bus::Ticks now) {
  Connection& c = m_conns[i];
  const int ci = static_cast<int>(i);
  if (c.state == ConnectionState::Configured) {
    establish(i, pair, now, CommEvent::Kind::Established);
    return;
  }
  if (c.state == ConnectionState::Lost) return;  // only reestablish() brings it back
  // Paths that went down; the reserves first, the active one decides below.
  std::string active_why;
  for (std::size_t k = 0; k < c.paths.size(); ++k) {
    ConnectionPath& p = c.paths[k];
    if (!p.up || keep(pair, p)) continue;
    p.up = false;
    if (static_cast<int>(k) == c.active) {
      active_why = why_down(pair, p);
      continue;
    }
    emit({now, CommEvent::Kind::PathLost, ci, p.rack, p.cp, -1, -1,
          "connection " + c.config.name + ": reserve path " + path_name(p) + " lost (" +
              why_down(pair, p) + ")"});
  }
  // Paths back as reserves (fault-tolerant only: a standard connection's one path is the
  // connection, handled by the loss below and reestablish()).
  if (c.config.kind == ConnectionKind::FaultTolerant)
    for (std::size_t k = 0; k < c.paths.size(); ++k) {
      ConnectionPath& p = c.paths[k];
      if (p.up || !can_establish(pair, p)) continue;
      if (static_cast<int>(k) == c.active && !active_why.empty()) continue;
      p.up = true;
      emit({now, CommEvent::Kind::PathRegained, ci, p.rack, p.cp, -1, -1,
            "connection " + c.config.name + ": path " + path_name(p) + " back as a reserve"});
    }
  if (active_why.empty()) return;
  const ConnectionPath from = c.paths[static_cast<std::size_t>(c.active)];
  const int to = c.config.kind == ConnectionKind::FaultTolerant ? next_path(c, c.active) : -1;
  if (to >= 0) {
    c.active = to;
    const ConnectionPath& t = c.paths[static_cast<std::size_t>(to)];
    emit({now, CommEvent::Kind::PathSwitched, ci, from.rack, from.cp, t.rack, t.cp,
          "connection " + c.config.name + ": active path " + path_name(from) + " down (" +
              active_why + "), continues over " + path_name(t)});
    return;
  }
  c.state = ConnectionState::Lost;
  c.active = -1;
  c.lost_at = now;
  for (ConnectionPath& p : c.paths) p.up = false;
  emit({now, CommEvent::Kind::Lost, ci, from.rack, from.cp, -1, -1,
        "connection " + c.config.name + " lost: " + path_name(from) + " down (" + active_why +
            ")" + (c.config.kind == ConnectionKind::FaultTolerant ? ", no path left" : "")});
}

void HConnections::update(const HCpuPair& pair, bus::Ticks now) {
  for (std::size_t i = 0; i < m_conns.size(); ++i) update_one(i, pair, now);
}

bool HConnections::fail_cp(int rack, int cp, const HCpuPair& pair, bus::Ticks now) {
  const int s = cp_slot(rack, cp);
  if (s < 0 || m_cp_failed[static_cast<std::size_t>(s)]) return false;
  m_cp_failed[static_cast<std::size_t>(s)] = true;
  emit({now, CommEvent::Kind::CpFailed, -1, rack, cp, -1, -1,
        std::string(to_string(m_cps[static_cast<std::size_t>(s)].kind)) + " rack " +
            std::to_string(rack) + " CP " + std::to_string(cp) + " failed (F4)"});
  update(pair, now);
  return true;
}

bool HConnections::repair_cp(int rack, int cp, const HCpuPair& pair, bus::Ticks now) {
  const int s = cp_slot(rack, cp);
  if (s < 0 || !m_cp_failed[static_cast<std::size_t>(s)]) return false;
  m_cp_failed[static_cast<std::size_t>(s)] = false;
  emit({now, CommEvent::Kind::CpRepaired, -1, rack, cp, -1, -1,
        std::string(to_string(m_cps[static_cast<std::size_t>(s)].kind)) + " rack " +
            std::to_string(rack) + " CP " + std::to_string(cp) + " replaced"});
  update(pair, now);
  return true;
}

bool HConnections::reestablish(std::size_t i, const HCpuPair& pair, bus::Ticks now) {
  if (i >= m_conns.size() || m_conns[i].state != ConnectionState::Lost) return false;
  return establish(i, pair, now, CommEvent::Kind::Reestablished);
}

}  // namespace pbvbus::devices
