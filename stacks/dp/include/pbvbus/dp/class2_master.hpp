#pragma once
// DP master class 2 (IEC 61158-6 DP "DPM2"; protocol-facts.md §D.1, §D.3, §D.4, §D.7, §E.1–§E.3,
// §E.6): a sans-I/O fdl::InitiatorUser for engineering and diagnosis tools. Every service is a
// one-shot request against any station, with a decoded result delivered to a callback:
// Get_Cfg, Rd_Inp, Rd_Outp, Slave_Diag, Set_Slave_Add (DP-V0, from SSAP 62) and MSAC_C2
// Initiate, Read, Write and Abort (from SSAP 50). It never parameterises anyone, so it works
// next to a class-1 master that owns the slaves.
//
// Decisions where the sources are silent (protocol-facts.md marks them [I]/[U]):
// - Requests run one at a time in the order given, as SRD high; at most one poll per token
//   visit. The FDL station does FCB, retries and non-operational marking.
// - One MSAC_C2 connection per slave and class-2 master, addressed by the slave's address.
//   c2_initiate() sends Initiate.req to the resource manager (SAP 49); its `56 SAP
//   Send_Timeout` answer names the connection SAP, to which the same Initiate.req goes next;
//   Initiate.res+ opens the connection. The Initiate.req is 20 octets: `57 00 00 00`,
//   Send_Timeout, Features_Supported_1 = 0x01 (read/write), 0, profile features 0 0, profile
//   ident 0, S_Type 0, S_Len 2, D_Type 0, D_Len 2, address data `00 00` (API 0, SCL 0) twice.
// - A connection answer of SC (or an empty DL) means "not ready": the master polls with the
//   Idle PDU `48 00` (S3's two-octet form) until the answer comes or Send_Timeout has passed
//   (→ Timeout, the connection is then given up). An open connection with nothing to do gets
//   an Idle every Send_Timeout / 2, well inside the slave's 2 × Send_Timeout supervision.
// - Abort sends `58 00 20 00` (no subnet, instance user, reason 0) and forgets the connection
//   whatever the answer. A connection whose request gets NoResponse or RS is closed.
// - RS/UE/RR to any service → NotAvailable (the slave does not offer it in its state, e.g.
//   Rd_Inp outside data exchange, Set_Slave_Add not supported or not allowed).
// - The API is for the bus thread (the CLI injects commands as events at the current time).

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <span>
#include <string_view>
#include <vector>

#include "pbvbus/dp/cfg_identifier.hpp"
#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/dpv1_pdu.hpp"
#include "pbvbus/dp/master_acyclic.hpp"
#include "pbvbus/dp/sap.hpp"
#include "pbvbus/fdl/station.hpp"

namespace pbvbus::dp {

enum class Class2Service : std::uint8_t {
  GetCfg,
  RdInp,
  RdOutp,
  SlaveDiag,
  SetSlaveAdd,
  C2Initiate,
  C2Read,
  C2Write,
  C2Abort,
};
std::string_view to_string(Class2Service s);

struct Class2Result {
  std::uint32_t id = 0;
  Class2Service service = Class2Service::GetCfg;
  std::uint8_t slave = 0;
  AcyclicStatus status = AcyclicStatus::Ok;
  fdl::ResponseStatus fdl_status = fdl::ResponseStatus::OK;  ///< status of the last reply
  bool short_ack = false;
  std::vector<std::uint8_t> data;  ///< response DU: identifiers, inputs, outputs, diagnosis,
                                   ///< record data (Read), or the response PDU (C2)
  Dpv1Error error;                 ///< Negative
  // Get_Cfg
  std::vector<CfgIdentifier> cfg;
  std::size_t inputs = 0;   ///< Get_Cfg: total input / output octets
  std::size_t outputs = 0;
  // Slave_Diag
  StandardDiag diag;
  std::vector<std::vector<std::uint8_t>> diag_blocks;  ///< extended blocks, header included
  // C2 Initiate
  std::uint8_t c2_sap = 0;
  std::uint8_t max_len_data_unit = 0;
  std::uint8_t features_1 = 0;
  std::uint8_t features_2 = 0;
  bool ok() const { return status == AcyclicStatus::Ok; }
};
using Class2Callback = std::function<void(const Class2Result&)>;

struct Class2Params {
  std::uint8_t address = 2;
  std::uint16_t send_timeout = 100;  ///< MSAC_C2 Send_Timeout, 10 ms units (S3: 100 at ≥ 1.5M)
};

class Class2Master final : public fdl::InitiatorUser {
 public:
  explicit Class2Master(Class2Params p = {});
  Class2Master(const Class2Master&) = delete;
  Class2Master& operator=(const Class2Master&) = delete;

  std::uint8_t address() const { return m_p.address; }

  // Each returns an id (> 0), or 0 if the arguments are unusable (address > 126 or our own,
  // record length 0 or > 240, a C2 read/write/abort without an open connection, an initiate
  // on an open one).
  std::uint32_t get_cfg(std::uint8_t slave, Class2Callback cb);
  std::uint32_t rd_inp(std::uint8_t slave, Class2Callback cb);
  std::uint32_t rd_outp(std::uint8_t slave, Class2Callback cb);
  std::uint32_t slave_diag(std::uint8_t slave, Class2Callback cb);
  std::uint32_t set_slave_add(std::uint8_t slave, std::uint8_t new_address, std::uint16_t ident,
                              bool no_add_chg, Class2Callback cb,
                              std::span<const std::uint8_t> rem_slave_data = {});
  std::uint32_t c2_initiate(std::uint8_t slave, Class2Callback cb);
  std::uint32_t c2_read(std::uint8_t slave, std::uint8_t slot, std::uint8_t index,
                        std::uint8_t length, Class2Callback cb);
  std::uint32_t c2_write(std::uint8_t slave, std::uint8_t slot, std::uint8_t index,
                         std::span<const std::uint8_t> data, Class2Callback cb);
  std::uint32_t c2_abort(std::uint8_t slave, Class2Callback cb);

  /// Whether a connection to `slave` is open (or being opened/used by a queued request).
  bool c2_open(std::uint8_t slave) const;
  std::size_t pending() const { return m_jobs.size(); }

  // fdl::InitiatorUser
  void on_power_on(bus::Ticks now) override;
  bool next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) override;
  void on_confirmation(const fdl::Confirmation& con) override;
  void on_token(bus::Ticks now, bus::Ticks trr) override;

  /// The Initiate.req PDU this master sends (documented above).
  std::vector<std::uint8_t> initiate_pdu() const;

 private:
  enum class Phase : std::uint8_t { Request, Poll, RmDone };
  struct Job {
    std::uint32_t id = 0;
    Class2Service service = Class2Service::GetCfg;
    std::uint8_t slave = 0;
    std::uint8_t dsap = 0;
    std::uint8_t ssap = kSapMs0;
    std::vector<std::uint8_t> pdu;
    std::uint8_t slot = 0, index = 0, length = 0;
    Phase phase = Phase::Request;
    bus::Ticks deadline = bus::kNever;
    Class2Callback cb;
  };
  struct Connection {
    enum class St : std::uint8_t { Opening, Open } st = St::Opening;
    std::uint8_t sap = 0;
    bus::Ticks last_tx = 0;
  };

  std::uint32_t queue(Job j);
  void finish(Job& j, Class2Result& r);
  void finish_status(AcyclicStatus st, const fdl::Confirmation* con);
  bus::Ticks send_timeout_ticks() const {
    return static_cast<bus::Ticks>(m_p.send_timeout) * 10 * bus::kTicksPerMs;
  }

  Class2Params m_p;
  std::deque<Job> m_jobs;
  std::map<std::uint8_t, Connection> m_conns;
  std::uint32_t m_next_id = 1;
  bool m_outstanding = false;
  bool m_outstanding_idle = false;   ///< keep-alive Idle to m_idle_slave
  std::uint8_t m_idle_slave = 0;
  bool m_polled_this_visit = false;
  bus::Ticks m_now = 0;
};

}  // namespace pbvbus::dp
