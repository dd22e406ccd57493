// The pair's scheduler events (hsby_pair.hpp): the primary's scan with the per-scan transfer
// (seed 003 "per-scan transfer": CPU -> CHS at scan start, CHS -> CHS while the primary solves
// logic), the transfer's completion with the reverse transfer, the standby's transfer watchdog
// (takeover or fibre fault), the planned handover at a scan boundary and the program update's
// end. docs/quantum-hsby-pair.md has the reasons.
#include <algorithm>
#include <string>

#include "pbvbus/quantum/hsby_pair.hpp"

namespace pbvbus::quantum {

namespace {

enum HsbyTag : std::uint64_t { kHsbyScan = 0, kHsbyTransfer = 1, kHsbyWatch = 2, kHsbyUpdate = 3 };

std::uint64_t hsby_tag(HsbyTag kind, int rack, std::uint64_t gen) {
  return (gen << 3) | (static_cast<std::uint64_t>(rack) << 2) | static_cast<std::uint64_t>(kind);
}

}  // namespace

void HsbyPair::arm_scan(int r, bus::Ticks at) {
  Rack& k = rk(r);
  k.next_scan = at;
  m_sched.schedule(at, *this, hsby_tag(kHsbyScan, r, k.scan_gen));
}

void HsbyPair::arm_update(int r) {
  m_sched.schedule(m_sched.now() + m_update_time, *this,
                   hsby_tag(kHsbyUpdate, r, rk(r).update_gen));
}

void HsbyPair::arm_watch(int s) {
  const int p = 1 - s;
  if (rk(s).state != CpuState::Standby || rk(p).state != CpuState::Primary) return;
  Rack& k = rk(s);
  ++k.watch_gen;
  k.rechecking = false;
  // The next transfer is due at the primary's next scan start; the primary's scan event there
  // was scheduled before this one, so at an equal instant the scan (and its transfer) comes
  // first and makes this event stale.
  m_sched.schedule(rk(p).next_scan, *this, hsby_tag(kHsbyWatch, s, k.watch_gen));
}

void HsbyPair::on_event(bus::Ticks now, std::uint64_t tag) {
  const auto kind = static_cast<HsbyTag>(tag & 3);
  const int r = static_cast<int>((tag >> 2) & 1);
  const std::uint64_t gen = tag >> 3;
  switch (kind) {
    case kHsbyScan: {
      if (gen != rk(r).scan_gen || rk(r).state != CpuState::Primary) return;
      // A handover ends a scan: a new primary always runs its first scan (so two units whose
      // command registers disagree cannot hand control back and forth within one instant).
      if (m_handover.active && rk(r).scans_as_primary > 0) {
        const int o = 1 - r;
        if (rk(o).state == CpuState::Standby && wants_offline(r)) {
          handover(r, now);
          return;
        }
        m_handover.active = false;
      }
      scan(r, now);
      return;
    }
    case kHsbyTransfer:
      transfer_done(gen, now);
      return;
    case kHsbyWatch:
      if (gen != rk(r).watch_gen) return;
      watch(r, now);
      return;
    case kHsbyUpdate:
      if (gen != rk(r).update_gen || rk(r).update != UpdatePhase::Running) return;
      update_done(r, now);
      return;
  }
}

void HsbyPair::scan(int r, bus::Ticks now) {
  Rack& p = rk(r);
  const int o = 1 - r;
  ++p.scans;
  ++p.scans_as_primary;
  p.last_scan = now;
  // The command register (override) and every unit's status register at the scan start.
  reconcile();
  // Two primaries meeting again over the fibre: the later one just went offline.
  if (rk(r).state != CpuState::Primary) return;

  // CPU -> CHS: the snapshot of this scan's ranges; it reaches the standby after transfer_time.
  const bool to_standby = rk(o).state == CpuState::Standby && m_fibre == FibreState::Ok;
  if (to_standby) {
    m_flight = InFlight{};
    m_flight.active = true;
    m_flight.gen = ++m_flight_gen;
    m_flight.from = r;
    m_flight.to = o;
    m_flight.scan_start = now;
    const NonTransferArea& nt = m_p.plan.non_transfer;
    auto take = [&](const TransferRange& tr) {
      const std::uint32_t end = std::min(tr.first + tr.count, p.ram.count(tr.type));
      for (std::uint32_t i = tr.first; i < end; ++i) {
        if (tr.type == RefType::Register4x && nt.count > 0 && i >= nt.first &&
            i < nt.first + nt.count)
          continue;  // the non-transfer area (seed p. 94)
        std::uint16_t v = 0;
        switch (tr.type) {
          case RefType::Coil0x:
            v = p.ram.coil(i) ? 1 : 0;
            break;
          case RefType::Input1x:
            v = p.ram.input(i) ? 1 : 0;
            break;
          case RefType::Register3x:
            v = p.ram.input_reg(i);
            break;
          case RefType::Register4x:
            v = p.ram.holding(i);
            break;
        }
        m_flight.values.push_back(TransferValue{tr.type, i, v});
      }
    };
    for (const auto& tr : m_p.plan.every_scan) take(tr);
    const auto& slices = m_p.plan.additional_slices;
    if (!slices.empty()) {
      const std::size_t k = static_cast<std::size_t>((p.scans - 1) % slices.size());
      for (const auto& tr : slices[k]) take(tr);
    }
    rk(o).last_transfer_start = now;
    m_sched.schedule(now + m_transfer_time, *this, hsby_tag(kHsbyTransfer, 0, m_flight.gen));
  }

  // The scan itself: inputs from the remote I/O, the logic, outputs to the remote I/O.
  if (p.head != nullptr) p.head->read_inputs(p.ram);
  if (p.logic) p.logic(p.ram, now);
  if (p.head != nullptr) p.head->write_outputs(p.ram);
  arm_scan(r, now + m_p.scan_time);
  if (to_standby) arm_watch(o);
}

void HsbyPair::transfer_done(std::uint64_t gen, bus::Ticks now) {
  if (!m_flight.active || gen != m_flight.gen) return;  // lost (lose_in_flight) or replaced
  InFlight f = std::move(m_flight);
  m_flight = InFlight{};
  Rack& p = rk(f.from);
  Rack& s = rk(f.to);
  s.updated = true;
  for (const auto& v : f.values) {
    switch (v.type) {
      case RefType::Coil0x:
        s.ram.set_coil(v.index, v.value != 0);
        break;
      case RefType::Input1x:
        s.ram.set_input(v.index, v.value != 0);
        break;
      case RefType::Register3x:
        s.ram.set_input_reg(v.index, v.value);
        break;
      case RefType::Register4x:
        s.ram.set_holding(v.index, v.value);
        break;
    }
  }
  // Reverse transfer: registers 1-2 of the non-transfer area, standby -> primary (seed p. 82).
  const NonTransferArea& nt = m_p.plan.non_transfer;
  if (nt.count >= 2 && nt.first + 1 < p.ram.count(RefType::Register4x)) {
    p.ram.set_holding(nt.first, s.ram.holding(nt.first));
    p.ram.set_holding(nt.first + 1, s.ram.holding(nt.first + 1));
  }
  ++m_transfers_done;
  m_last_done_scan_start = f.scan_start;
  write_status(f.to);  // the standby's own status register at its (logic-free) scan
  (void)now;
}

void HsbyPair::watch(int s, bus::Ticks now) {
  Rack& k = rk(s);
  if (k.state != CpuState::Standby) return;
  const int p = 1 - s;
  // No transfer started at the primary's scan start: the primary failed, or the fibre did.
  // The remote I/O line tells them apart: the active master still heard = the primary lives.
  const bool primary_alive = rk(p).state == CpuState::Primary;
  // The second question asks for a frame STARTED since the first one: a frame already on the
  // wire when the primary failed may end after the first question (docs/quantum-hsby-campaign.md
  // F2: a CPU stop just before the transfer was due was taken for a fibre fault).
  const bool heard = k.head == nullptr ? primary_alive
                     : k.rechecking    ? k.head->heard_since(k.first_check, now)
                                       : k.head->hears_active_master(now);
  if (heard && m_p.line_check_delay > 0 && !k.rechecking) {
    k.first_check = now;
    // The head hears the line within its silence bound: the primary may have failed just
    // before the due instant. Ask again once the bound has passed: still heard = the primary
    // lives (fibre fault); silent = it failed less than 2 bounds ago (takeover then).
    k.rechecking = true;
    m_sched.schedule(now + m_p.line_check_delay, *this, hsby_tag(kHsbyWatch, s, k.watch_gen));
    return;
  }
  k.rechecking = false;
  if (heard) {
    log(s, PairEventKind::Fibre,
        "no transfer from the primary and its I/O head still heard: CHS link failure, the "
        "standby goes offline and the primary runs alone");
    set_state(s, CpuState::Offline, "CHS link failure");
    reconcile();
    return;
  }
  if (!k.updated) {
    // A unit that has just joined holds its state RAM from before its own outage until the
    // first transfer completes: taking control from it would drive the outputs back by every
    // scan it missed. It is not yet ready to assume control (seed p. 19: the standby LED
    // steady = "ready to assume"), so it goes Offline and nobody is primary: the slaves go to
    // their safe state (docs/quantum-hsby-pair.md, "A standby before its first transfer").
    log(s, PairEventKind::Switchover,
        "the primary failed before the first transfer to this standby completed: its state RAM "
        "is from before it joined, it cannot take over and goes offline");
    set_state(s, CpuState::Offline, "not updated since it joined");
    reconcile();
    return;
  }
  SwitchoverRecord rec;
  rec.old_rack = p;
  rec.new_rack = s;
  if (m_failure.active && m_failure.rack == p) {
    rec.cause = m_failure.cause;
    rec.cause_time = m_failure.time;
  } else {
    rec.cause = SwitchoverCause::LinkSilent;
    rec.cause_time = m_fibre != FibreState::Ok ? m_link_fault_time : now;
    if (primary_alive)
      log(-1, PairEventKind::Switchover,
          "no transfer and the line silent while the primary still runs: both units primary");
  }
  rec.time = now;
  become_primary(s, now, &rec);
  reconcile();
}

void HsbyPair::handover(int old_rack, bus::Ticks now) {
  const int n = 1 - old_rack;
  SwitchoverRecord rec;
  rec.old_rack = old_rack;
  rec.new_rack = n;
  rec.cause = m_handover.cause;
  rec.cause_time = m_handover.time;
  rec.time = now;
  m_handover.active = false;
  ++rk(old_rack).scan_gen;
  set_state(old_rack, CpuState::Offline,
            rec.cause == SwitchoverCause::KeyOffLine ? "key Off Line: control handed over"
                                                     : "run bit 0: control handed over");
  become_primary(n, now, &rec);
  reconcile();
}

void HsbyPair::become_primary(int r, bus::Ticks now, const SwitchoverRecord* rec) {
  set_state(r, CpuState::Primary, rec != nullptr ? "takeover" : "no other primary");
  if (rec != nullptr) {
    SwitchoverRecord s = *rec;
    s.takeover_ticks = s.time - s.cause_time;
    s.takeover_scans = static_cast<double>(s.takeover_ticks) / static_cast<double>(m_p.scan_time);
    log(r, PairEventKind::Switchover,
        "switchover rack " + std::to_string(s.old_rack) + " -> rack " + std::to_string(r) + " (" +
            std::string(to_string(s.cause)) + "), takeover " + std::to_string(s.takeover_ticks) +
            " ticks");
    m_switchovers.push_back(s);
  }
  m_failure.active = false;
  m_handover.active = false;
  ++rk(r).scan_gen;
  update_heads();    // the old primary's head leaves Active before the new one enters
  arm_scan(r, now);  // the first scan at once, from the state RAM as last transferred
}

void HsbyPair::update_done(int r, bus::Ticks now) {
  const int p = 1 - r;
  Rack& k = rk(r);
  k.update = UpdatePhase::None;
  // The full program: configuration, I/O map, logic, loadables and all of state RAM (p. 21).
  k.ram = rk(p).ram;
  k.checksum = rk(p).checksum;
  k.logic = rk(p).logic;
  log(r, PairEventKind::Update,
      "program update complete: program and all state RAM copied from rack " + std::to_string(p) +
          "; the unit goes to " + std::string(to_string(k.key)));
  (void)now;
  join_on_own_event(r);
  reconcile();
}

}  // namespace pbvbus::quantum
