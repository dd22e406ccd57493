#pragma once
// The model behind `pbvbus timeline CAPTURE` (README.md "A picture of the bus"): a capture read
// into lanes of frames with their times on the wire, who held the token when, the DP cycle of
// every slave, the events, and (docs/redundancy.md) the active channel of every switched station.
// and (docs/h-system.md) the states, roles and OBs of the CPUs of an H system. timeline_render.hpp
// draws it as HTML or SVG.
//
// Decisions:
//  - One lane per interface with link type USER0 (147) or PROFIBUS_DL (257), in interface
//    order, whether or not it has frames: a line, or one probe of a line when a capture has
//    several interfaces on one line. The model draws what the file holds; it does not merge or
//    split lanes. Interfaces of other link types except the events interface (USER1, 148) are
//    counted in `skipped_interfaces` and otherwise ignored.
//  - A frame lasts from its timestamp (the start bit of its first character) for 11 bit times
//    per octet captured at the interface's if_speed: end_ns = start_ns +
//    floor(octets * 11 * 10^9 / if_speed), in integer arithmetic. Without if_speed (or with an
//    absurd one above 10^12 bit/s) a frame has no length (end_ns = start_ns) and nothing is
//    given in bit times.
//  - Frames of a lane are sorted by start time (stable: file order for equal starts). The file
//    is in order of frame ends, and during a cut or a collision frames on one interface overlap.
//  - Kind: Bad if epb_flags has a link-layer error bit (collision, CRC, partial, ...) or the FDL
//    codec rejects the octets (also an intact frame that breaks an FDL rule); otherwise Token
//    (SD4), SC (0xE5), or Request / Response by the FC octet's request bit (0x40).
//  - idle_ns / idle_bits: from the end of the previous frame of the lane (in start order) to this
//    frame's start; negative when the frames overlap. Bit times round to the nearest whole bit
//    (ns timestamps are rounded down, a bit time at 1.5 Mbit/s is 666.67 ns).
//  - Token holder: every Token frame hands the token to its DA, who holds it from the end of
//    that frame to the start of the next Token frame of the lane (the last one to the end of the
//    lane's last frame). A token that was not taken up (a retried pass) still makes a span: the
//    model shows what the wire says, not what the stations believed.
//  - DP cycle: a Data_Exchange request is an SRD (high or low) without a DSAP (the default SAP;
//    as in inspect.hpp and the Lua dissector). Its answer is the first later frame of the lane
//    (start order) that starts at least 10 bit times after the request's end (TSDR >= 11,
//    less one for ns rounding) and is a Response from the request's DA to its SA, or an SC
//    with no other station's request in between; unless the requester sends again first (a
//    retry, its next request or its token pass). Frames of other stations in between are
//    passed over because during a cable cut one interface carries both halves of the line (an
//    SC of the other half can still be taken for the answer: SC carries no addresses). The
//    search stops after 32 frames or 65536 bit times (more than the longest slot time). A slave address gets a row if it answered a
//    Data_Exchange at least once in the capture; its polls are all the Data_Exchange requests
//    to it, answered or not, and a poll's cycle time is the time since
//    the previous Data_Exchange request to the same address on that lane (from start to start,
//    whoever sent it; a retry after a missing answer therefore shows as a short cycle).
//  - Events: every record of every USER1 interface, decoded with decode_event(); records that
//    do not decode are counted in `bad_event_records`. Line events that inject a fault (cable cut,
//    short circuit, noise on, power off, transceiver failure, babbling on) are faults; their
//    opposites are repairs; everything else is a plain event.
//  - Active channel of a switched station (docs/redundancy.md): from the Redundancy event records
//    (category 4; code = redundancy::SystemEvent::Kind, a = station address, line = the line's
//    index, Line::index()). A station gets a row if it has at least one switchover record
//    (code 6, "station a's active channel is now line `line`", also at start-up); stations
//    without one (one-sided slaves, the master system with a = -1) get none. Its row starts at
//    the station's first Redundancy record of any kind, with no active channel until the first
//    switchover; a station failure (code 2) means no active channel until the next switchover;
//    other codes change nothing. The last span lasts to last_ns (the end of the capture).
//    A pbvbus run writes a start-up switchover record when the system first sees a station's
//    primary (redundancy::MasterSystem), so a row starts within the first DP cycles.
//    Consecutive spans of the same line are one span; a span that another record at the same
//    instant replaces (zero length, not the last) is dropped. A line index names a lane as a
//    Line event does: the Line event records (category 1) of that line index start their text
//    with the line's name ("DP_A: power on"), and the line's lane is the first lane named NAME
//    or NAME@...; for a line index without a Line event, the lanes are grouped by the name
//    before '@' in interface order (pbvbus declares each line's interfaces together, in line
//    index order) and the Nth group's first lane is line N's. A line index with no such lane
//    keeps its index with line_lane = -1. Worked out on the whole capture like the token spans.
//  - CPU rows of an H system (docs/h-system.md): from
//    the Cpu event records (category 5, cpu_event.hpp). A CPU gets a row if it has at least one
//    State record (kind 0); a row is (system, rack): `system` is the name before ": CPU <rack>:"
//    in the record's text (pbvbus writes "H-CPU: CPU 0: STOP -> STARTUP"; "" when the text does
//    not start that way), so that two simulated pairs' rack 0 are two rows. The row starts at
//    the CPU's first State record: a State record sets (state = "to", role = b, the role after
//    the event), a Role record (kind 1) sets role = "to" and keeps the state; Role records
//    before the first State record are passed over (that State record carries the role).
//    System-mode records (kind 2) change no span: RUN in Solo or in Redundant mode is one state
//    (the report's table has the mode column). A span is a (state, role) period, with the same
//    rules as the active channels: consecutive records with the same (state, role) make one
//    span, a span that another record at the same instant replaces (zero length, not the last)
//    is dropped, and the last span lasts to last_ns. Numbers outside the known enums are kept
//    as they are (cpu_state_name() says "state 12").
//  - OB marks: every Cpu record of kind Ob (3) of a CPU that has a row, at its time, with the OB
//    number, event ID and reason from the value and the record's text; a record for both CPUs
//    (a = -1, "CPU 0+1: ...") gives one mark on each row of its system. OB records of CPUs
//    without a row are not marked (they are still events). By system, rack, then time.
//  - MPI connections (captures/README.md "MPI and S7"): per lane, the frames that are MPI by
//    the dissector's rule (an intact SD2/SD3 SRD request with DSAP and SSAP whose DU is a whole
//    MPI PDU, mpi::decode(); a connect request only to DSAP 0; on a lane whose if_description
//    does not start with "MPI" only when neither SAP is a DP SAP 49..63). A connection is
//    (initiator address, SAP, responder address, SAP): a connect request from (a, s) to b waits
//    for the confirm from (b, r) to (a, s), which names the row (a, s, b, r); every other PDU
//    between (a, s) and (b, r), either way, belongs to it. A PDU of no known connection opens a
//    row with its sender as initiator (setup_seen false). Spans: connecting from the connect
//    request (the confirm when the request is not in the capture) to the responder's
//    connection ack, connected from then (or from the first data message or data ack) to a
//    disconnect request of either side; the last span lasts to the lane's last frame end.
//    A new connect request of the same row ends its current span; a span never starts before
//    the end of the row's previous one (a confirm whose request came before PDUs of the old
//    connection starts its span after them), and a span that ends where it starts is dropped
//    when the next one opens. Connect requests that no
//    confirm answers give a row with responder SAP -1, marks only. Every MPI PDU is a mark,
//    repeats by the FDL layer included (the wire's view). Rows are worked out on the whole
//    capture and cut to the window like the DX rows; every row is kept, also without spans or
//    marks in the window.
//  - Quantum Hot Standby rows (docs/quantum-hsby.md "Captures and timeline"): from the Hsby
//    event records (category 7, hsby_event.hpp). A rack gets a row if it has at least one record
//    with a >= 0 and b >= 0 (every such record carries the rack's state after the event, whatever
//    its kind); a row is (pair, rack), the pair being the name before ": rack <rack>: " in the
//    text (hsby_pair_name(); pbvbus writes "Q: rack 0: offline -> primary (power on)"). The row
//    starts at the rack's first such record; each sets state = b; spans merge and drop as the CPU
//    rows' do, and the last lasts to last_ns. Records of the pair or the fibre (a = -1) make no
//    span. Switchover marks: every record of kind switchover (3) of a rack with a row, on that
//    rack's row (the new primary's; "two primaries meet again" names the unit that goes
//    offline), with the takeover time from the value (0: none given). By pair, rack, then time.
//  - Window [from_ns, to_ns): frames, token spans, active-channel spans and CPU state spans that
//    overlap it, polls, events and OB marks that start in it. Without a window: from the earliest record to 1 ns
//    after the end of the latest frame or event (so that what happens last is inside; to_ns
//    saturates at the int64 limit, and a window ending there includes it). Token spans, active
//    channels, CPU states and cycle times are worked out on the whole capture first, so a window does not
//    change them; the per-slave summary covers the polls in the window. Times are the capture's own (virtual time since the start
//    of the run for pbvbus captures).
//  - Errors: anything the reader rejects (not pcapng, truncated or malformed block) fails the
//    whole build with the reader's message and offset: a partial picture of a broken file would
//    look complete. So do an empty file, a capture without records, a capture without a line
//    interface, and a window whose start is not before its end. Nothing here throws or reads
//    outside a buffer on bad input.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/captures/event_record.hpp"
#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::captures {

enum class FrameKind : std::uint8_t { Token, Request, Response, Sc, Bad };
/// "token", "request", "response", "SC", "bad"
std::string_view to_string(FrameKind k);

struct TimelineFrame {
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
  FrameKind kind = FrameKind::Bad;
  std::vector<std::uint8_t> bytes;
  std::uint32_t flags = 0;  ///< epb_flags
  std::string comment;      ///< opt_comment
  /// Decoded by the FDL codec (then the fields below are valid; a frame with error flags may
  /// still decode).
  bool decoded = false;
  fdl::FrameType type = fdl::FrameType::SC;
  std::uint8_t da = 0;
  std::uint8_t sa = 0;
  std::uint8_t fc = 0;
  std::optional<std::uint8_t> dsap;
  std::optional<std::uint8_t> ssap;
  std::size_t data_len = 0;  ///< DU octets after the extension octets
  /// The frame's MPI PDU in words ("data 0", "connect request") when it is MPI by the rule of
  /// "MPI connections" below; "" otherwise.
  std::string mpi;
  /// Why the frame is bad ("" if it is not): the writer's comment, else the epb_flags error
  /// bits in words, plus the decoder's reason.
  std::string problem;
  std::optional<std::int64_t> idle_ns;    ///< since the end of the previous frame of the lane
  std::optional<std::int64_t> idle_bits;  ///< idle_ns in bit times (needs if_speed)
};

struct TokenSpan {
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
  std::uint8_t holder = 0;     ///< DA of the token frame
  std::uint8_t passed_by = 0;  ///< SA of the token frame
};

struct DxPoll {
  std::int64_t start_ns = 0;   ///< start of the Data_Exchange request
  std::uint8_t master = 0;     ///< its SA
  bool answered = false;
  std::optional<std::int64_t> cycle_ns;  ///< since the previous Data_Exchange request to the slave
};

struct CycleStats {
  std::uint64_t count = 0;  ///< polls in the window with a cycle time
  std::int64_t min_ns = 0;
  std::int64_t median_ns = 0;  ///< lower median
  std::int64_t max_ns = 0;
};

struct SlaveCycles {
  std::uint8_t address = 0;
  std::vector<DxPoll> polls;  ///< in the window, in time order
  std::uint64_t unanswered = 0;  ///< polls in the window without an answer
  CycleStats cycle;
};

/// What an MPI connection was doing in a span (captures/README.md "MPI and S7").
enum class MpiState : std::uint8_t { Connecting, Connected };
std::string_view to_string(MpiState s);  ///< "connecting", "connected"

struct MpiSpan {
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
  MpiState state = MpiState::Connecting;
};

/// One MPI PDU of a connection on the wire, drawn as a mark on the connection's row.
struct MpiMark {
  std::int64_t ts_ns = 0;            ///< start of the frame
  std::uint8_t pdu = 0;              ///< first octet: E0, D0, 05, F1, B0, 80 (mpi/pdu.hpp)
  bool from_initiator = true;        ///< sent by the side that sent the connect request
  std::optional<std::uint8_t> nr;    ///< data: its message number; data ack: the number acked
  std::string text;                  ///< "data 0 0:20→2:20: S7 job Read Var, 1 item"
};

/// One MPI connection seen on a lane: (initiator address, SAP) ↔ (responder address, SAP).
struct MpiConnection {
  std::uint8_t initiator = 0;      ///< the PG/OP: sender of the connect request
  std::uint8_t initiator_sap = 0;
  std::uint8_t responder = 0;      ///< the CPU
  int responder_sap = -1;          ///< the CPU's connection SAP; -1: no confirm seen
  /// False when the capture shows the connection only from a later PDU on (it started before
  /// the capture): then the initiator is a guess, the sender of the first PDU seen.
  bool setup_seen = false;
  std::vector<MpiSpan> spans;  ///< in the window, by start time
  std::vector<MpiMark> marks;  ///< in the window, by time
  std::uint64_t data_messages = 0;  ///< in the window
  std::uint64_t data_acks = 0;      ///< in the window
};
/// "0:20↔2:20" (responder SAP "?" when unknown).
std::string mpi_connection_label(const MpiConnection& c);

struct TimelineLane {
  std::uint32_t interface = 0;  ///< pcapng interface index
  std::string name;             ///< if_name
  std::string description;      ///< if_description
  std::uint16_t link_type = 0;
  std::uint64_t speed = 0;  ///< if_speed in bit/s; 0 = unknown (also for absurd values)
  std::vector<TimelineFrame> frames;  ///< in the window, by start time
  std::vector<TokenSpan> token;       ///< in the window, by start time
  std::vector<SlaveCycles> slaves;    ///< by address
  std::uint64_t bad_frames = 0;       ///< in the window
  /// Whether the interface is marked MPI (if_description starts with "MPI").
  bool mpi_marked = false;
  /// MPI connections (captures/README.md "MPI and S7"), by initiator, its SAP, responder, SAP.
  std::vector<MpiConnection> mpi;
};

enum class EventStyle : std::uint8_t { Fault, Repair, Event };
std::string_view to_string(EventStyle s);  ///< "fault", "repair", "event"

struct TimelineEvent {
  std::int64_t ts_ns = 0;
  std::uint32_t interface = 0;
  EventRecord record;
  EventStyle style = EventStyle::Event;
};

/// A time in which a switched station's active channel was one line (or none).
struct ActiveChannelSpan {
  int station = 0;     ///< the station's address
  int line = -1;       ///< line index (Line::index()) of the active channel; -1 = none
  int line_lane = -1;  ///< index into Timeline::lanes of that line; -1 = none, or no lane
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
};

/// A time in which one CPU of an H system was in one state with one role (numbers as in
/// cpu_event.hpp: state devices::CpuState, role devices::CpuRole).
struct CpuStateSpan {
  std::string system;  ///< the H system's name from the record texts ("" if none)
  int rack = 0;
  int state = 0;  ///< 0 OFF, 1 STOP, 2 STARTUP, 3 RUN, 4 LINK-UP, ... (cpu_state_name())
  int role = 0;   ///< 0 none, 1 master, 2 standby (cpu_role_name())
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
};

/// An OB that ran on a CPU (a Cpu record of kind Ob), drawn as a tick on the CPU's row.
struct CpuObMark {
  std::string system;
  int rack = 0;
  std::int64_t ts_ns = 0;
  int ob = 0;                 ///< OB number (72, 121, 85, ...)
  std::uint16_t event_id = 0;  ///< W#16#.... (0 = none given)
  int reason = 0;             ///< devices::HReason (0 none)
  std::string text;           ///< the record's text
};

/// A time in which one rack of a Quantum Hot Standby pair was in one state (hsby_event.hpp:
/// 0 off, 1 offline, 2 primary, 3 standby; hsby_state_name()).
struct HsbyStateSpan {
  std::string pair;  ///< the pair's name from the record texts ("" if none)
  int rack = 0;
  int state = 0;
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
};

/// A switchover of a Quantum pair, drawn as a marker on the rack's row.
struct HsbySwitchoverMark {
  std::string pair;
  int rack = 0;  ///< the new primary
  std::int64_t ts_ns = 0;
  std::uint64_t takeover_ns = 0;  ///< from the failure or request to the first scan; 0 = none given
  std::string text;               ///< the record's text
};

struct Timeline {
  std::int64_t from_ns = 0;  ///< the window
  std::int64_t to_ns = 0;
  std::int64_t first_ns = 0;  ///< the whole capture: earliest record
  std::int64_t last_ns = 0;   ///< end of the latest frame, or the latest event
  std::vector<TimelineLane> lanes;
  std::vector<TimelineEvent> events;  ///< in the window, by time
  /// In the window, by station, then by start time (one row per switched station).
  std::vector<ActiveChannelSpan> active_channels;
  /// In the window, by system, rack, then start time (one row per CPU with a State record).
  std::vector<CpuStateSpan> cpu_states;
  /// In the window, by system, rack, then time.
  std::vector<CpuObMark> cpu_obs;
  /// Quantum Hot Standby rows: in the window, by pair, rack, then start time.
  std::vector<HsbyStateSpan> hsby_states;
  /// In the window, by pair, rack, then time.
  std::vector<HsbySwitchoverMark> hsby_switchovers;
  std::uint64_t records = 0;
  std::uint64_t bad_event_records = 0;
  std::uint64_t skipped_interfaces = 0;
};

struct TimelineOptions {
  std::optional<std::int64_t> from_ns;
  std::optional<std::int64_t> to_ns;
};

/// Reads everything `reader` still has. nullopt with a one-line reason in `error` on failure.
std::optional<Timeline> build_timeline(PcapngReader& reader, const TimelineOptions& opts,
                                       std::string& error);
/// The same from a buffer (a copy is taken) or a file.
std::optional<Timeline> build_timeline(std::span<const std::uint8_t> data,
                                       const TimelineOptions& opts, std::string& error);
std::optional<Timeline> read_timeline_file(const std::string& path, const TimelineOptions& opts,
                                           std::string& error);

/// Duration `ns` in bit times at `speed` bit/s, rounded to the nearest (halves away from zero).
/// nullopt without a speed.
std::optional<std::int64_t> ns_to_bits(std::int64_t ns, std::uint64_t speed);

/// Length of `octets` characters on the wire in ns (rounded down); 0 without a speed.
std::int64_t frame_duration_ns(std::size_t octets, std::uint64_t speed);

/// Several lines of text describing a frame: frame type and direction, addresses, FC in words,
/// SAPs and DP service, lengths, and for a bad frame why. No hex dump.
std::string describe(const TimelineFrame& f);

/// Parses "2s", "1500ms", "250us" (or "250µs"), "100ns", "1.25s" into ns, exactly. nullopt for
/// anything else: no number, no or an unknown unit, a sign, more than 9 decimals of a second,
/// overflow.
std::optional<std::int64_t> parse_time_ns(std::string_view s);

/// "2.000000000 s" style, for messages.
std::string format_time_ns(std::int64_t ns);

}  // namespace pbvbus::captures
