#pragma once
// One ISO-on-TCP connection, sans-I/O (docs/iso-on-tcp.md): the octets a client sends go in
// (any chunking, byte by byte included), the octets for the client come out through `send`,
// and `finish` says when and why the transport must close. The TCP door (iso_door.hpp) is this
// plus a socket; the fuzz target drives it directly.
//
// What it does, in order (RFC 1006 TPKT, ISO 8073 class 0 COTP, S7 PDUs of protocol-facts §H.4):
//  1. TPKTs are reassembled (stacks/s7 TpktReassembler), each up to the class 0 maximum
//     (2048 + 4), whatever TPDU size the CC confirmed (what the door sends keeps to it).
//  2. The first TPDU must be a CR with both TSAPs. It goes to the S7Router: a refusal is answered
//     with a DR carrying the router's reason; a channel is confirmed with a CC that echoes the
//     CR's parameters (so libnodave's 22-octet check passes, tools-and-formats §3.2), the TPDU
//     size lowered to max_tpdu_code.
//  3. DTs are joined until EOT into one S7 PDU (at most max_pdu octets). A Job or Userdata goes
//     to the channel; at most AmQ (the max AmQ called of the Setup Communication answer, 1 before
//     it) are outstanding, the rest wait in order, at most max_queued_jobs; one more and the
//     session finishes (QueueFull).
//  4. An answer goes back in as many DTs as the TPDU size needs (EOT on the last).
//  5. A DR from the client is answered with a DC, then the session finishes. The channel
//     closing (its connection broke) sends a DR, reason 0 (not specified), then finishes.
//  6. Anything else finishes the session: TPKT framing lost (no resynchronisation is possible),
//     a TPDU that does not decode or is not allowed in this state (answered with an ER first, as
//     ISO 8073 §13.12 has it, when a CC has gone out or the TPDU was a broken CR), an S7 PDU that
//     is no Job or Userdata.
// After finish the session takes no more input; answers still owed are dropped.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/iso_on_tcp/pdu_capture.hpp"
#include "pbvbus/iso_on_tcp/s7_router.hpp"
#include "pbvbus/s7/cotp_connect.hpp"
#include "pbvbus/s7/tpkt.hpp"

namespace pbvbus::iso_on_tcp {

struct SessionLimits {
  /// Jobs waiting beyond the negotiated AmQ; one more closes the connection.
  std::size_t max_queued_jobs = 256;
  /// Largest S7 PDU accepted from the client (DT segments joined): the largest PDU length any
  /// S7 CPU negotiates is 960; the bound leaves room and stops a client that never sends EOT.
  std::size_t max_pdu = 8192;
  /// Largest TPDU size confirmed (2^code): class 0's maximum, 2048.
  std::uint8_t max_tpdu_code = s7::kTpduSizeClass0MaxCode;
};

/// Why a session ended.
enum class SessionEnd : std::uint8_t {
  ClientDisconnect,  ///< DR from the client, DC sent
  Refused,           ///< the router refused the CR, DR sent
  ChannelClosed,     ///< the route broke, DR sent
  Garbage,           ///< framing, TPDU or S7 PDU not acceptable (ER sent where it can be)
  QueueFull,         ///< more pipelined jobs than AmQ + max_queued_jobs
  NoAnswer,          ///< the channel answered a job with nothing (not an S7 job)
};

const char* to_string(SessionEnd e);

class IsoSession {
 public:
  struct Hooks {
    /// Octets for the client (whole TPKTs).
    std::function<void(std::span<const std::uint8_t>)> send;
    /// Close the transport once what was sent is out. Called once; `why` is a log line's text.
    std::function<void(SessionEnd, const std::string& why)> finish;
    PduCapture capture;  ///< optional
  };

  /// `own_ref` = the door's COTP source reference for this connection (non-zero).
  IsoSession(S7Router& router, const SessionLimits& limits, Hooks hooks,
             std::uint64_t connection_id, std::uint16_t own_ref);
  ~IsoSession();
  IsoSession(const IsoSession&) = delete;
  IsoSession& operator=(const IsoSession&) = delete;

  /// Client octets, in any chunks.
  void feed(std::span<const std::uint8_t> in);

  bool finished() const { return finished_; }
  bool connected() const { return channel_ != nullptr; }
  /// The AmQ in force (max AmQ called of the Setup Communication answer; 1 before it).
  std::size_t amq() const { return amq_; }
  std::size_t in_flight() const { return in_flight_; }
  std::size_t queued() const { return queue_.size(); }
  std::uint64_t jobs() const { return jobs_; }
  std::uint64_t answers() const { return answers_; }
  /// Most jobs that ever waited in the queue at once.
  std::size_t queued_max() const { return queued_max_; }

 private:
  void on_tpdu(std::span<const std::uint8_t> tpdu);
  void on_connect_request(std::span<const std::uint8_t> tpdu);
  void on_data(std::span<const std::uint8_t> tpdu);
  void on_job(std::vector<std::uint8_t> pdu);
  void dispatch(std::vector<std::uint8_t> pdu);
  void drain();
  void on_answer(std::vector<std::uint8_t> answer);
  void on_channel_closed(const std::string& reason);
  void send_tpdu(const std::vector<std::uint8_t>& tpdu);
  void send_error(std::uint8_t cause, std::span<const std::uint8_t> tpdu);
  void capture(PduDirection d, std::span<const std::uint8_t> pdu);
  void end(SessionEnd e, const std::string& why);

  S7Router& router_;
  SessionLimits limits_;
  Hooks hooks_;
  std::uint64_t id_;
  std::uint16_t own_ref_;
  std::uint16_t peer_ref_ = 0;
  std::vector<std::uint8_t> calling_tsap_;
  std::vector<std::uint8_t> called_tsap_;
  std::size_t tpdu_size_ = 128;  ///< ISO 8073: 128 when the CR names none
  s7::TpktReassembler reasm_;
  std::unique_ptr<S7Channel> channel_;
  std::vector<std::uint8_t> tsdu_;  ///< DT user data until EOT
  std::deque<std::vector<std::uint8_t>> queue_;
  std::size_t amq_ = 1;
  std::size_t in_flight_ = 0;
  std::size_t queued_max_ = 0;
  bool draining_ = false;
  bool finished_ = false;
  std::uint64_t jobs_ = 0;
  std::uint64_t answers_ = 0;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace pbvbus::iso_on_tcp
