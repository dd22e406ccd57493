"""The PG's side of one MPI connection: connect, Setup Communication, Read Var, disconnect.

The station's user (fdl_station.ActiveStation): it hands out the next MPI PDU to send while the
station holds the token (next_request), learns each one's FDL outcome (on_result) and takes the
PDUs the CPU sends to it as SRD requests (on_indication: True = SC, False = RS).

Sequence (protocol-facts.md §H.3, docs/mpi.md):
  1. E0 + 11 connect parameters to the CPU's SAP 0, from the PG's SAP (default 0x14)
  2. the CPU's D0 confirm (a request to us); its SSAP is the CPU's SAP from now on
  3. 05 01 to the CPU; 4. the CPU's 05 01
  5. F1 nr + Setup Communication (PDU 240); the CPU's B0 01 nr and its F1 answer (any order),
     which the PG acknowledges with B0 01 <its nr> in its own SRD frame
  6. F1 nr + Read Var DBn.DBB<start> x len, as many as the negotiated PDU size needs
  7. 80 (disconnect); done when the CPU's FDL has taken it (SC)
Stop and wait: one data message outstanding (docs/mpi.md decision 6). Message numbers per
sender from 0, after 255 comes 1. A data message the CPU repeats (the same number again: our ack
was lost) is acknowledged again and not taken twice.
"""

from collections import deque

import fdl_frames as F
import mpi_pdus as M
import s7_pdus as S
from fdl_station import Request

FDL_STATUS_NAMES = {F.ST_UE: "UE user error", F.ST_RR: "RR no resources",
                    F.ST_RS: "RS SAP not activated"}


class PgSession:
    def __init__(self, cpu, db, start, length, clock, pg_sap=M.DEFAULT_PG_SAP,
                 pdu_size=S.PG_PDU_SIZE, step_timeout=10.0, disconnect=True, log=None):
        self.cpu, self.db, self.start, self.length = cpu, db, start, length
        self.clock, self.pg_sap, self.asked_pdu = clock, pg_sap, pdu_size
        self.step_timeout, self.want_disconnect = step_timeout, disconnect
        self.log = log or (lambda msg: None)
        self.out = deque()
        self.cpu_sap = None
        self.state = "connect"
        self.connected = False
        self.disconnected = False
        self.pdu_size = None
        self.data = bytearray()
        self.error = None
        self.done = False
        self.tx_nr = 0               # our next message number
        self.outstanding = None      # our data message awaiting its B0 ack
        self.last_acked = None
        self.rx_last = None          # the CPU's last message number taken
        self.answer = None           # the CPU's answer to the job in progress
        self.job = None              # ("setup"|"read", ref, offset, n)
        self.ref = 0
        self.count = {"data_sent": 0, "data_received": 0, "acks_sent": 0, "acks_received": 0,
                      "repeats_received": 0, "ignored_pdus": 0, "reads": 0}
        self.deadline = float("inf")  # the first token: only --max-time bounds the wait
        self.waiting_for = "the first token (a GAP poll and the token from a master)"
        self.queue(M.connect_request(), dsap=M.CONNECT_SAP, tag="connect")

    # --- helpers ------------------------------------------------------------------------------

    def queue(self, du, dsap=None, tag="data", front=False):
        req = Request(self.cpu, self.cpu_sap if dsap is None else dsap, self.pg_sap, du, tag)
        (self.out.appendleft if front else self.out.append)(req)

    def wait(self, what):
        self.waiting_for = what
        self.deadline = self.clock() + self.step_timeout

    def fail(self, why):
        if self.error is None:
            self.error = why
            self.log("error: " + why)
        if self.connected and self.want_disconnect and self.state != "disconnecting" \
                and self.cpu_sap is not None and self.state != "broken":
            self.begin_disconnect()
        else:
            self.done = True

    def finished(self):
        return self.done

    def check(self, now):
        """Called from the main loop: the step in progress must not wait forever."""
        if not self.done and now > self.deadline:
            # Connected: the disconnect is queued and gets a step of its own; a disconnect that
            # is not taken in time ends the session.
            self.fail("no progress within %.1f s: waiting for %s" % (self.step_timeout,
                                                                     self.waiting_for))

    # --- the S7 jobs --------------------------------------------------------------------------

    def send_job(self, s7_pdu):
        self.queue(M.data(self.tx_nr, s7_pdu))
        self.outstanding = self.tx_nr
        self.tx_nr = M.next_message_number(self.tx_nr)
        self.answer = None
        self.count["data_sent"] += 1

    def next_ref(self):
        self.ref = self.ref % 0xFFFF + 1
        return self.ref

    def start_setup(self):
        ref = self.next_ref()
        self.job = ("setup", ref, 0, 0)
        self.state = "setup"
        self.send_job(S.setup_request(ref, self.asked_pdu))
        self.wait("the answer to Setup Communication")

    def start_read(self, offset):
        n = min(self.length - offset, S.max_read_length(self.pdu_size))
        ref = self.next_ref()
        self.job = ("read", ref, offset, n)
        self.state = "read"
        self.count["reads"] += 1
        self.send_job(S.read_db_bytes_request(ref, self.db, self.start + offset, n))
        self.wait("the answer to Read Var DB%d.DBB%d x %d" % (self.db, self.start + offset, n))

    def begin_disconnect(self):
        self.state = "disconnecting"
        self.queue(M.disconnect(), tag="disconnect")
        self.wait("the disconnect to be taken")

    def job_complete(self):
        """Our data message is acknowledged and its answer is in."""
        kind, ref, offset, n = self.job
        pdu, self.answer, self.job = self.answer, None, None
        try:
            if kind == "setup":
                cpu_pdu = S.parse_setup_answer(pdu, ref)
                self.pdu_size = min(self.asked_pdu, cpu_pdu)
                self.log("PDU size %d (CPU %d)" % (self.pdu_size, cpu_pdu))
                if S.max_read_length(self.pdu_size) < 1:
                    raise S.S7Error("negotiated PDU size %d is too small" % self.pdu_size)
                if self.length > 0:
                    return self.start_read(0)
            else:
                self.data += S.parse_read_answer(pdu, ref, n)
                if offset + n < self.length:
                    return self.start_read(offset + n)
        except S.S7Error as e:
            return self.fail("%s: %s" % ("Setup Communication" if kind == "setup" else
                                         "Read Var DB%d.DBB%d x %d" % (self.db, self.start + offset,
                                                                       n), e))
        if self.want_disconnect:
            self.begin_disconnect()
        else:
            self.done = True

    # --- the station's user -------------------------------------------------------------------

    def next_request(self):
        return self.out.popleft() if self.out and not self.done else None

    def on_result(self, req, result, reply):
        if result == "delivered":
            if req.tag == "connect":
                self.state = "await_confirm"
                self.wait("the connect confirm (D0) from CPU %d" % self.cpu)
            elif req.tag == "disconnect":
                self.disconnected = True
                self.done = True
            return
        self.state = "broken"
        if result == "refused":
            what = FDL_STATUS_NAMES.get(reply.status, "status 0x%X" % reply.status)
            if req.tag == "connect":
                return self.fail("CPU %d refused the connection: %s" % (self.cpu, what))
            return self.fail("CPU %d refused a frame of the connection: %s" % (self.cpu, what))
        self.fail("CPU %d does not answer at FDL level (retries exhausted)" % self.cpu)

    def on_indication(self, sa, dsap, ssap, du):
        if sa != self.cpu or dsap != self.pg_sap:
            return False
        pdu = M.decode(du)
        kind = pdu[0]
        if kind == "connect_confirm":
            if self.state != "await_confirm":
                self.count["ignored_pdus"] += 1
                return True
            self.cpu_sap = ssap
            self.state = "await_conn_ack"
            self.queue(M.connection_ack(), tag="conn_ack")
            self.wait("the connection ack (05 01) from CPU %d" % self.cpu)
            return True
        if ssap != self.cpu_sap:
            return False
        if kind == "conn_ack":
            if self.state == "await_conn_ack":
                self.connected = True
                self.log("connected: PG SAP 0x%02X, CPU SAP 0x%02X" % (self.pg_sap, self.cpu_sap))
                self.start_setup()
            else:
                self.count["ignored_pdus"] += 1
            return True
        if kind == "data_ack":
            nr = pdu[1]
            if nr == self.outstanding:
                self.count["acks_received"] += 1
                self.last_acked, self.outstanding = nr, None
                if self.answer is not None and self.job is not None:
                    self.job_complete()
            elif nr != self.last_acked:
                self.count["ignored_pdus"] += 1
            return True
        if kind == "data":
            nr, s7 = pdu[1], pdu[2]
            self.queue(M.data_ack(nr), tag="ack", front=True)
            self.count["acks_sent"] += 1
            if nr == self.rx_last:
                self.count["repeats_received"] += 1
                return True
            self.rx_last = nr
            self.count["data_received"] += 1
            if self.job is None or self.answer is not None:
                self.count["ignored_pdus"] += 1
                return True
            self.answer = s7
            if self.outstanding is None:
                self.job_complete()
            return True
        if kind == "disconnect":
            self.connected = False
            self.state = "broken"
            self.fail("CPU %d closed the connection (80)" % self.cpu)
            self.done = True
            return True
        self.count["ignored_pdus"] += 1
        return True
