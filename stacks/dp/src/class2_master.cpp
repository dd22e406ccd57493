// DP master class 2 (protocol-facts.md §D.7, §E.6); decisions are listed in class2_master.hpp.
#include "pbvbus/dp/class2_master.hpp"
#include "confirmation_kind.hpp"

#include <algorithm>

namespace pbvbus::dp {

using fdl::Confirmation;
using fdl::ResponseStatus;

std::string_view to_string(Class2Service s) {
  switch (s) {
    case Class2Service::GetCfg: return "Get_Cfg";
    case Class2Service::RdInp: return "Rd_Inp";
    case Class2Service::RdOutp: return "Rd_Outp";
    case Class2Service::SlaveDiag: return "Slave_Diag";
    case Class2Service::SetSlaveAdd: return "Set_Slave_Add";
    case Class2Service::C2Initiate: return "MSAC_C2 Initiate";
    case Class2Service::C2Read: return "MSAC_C2 Read";
    case Class2Service::C2Write: return "MSAC_C2 Write";
    case Class2Service::C2Abort: return "MSAC_C2 Abort";
  }
  return "?";
}

namespace {
constexpr std::uint8_t kIdlePdu[] = {kFnIdle, 0x00};
bool is_c2(Class2Service s) {
  return s == Class2Service::C2Initiate || s == Class2Service::C2Read ||
         s == Class2Service::C2Write || s == Class2Service::C2Abort;
}
}  // namespace

Class2Master::Class2Master(Class2Params p) : m_p(p) {}

std::vector<std::uint8_t> Class2Master::initiate_pdu() const {
  return {
      kFnInitiate, 0x00, 0x00, 0x00,  // Function_Num, 3 reserved
      static_cast<std::uint8_t>(m_p.send_timeout >> 8),
      static_cast<std::uint8_t>(m_p.send_timeout & 0xFF),
      0x01, 0x00,                     // Features_Supported_1 (Read/Write), _2
      0x00, 0x00,                     // Profile_Features_Supported_1, _2
      0x00, 0x00,                     // Profile_Ident_Number
      0x00, 0x02, 0x00, 0x02,         // S_Type, S_Len, D_Type, D_Len
      0x00, 0x00,                     // S address data: API, SCL
      0x00, 0x00,                     // D address data: API, SCL
  };
}

std::uint32_t Class2Master::queue(Job j) {
  if (j.slave > 126 || j.slave == m_p.address) return 0;
  if (is_c2(j.service) && j.service != Class2Service::C2Initiate && !c2_open(j.slave) &&
      std::none_of(m_jobs.begin(), m_jobs.end(), [&](const Job& q) {
        return q.slave == j.slave && q.service == Class2Service::C2Initiate;
      }))
    return 0;
  j.id = m_next_id++;
  m_jobs.push_back(std::move(j));
  return m_jobs.back().id;
}

std::uint32_t Class2Master::get_cfg(std::uint8_t slave, Class2Callback cb) {
  return queue({0, Class2Service::GetCfg, slave, kSapGetCfg, kSapMs0, {}, 0, 0, 0, Phase::Request,
                bus::kNever, std::move(cb)});
}
std::uint32_t Class2Master::rd_inp(std::uint8_t slave, Class2Callback cb) {
  return queue({0, Class2Service::RdInp, slave, kSapRdInp, kSapMs0, {}, 0, 0, 0, Phase::Request,
                bus::kNever, std::move(cb)});
}
std::uint32_t Class2Master::rd_outp(std::uint8_t slave, Class2Callback cb) {
  return queue({0, Class2Service::RdOutp, slave, kSapRdOutp, kSapMs0, {}, 0, 0, 0, Phase::Request,
                bus::kNever, std::move(cb)});
}
std::uint32_t Class2Master::slave_diag(std::uint8_t slave, Class2Callback cb) {
  return queue({0, Class2Service::SlaveDiag, slave, kSapSlaveDiag, kSapMs0, {}, 0, 0, 0,
                Phase::Request, bus::kNever, std::move(cb)});
}

std::uint32_t Class2Master::set_slave_add(std::uint8_t slave, std::uint8_t new_address,
                                          std::uint16_t ident, bool no_add_chg, Class2Callback cb,
                                          std::span<const std::uint8_t> rem_slave_data) {
  if (new_address > kMaxSlaveAddress || rem_slave_data.size() > 240) return 0;
  Job j{0, Class2Service::SetSlaveAdd, slave, kSapSetSlaveAdd, kSapMs0, {}, 0, 0, 0,
        Phase::Request, bus::kNever, std::move(cb)};
  j.pdu.resize(4 + rem_slave_data.size());
  j.pdu[0] = new_address;
  j.pdu[1] = static_cast<std::uint8_t>(ident >> 8);
  j.pdu[2] = static_cast<std::uint8_t>(ident & 0xFF);
  j.pdu[3] = no_add_chg ? 1 : 0;
  std::copy(rem_slave_data.begin(), rem_slave_data.end(), j.pdu.begin() + 4);
  return queue(std::move(j));
}

bool Class2Master::c2_open(std::uint8_t slave) const { return m_conns.count(slave) != 0; }

std::uint32_t Class2Master::c2_initiate(std::uint8_t slave, Class2Callback cb) {
  if (c2_open(slave)) return 0;
  for (const auto& j : m_jobs)
    if (j.slave == slave && j.service == Class2Service::C2Initiate) return 0;
  Job j{0, Class2Service::C2Initiate, slave, kSapC2ResourceManager, kSapMs2, initiate_pdu(),
        0, 0, 0, Phase::Request, bus::kNever, std::move(cb)};
  return queue(std::move(j));
}

std::uint32_t Class2Master::c2_read(std::uint8_t slave, std::uint8_t slot, std::uint8_t index,
                                    std::uint8_t length, Class2Callback cb) {
  if (length == 0 || length > kMaxRecordData) return 0;
  Job j{0, Class2Service::C2Read, slave, 0, kSapMs2, {kFnRead, slot, index, length},
        slot, index, length, Phase::Request, bus::kNever, std::move(cb)};
  return queue(std::move(j));
}

std::uint32_t Class2Master::c2_write(std::uint8_t slave, std::uint8_t slot, std::uint8_t index,
                                     std::span<const std::uint8_t> data, Class2Callback cb) {
  if (data.empty() || data.size() > kMaxRecordData) return 0;
  const auto len = static_cast<std::uint8_t>(data.size());
  Job j{0, Class2Service::C2Write, slave, 0, kSapMs2, {}, slot, index, len, Phase::Request,
        bus::kNever, std::move(cb)};
  j.pdu.resize(4 + data.size());
  j.pdu[0] = kFnWrite;
  j.pdu[1] = slot;
  j.pdu[2] = index;
  j.pdu[3] = len;
  std::copy(data.begin(), data.end(), j.pdu.begin() + 4);
  return queue(std::move(j));
}

std::uint32_t Class2Master::c2_abort(std::uint8_t slave, Class2Callback cb) {
  Job j{0, Class2Service::C2Abort, slave, 0, kSapMs2,
        {kFnAbort, kAbortSubnetNone, kAbortInstanceUser, 0x00}, 0, 0, 0, Phase::Request,
        bus::kNever, std::move(cb)};
  return queue(std::move(j));
}

// --- InitiatorUser ----------------------------------------------------------------------------

void Class2Master::on_power_on(bus::Ticks now) {
  m_now = now;
  m_outstanding = m_outstanding_idle = false;
  m_conns.clear();
  while (!m_jobs.empty()) finish_status(AcyclicStatus::Rejected, nullptr);
}

void Class2Master::on_token(bus::Ticks now, bus::Ticks /*trr*/) {
  m_now = now;
  m_polled_this_visit = false;
  // Nothing can be outstanding at a new token; a request the station never confirmed (it left
  // the ring) is simply sent again.
  m_outstanding = m_outstanding_idle = false;
}

bool Class2Master::next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) {
  m_now = now;
  if (prio != fdl::Priority::High || m_outstanding) return false;
  while (!m_jobs.empty()) {
    Job& j = m_jobs.front();
    std::uint8_t dsap = j.dsap;
    std::span<const std::uint8_t> data = j.pdu;
    if (is_c2(j.service) && !(j.service == Class2Service::C2Initiate && j.phase == Phase::Request)) {
      const auto it = m_conns.find(j.slave);
      if (it == m_conns.end()) {
        finish_status(AcyclicStatus::NotAvailable, nullptr);  // connection lost meanwhile
        continue;
      }
      dsap = it->second.sap;
      it->second.last_tx = now;
    }
    if (j.phase == Phase::Poll) {
      if (m_polled_this_visit) return false;
      if (now >= j.deadline) {
        m_conns.erase(j.slave);
        finish_status(AcyclicStatus::Timeout, nullptr);
        continue;
      }
      m_polled_this_visit = true;
      data = kIdlePdu;
    }
    if (is_c2(j.service) && j.deadline == bus::kNever) j.deadline = now + send_timeout_ticks();
    if (j.service == Class2Service::C2Initiate && j.phase == Phase::Request)
      m_conns[j.slave] = Connection{Connection::St::Opening, 0, now};
    out.da = j.slave;
    out.fn = fdl::RequestFn::SrdHigh;
    out.dsap = dsap;
    out.ssap = j.ssap;
    out.data.assign(data.begin(), data.end());
    out.tag = j.id;
    m_outstanding = true;
    return true;
  }
  // Keep-alive for open connections with nothing to do.
  for (auto& [slave, c] : m_conns) {
    if (c.st != Connection::St::Open || now - c.last_tx < send_timeout_ticks() / 2) continue;
    c.last_tx = now;
    out.da = slave;
    out.fn = fdl::RequestFn::SrdHigh;
    out.dsap = c.sap;
    out.ssap = kSapMs2;
    out.data.assign(std::begin(kIdlePdu), std::end(kIdlePdu));
    out.tag = 0;
    m_outstanding = m_outstanding_idle = true;
    m_idle_slave = slave;
    return true;
  }
  return false;
}

void Class2Master::finish(Job& j, Class2Result& r) {
  r.id = j.id;
  r.service = j.service;
  r.slave = j.slave;
  Class2Callback cb = std::move(j.cb);
  m_jobs.pop_front();
  if (cb) cb(r);
}

void Class2Master::finish_status(AcyclicStatus st, const Confirmation* con) {
  Class2Result r;
  r.status = st;
  if (con) {
    r.fdl_status = con->status;
    r.short_ack = con->short_ack;
    r.data.assign(con->data.begin(), con->data.end());
  }
  finish(m_jobs.front(), r);
}

void Class2Master::on_confirmation(const Confirmation& con) {
  m_now = con.now;
  m_outstanding = false;
  if (m_outstanding_idle) {
    m_outstanding_idle = false;
    if (con.result != Confirmation::Result::Ok ||
        (!is_data(con) && !is_empty_ack(con)))
      m_conns.erase(m_idle_slave);  // the slave no longer knows the connection
    return;
  }
  if (m_jobs.empty() || con.tag != m_jobs.front().id) return;
  Job& j = m_jobs.front();
  if (con.result == Confirmation::Result::NoResponse) {
    if (is_c2(j.service)) m_conns.erase(j.slave);
    return finish_status(AcyclicStatus::NoResponse, &con);
  }
  if (con.result != Confirmation::Result::Ok) return finish_status(AcyclicStatus::Rejected, &con);

  Class2Result r;
  r.fdl_status = con.status;
  r.short_ack = con.short_ack;
  r.data.assign(con.data.begin(), con.data.end());
  const bool data = is_data(con);
  const bool empty = is_empty_ack(con);
  auto done = [&](AcyclicStatus st) {
    r.status = st;
    finish(j, r);
  };
  switch (j.service) {
    case Class2Service::GetCfg:
      if (empty) return done(AcyclicStatus::Ok);
      if (!data) return done(AcyclicStatus::NotAvailable);
      if (parse_cfg(con.data, r.cfg, false) != CfgError::None) {
        r.cfg.clear();
        return done(AcyclicStatus::InvalidResponse);
      }
      {
        const CfgTotals t = cfg_totals(r.cfg);
        r.inputs = t.inputs;
        r.outputs = t.outputs;
      }
      return done(AcyclicStatus::Ok);
    case Class2Service::RdInp:
    case Class2Service::RdOutp:
      return done(empty || data ? AcyclicStatus::Ok : AcyclicStatus::NotAvailable);
    case Class2Service::SlaveDiag: {
      if (!data) return done(empty ? AcyclicStatus::InvalidResponse : AcyclicStatus::NotAvailable);
      std::vector<ExtDiagBlock> blocks;
      if (!StandardDiag::decode(con.data, r.diag) ||
          !split_ext_diag(con.data.subspan(kStdDiagLen), blocks))
        return done(AcyclicStatus::InvalidResponse);
      for (const auto& b : blocks) r.diag_blocks.emplace_back(b.bytes.begin(), b.bytes.end());
      return done(AcyclicStatus::Ok);
    }
    case Class2Service::SetSlaveAdd:
      if (empty) return done(AcyclicStatus::Ok);
      return done(data ? AcyclicStatus::InvalidResponse : AcyclicStatus::NotAvailable);
    case Class2Service::C2Initiate: {
      if (!data && !empty) {
        m_conns.erase(j.slave);
        return done(AcyclicStatus::NotAvailable);
      }
      if (j.phase == Phase::Request) {
        // The resource manager's answer: `56 SAP Send_Timeout`.
        if (data && con.data.size() == 4 && con.data[0] == kFnResourceManager &&
            con.data[1] <= kSapC2ConnectionHigh) {
          m_conns[j.slave].sap = con.data[1];
          j.phase = Phase::RmDone;
          return;
        }
        m_conns.erase(j.slave);
        if (data && con.data.size() == 4 && con.data[0] == (kFnInitiate | kFnErrorBit)) {
          r.error = {con.data[1], con.data[2], con.data[3]};
          return done(AcyclicStatus::Negative);
        }
        return done(AcyclicStatus::InvalidResponse);
      }
      if (empty) {
        j.phase = Phase::Poll;
        m_polled_this_visit = true;  // give the slave until the next token visit
        return;
      }
      if (con.data.size() == 4 && con.data[0] == (kFnInitiate | kFnErrorBit)) {
        m_conns.erase(j.slave);
        r.error = {con.data[1], con.data[2], con.data[3]};
        return done(AcyclicStatus::Negative);
      }
      if (con.data.size() < 12 || con.data[0] != kFnInitiate ||
          con.data.size() != 12u + con.data[9] + con.data[11]) {
        m_conns.erase(j.slave);
        return done(AcyclicStatus::InvalidResponse);
      }
      auto& c = m_conns[j.slave];
      c.st = Connection::St::Open;
      r.c2_sap = c.sap;
      r.max_len_data_unit = con.data[1];
      r.features_1 = con.data[2];
      r.features_2 = con.data[3];
      return done(AcyclicStatus::Ok);
    }
    case Class2Service::C2Read:
    case Class2Service::C2Write: {
      if (empty) {
        j.phase = Phase::Poll;
        m_polled_this_visit = true;  // give the slave until the next token visit
        return;
      }
      if (!data) {
        m_conns.erase(j.slave);
        return done(AcyclicStatus::NotAvailable);
      }
      Dpv1Error err;
      switch (match_record_response(con.data, j.pdu[0], j.slot, j.index, j.length, err)) {
        case Dpv1Match::Ok:
          if (j.service == Class2Service::C2Read) r.data.erase(r.data.begin(), r.data.begin() + 4);
          return done(AcyclicStatus::Ok);
        case Dpv1Match::Negative: r.error = err; return done(AcyclicStatus::Negative);
        case Dpv1Match::Invalid: return done(AcyclicStatus::InvalidResponse);
      }
      return;
    }
    case Class2Service::C2Abort:
      m_conns.erase(j.slave);
      return done(data || empty ? AcyclicStatus::Ok : AcyclicStatus::NotAvailable);
  }
}

}  // namespace pbvbus::dp
