"""Unit tests of the outside PG (run: /usr/bin/python3 -m unittest discover -s THIS_FOLDER).

Golden bytes are the trace frames of protocol-facts.md §H.3 and Appendix 1 and the frames of
docs/mpi.md, or worked out by hand here (FCS = sum of DA..last DU octet mod 256, the sums
written out in the comments); none is produced by the code under test. A fake line plays the CPU
(MPI address 2) and the token partner with its own little frame builder, so a whole ring entry,
connect, Setup Communication, Read Var and disconnect run in memory, on fake time.
"""

import io
import json
import os
import struct
import sys
import threading
import unittest
from collections import deque
from contextlib import redirect_stderr, redirect_stdout

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import fdl_frames as F  # noqa: E402
import mpi_pdus as M  # noqa: E402
import outside_pg  # noqa: E402
import s7_pdus as S  # noqa: E402
from fdl_station import ActiveStation, Request  # noqa: E402
from pg_session import PgSession  # noqa: E402


def h(s):
    return bytes.fromhex(s)


# --- hand-worked frames (PG 0, CPU 2, both SAPs 0x14 unless said) --------------------------

CONNECT_REQUEST = h("68 11 11 68 82 80 6D 00 14 E0 04 00 80 00 02 00 02 01 00 01 00 ED 16")  # §H.3
CONNECT_CONFIRM = h("68 11 11 68 80 82 6C 14 14 D0 04 00 80 00 02 00 02 01 00 01 00 F0 16")  # §H.3
CONN_ACK_PG = h("68 07 07 68 82 80 5D 14 14 05 01 8D 16")    # docs/mpi.md step 3
CONN_ACK_PLC = h("68 07 07 68 80 82 5C 14 14 05 01 8C 16")   # docs/mpi.md step 4
READ_DATA_0 = h("68 1F 1F 68 82 80 7D 14 14 F1 00 32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02"
                " 00 0A 00 01 84 00 00 00 9C 16")               # docs/mpi.md step 5 (§H.4 read)
DATA_ACK_PLC_0 = h("68 08 08 68 80 82 7C 14 14 B0 01 00 57 16")  # docs/mpi.md step 6
DISCONNECT = h("68 06 06 68 82 80 5D 14 14 80 07 16")          # docs/mpi.md step 7
# PG -> PLC ack of the PLC's message 0, FC 5D: 82+80+5D+14+14+B0+01+00 = 0x238 -> 38
DATA_ACK_PG_0 = h("68 08 08 68 82 80 5D 14 14 B0 01 00 38 16")
# Setup Communication, ref 1, PDU 240, as data message 0 with FC 7D:
# 82+80+7D+14+14+F1+00 = 0x298; 32+01+01+08+F0+01+01+F0 = 0x21E; 0x298+0x21E = 0x4B6 -> B6
SETUP_JOB = h("32 01 00 00 00 01 00 08 00 00 F0 00 00 01 00 01 00 F0")
SETUP_DATA_0 = h("68 19 19 68 82 80 7D 14 14 F1 00") + SETUP_JOB + h("B6 16")
GAP_POLL_TO_PG = h("10 00 02 49 4B 16")       # 00+02+49 = 4B (as §H.2's 10 05 02 49 50 16)
READY_REPLY = h("10 02 00 20 22 16")          # 02+00+20 = 22: "ready to enter the ring"
POLL_1 = h("10 01 00 49 4A 16")               # 01+00+49 = 4A
TOKEN_TO_PG = h("DC 00 02")
TOKEN_TO_CPU = h("DC 02 00")
RS_IN_RING = h("10 02 00 33 35 16")           # 02+00+33 = 35: RS, station in the ring
RR_FROM_CPU = h("10 00 02 32 34 16")          # 00+02+32 = 34: RR no resources, CPU in ring


class FcsAndFrames(unittest.TestCase):
    def test_fcs_of_published_traces(self):
        self.assertEqual(F.fcs(h("05 02 49")), 0x50)  # §H.2 10 05 02 49 50 16
        self.assertEqual(F.fcs(CONNECT_REQUEST[4:-2]), 0xED)
        self.assertEqual(F.fcs(CONNECT_CONFIRM[4:-2]), 0xF0)

    def test_connect_request_frame_is_the_trace(self):
        self.assertEqual(F.encode(2, 0, 0x6D, 0x00, 0x14, M.connect_request()), CONNECT_REQUEST)

    def test_connection_ack_data_ack_disconnect(self):
        self.assertEqual(F.encode(2, 0, 0x5D, 0x14, 0x14, M.connection_ack()), CONN_ACK_PG)
        self.assertEqual(F.encode(0, 2, 0x5C, 0x14, 0x14, M.connection_ack()), CONN_ACK_PLC)
        self.assertEqual(F.encode(0, 2, 0x7C, 0x14, 0x14, M.data_ack(0)), DATA_ACK_PLC_0)
        self.assertEqual(F.encode(2, 0, 0x5D, 0x14, 0x14, M.data_ack(0)), DATA_ACK_PG_0)
        self.assertEqual(F.encode(2, 0, 0x5D, 0x14, 0x14, M.disconnect()), DISCONNECT)

    def test_read_var_data_message(self):
        pdu = S.read_db_bytes_request(1, 1, 0, 10)
        self.assertEqual(pdu, h("32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 0A 00 01 84 00"
                                " 00 00"))  # §H.4 example
        self.assertEqual(F.encode(2, 0, 0x7D, 0x14, 0x14, M.data(0, pdu)), READ_DATA_0)

    def test_setup_job(self):
        self.assertEqual(S.setup_request(1), SETUP_JOB)
        self.assertEqual(F.encode(2, 0, 0x7D, 0x14, 0x14, M.data(0, SETUP_JOB)), SETUP_DATA_0)

    def test_read_of_db7_dbb300(self):
        # 12 0A 10 02 | len 0004 | DB 0007 | 84 | 300*8 = 2400 = 0x000960
        self.assertEqual(S.read_db_bytes_request(0x1234, 7, 300, 4),
                         h("32 01 00 00 12 34 00 0E 00 00 04 01 12 0A 10 02 00 04 00 07 84 00 09"
                           " 60"))

    def test_tokens_and_fdl_status(self):
        self.assertEqual(F.encode_token(2, 0), TOKEN_TO_CPU)
        self.assertEqual(F.encode_token(5, 2), h("DC 05 02"))  # Appendix 1
        self.assertEqual(F.encode(0, 2, 0x49), GAP_POLL_TO_PG)
        self.assertEqual(F.encode(2, 0, 0x20), READY_REPLY)
        self.assertEqual(F.encode(1, 5, 0x30), h("10 01 05 30 36 16"))  # Appendix 1

    def test_sd3_when_du_with_saps_is_8(self):
        # F1 nr + a 4-octet PDU + 2 SAPs = 8 -> SD3: 82+80+7D+14+14+F1+00 = 0x298,
        # AA+BB+CC+DD = 0x30E, 0x298 + 0x30E = 0x5A6 -> A6
        self.assertEqual(F.encode(2, 0, 0x7D, 0x14, 0x14, h("F1 00 AA BB CC DD")),
                         h("A2 82 80 7D 14 14 F1 00 AA BB CC DD A6 16"))

    def test_decode_connect_confirm(self):
        t = F.decode(CONNECT_CONFIRM)
        self.assertEqual((t.kind, t.da, t.sa, t.fc, t.dsap, t.ssap), ("SD2", 0, 2, 0x6C, 0x14, 0x14))
        self.assertTrue(t.is_request)
        self.assertEqual(M.decode(t.data), ("connect_confirm", M.TRACE_CONNECT_PARAMS))

    def test_decode_rejects_bad_fcs_and_lengths(self):
        bad = bytearray(CONNECT_CONFIRM)
        bad[-2] ^= 1
        self.assertIsNone(F.decode(bytes(bad)))
        self.assertIsNone(F.decode(h("68 07 06 68 82 80 5D 14 14 05 01 8D 16")))
        self.assertIsNone(F.decode(CONN_ACK_PG[:-1]))
        t = F.decode(h("E5"))
        self.assertTrue(t.is_response)
        self.assertEqual(t.status, F.ST_OK)

    def test_deframer_resynchronises(self):
        d = F.Deframer()
        d.feed(h("00 FF 16") + TOKEN_TO_PG + CONN_ACK_PLC[:5])
        self.assertEqual(d.next(), TOKEN_TO_PG)
        self.assertIsNone(d.next())
        d.feed(CONN_ACK_PLC[5:] + h("E5"))
        self.assertEqual(d.next(), CONN_ACK_PLC)
        self.assertEqual(d.next(), h("E5"))
        self.assertEqual(d.garbage, 3)

    def test_mpi_decode_and_numbers(self):
        self.assertEqual(M.decode(h("05 01")), ("conn_ack",))
        self.assertEqual(M.decode(h("B0 01 07")), ("data_ack", 7))
        self.assertEqual(M.decode(h("F1 09 32 03")), ("data", 9, h("32 03")))
        self.assertEqual(M.decode(h("80")), ("disconnect",))
        self.assertIsNone(M.decode(h("B0 02 07"))[0])
        self.assertIsNone(M.decode(h("E0 04"))[0])
        self.assertEqual([M.next_message_number(n) for n in (0, 1, 254, 255)], [1, 2, 255, 1])

    def test_s7_answers(self):
        setup_answer = h("32 03 00 00 00 01 00 08 00 00 00 00 F0 00 00 01 00 01 00 F0")
        self.assertEqual(S.parse_setup_answer(setup_answer, 1), 240)
        # §H.4 example answer: FF 04 00 50 (80 bits) + 10 bytes
        read_answer = h("32 03 00 00 00 01 00 02 00 0E 00 00 04 01 FF 04 00 50") + bytes(range(10))
        self.assertEqual(S.parse_read_answer(read_answer, 1, 10), bytes(range(10)))
        missing = h("32 03 00 00 00 02 00 02 00 04 00 00 04 01 0A 00 00 00")
        with self.assertRaisesRegex(S.S7Error, "0x0A .object does not exist"):
            S.parse_read_answer(missing, 2, 10)
        with self.assertRaisesRegex(S.S7Error, "reference"):
            S.parse_setup_answer(setup_answer, 2)
        with self.assertRaisesRegex(S.S7Error, "error class 0x85"):
            S.parse_setup_answer(h("32 03 00 00 00 01 00 00 00 00 85 00"), 1)
        self.assertEqual(S.max_read_length(240), 222)


# --- a fake line with a CPU on it ---------------------------------------------------------------

def frame(da, sa, fc, du=b""):
    """The fake CPU's own frame builder (independent of fdl_frames)."""
    body = bytes([da, sa, fc]) + du
    s = sum(body) & 0xFF
    if not du:
        return b"\x10" + body + bytes([s, 0x16])
    if len(du) == 8:
        return b"\xA2" + body + bytes([s, 0x16])
    return bytes([0x68, len(body), len(body), 0x68]) + body + bytes([s, 0x16])


class FakeCpu:
    """CPU at MPI address 2 and the PG's token partner, reacting to each frame of the PG at once.

    It polls the PG, passes it the token, answers its SRD frames with E5, and when it holds the
    token sends its own MPI PDUs (connect confirm, connection ack, data acks, S7 answers) as SRD
    low frames with FCB (first 6C, then 5C/7C), one per PG E5, then passes the token back."""

    def __init__(self, sap=0x14, pdu_size=240, dbs=None, refuse_connect=False,
                 drop_first=(), repeat_answer=False, ignore_tokens=0, per_visit=2, silent=False,
                 token_before_e5=()):
        self.sap, self.pdu_size = sap, pdu_size
        self.dbs = {1: bytes(range(10))} if dbs is None else dbs
        self.refuse_connect, self.drop_first = refuse_connect, set(drop_first)
        self.repeat_answer, self.ignore_tokens, self.per_visit = repeat_answer, ignore_tokens, per_visit
        self.line = None
        self.pg_fcs = []          # FC octets of the PG's SRD frames, as received (retries too)
        self.pg_pdus = []         # MPI PDUs taken (repeats not)
        self.pg_last_fcb = None
        self.outgoing = deque()
        self.fcb = None           # our FCB toward the PG
        self.awaiting = None      # our frame awaiting the PG's reply
        self.sent_this_visit = 0
        self.nr = 0
        self.last_rx_nr = None
        self.pg_replies = []
        self.disconnected = False
        self.tokens_seen = 0
        self.polls_seen = []
        self.silent = silent
        self.token_before_e5 = set(token_before_e5)
        self.admitted = False

    def start(self):
        if not self.silent:
            self.line.to_pg.append(GAP_POLL_TO_PG)

    def queue_pdu(self, du):
        self.outgoing.append(du)

    def s7_answer(self, job):
        ref = job[4:6]
        fn = job[10]
        if fn == 0xF0:
            param = h("F0 00 00 01 00 01") + struct.pack(">H", self.pdu_size)
            return h("32 03 00 00") + ref + h("00 08 00 00 00 00") + param
        assert fn == 0x04, job.hex()
        length, db = struct.unpack(">HH", job[16:20])
        start = int.from_bytes(job[21:24], "big") // 8
        data = self.dbs.get(db)
        if data is None:
            item = h("0A 00 00 00")
        else:
            item = h("FF 04") + struct.pack(">H", length * 8) + data[start:start + length]
        return h("32 03 00 00") + ref + h("00 02") + struct.pack(">H", len(item)) + h("00 00 04 01") + item

    def take_pdu(self, du):
        self.pg_pdus.append(du)
        if du[0] == 0xE0:
            self.queue_pdu(b"\xD0" + du[1:])
        elif du == h("05 01"):
            self.queue_pdu(h("05 01"))
        elif du[0] == 0xF1:
            self.queue_pdu(h("B0 01") + du[1:2])
            self.queue_pdu(h("F1") + bytes([self.nr]) + self.s7_answer(du[2:]))
            self.nr = 1 if self.nr == 255 else self.nr + 1
        elif du[0] == 0xB0:
            pass
        elif du == h("80"):
            self.disconnected = True

    def send_next(self):
        if self.outgoing and self.sent_this_visit < self.per_visit:
            du = self.outgoing.popleft()
            if self.fcb is None:
                fc, self.fcb = 0x6C, True
            else:
                self.fcb = not self.fcb
                fc = 0x7C if self.fcb else 0x5C
            # DSAP = the PG's SAP 0x14, SSAP = ours (the connect confirm comes from our SAP)
            f = frame(0x80, 0x82, fc, bytes([0x14, self.sap]) + du)
            self.awaiting = f
            self.sent_this_visit += 1
            self.line.to_pg.append(f)
            if self.repeat_answer and du[0] == 0xF1 and du[2:4] == h("32 03"):
                self.repeat_answer = False
                self.line.to_pg.append(f)  # as if our E5 was lost: the same frame again
                self.awaiting = ("repeat", f)
        else:
            self.awaiting = None
            self.line.to_pg.append(TOKEN_TO_PG)

    def on_pg_frame(self, f):
        if f[0] == 0xDC:
            self.tokens_seen += 1
            if f != TOKEN_TO_CPU:
                return
            if self.ignore_tokens:
                self.ignore_tokens -= 1
                return
            self.sent_this_visit = 0
            self.send_next()
            return
        if f == READY_REPLY:
            self.pg_replies.append(f)
            self.admitted = True
            self.line.to_pg.append(TOKEN_TO_PG)
            return
        if f == h("E5") or (f[0] == 0x10 and f[3] & 0x40 == 0 and f[1] == 0x02):
            self.pg_replies.append(f)
            if isinstance(self.awaiting, tuple):
                self.awaiting = self.awaiting[1]  # the repeat's reply comes next
                return
            if self.awaiting is not None:
                self.send_next()
            return
        if f[0] == 0x10 and f[3] == 0x49:
            self.polls_seen.append(f[1])
            return
        assert f[0] in (0x68, 0xA2), f.hex()
        body = f[4:-2] if f[0] == 0x68 else f[1:-2]
        assert sum(body) & 0xFF == f[-2] and f[-1] == 0x16, f.hex()
        da, sa, fc, dsap, ssap, du = body[0], body[1], body[2], body[3], body[4], body[5:]
        assert (da, sa) == (0x82, 0x80), f.hex()
        self.pg_fcs.append(fc)
        key = du[:1].hex()
        if key in self.drop_first:
            self.drop_first.discard(key)
            return  # lost on the way: no reply
        repeat = fc & 0x10 and self.pg_last_fcb == bool(fc & 0x20)
        self.pg_last_fcb = bool(fc & 0x20)
        if du[0] == 0xE0 and self.refuse_connect:
            self.line.to_pg.append(RR_FROM_CPU)
            return
        if key in self.token_before_e5:
            # Our token retry was already on its way (the PG answered our token too late for
            # us): the PG hears DC 00 02 while it awaits the reply to its request.
            self.token_before_e5.discard(key)
            self.line.to_pg.append(TOKEN_TO_PG)
        self.line.to_pg.append(h("E5"))
        if not repeat:
            assert dsap == (0x00 if du[0] == 0xE0 else self.sap), f.hex()
            self.take_pdu(du)


class FakeLine:
    """The in-memory link: fake time advances 1 ms per frame and jumps to a read's deadline."""

    def __init__(self, cpu):
        self.t = 100.0
        self.to_pg = deque()
        self.sent = []
        self.cpu = cpu
        cpu.line = self
        cpu.start()

    def now(self):
        return self.t

    def send(self, f):
        self.sent.append(bytes(f))
        self.t += 0.001
        self.cpu.on_pg_frame(bytes(f))

    def read(self, deadline):
        if self.to_pg:
            self.t += 0.001
            return self.to_pg.popleft()
        self.t = max(self.t, deadline)
        return None


def run_pg(cpu, *args):
    line = FakeLine(cpu)
    a = outside_pg.options(["--port", "fake", "--timeout", "0.05", "--token-timeout", "0.05",
                            "--max-time", "30"] +
                           list(args))
    rc, summary = outside_pg.run(line, a, lambda msg: None)
    return rc, summary, line


class WholeExchange(unittest.TestCase):
    def test_connect_setup_read_disconnect(self):
        cpu = FakeCpu()
        rc, s, line = run_pg(cpu)
        self.assertEqual(rc, 0, s)
        self.assertTrue(s["ok"])
        self.assertTrue(s["connected"])
        self.assertTrue(s["disconnected"])
        self.assertEqual(s["pdu_size"], 240)
        self.assertEqual(s["bytes_read"], 10)
        self.assertEqual(s["data"], "00 01 02 03 04 05 06 07 08 09")
        self.assertEqual(s["cpu_sap"], 0x14)
        self.assertEqual((s["ps"], s["ns"]), (2, 2))
        self.assertEqual(s["retries"], 0)
        self.assertEqual(s["error"], None)
        self.assertTrue(cpu.disconnected)
        # The PG's frames, in order, as the fake line saw them.
        self.assertEqual(line.sent[0], READY_REPLY)
        self.assertEqual(line.sent[1], CONNECT_REQUEST)  # the §H.3 trace frame
        self.assertEqual(line.sent[2], POLL_1)          # GAP scan: address 1, no answer
        self.assertEqual(line.sent[3], TOKEN_TO_CPU)
        self.assertEqual(line.sent[4], h("E5"))          # for the connect confirm
        self.assertIn(CONN_ACK_PG, line.sent)
        self.assertIn(SETUP_DATA_0, line.sent)
        self.assertIn(DATA_ACK_PG_0, line.sent[line.sent.index(SETUP_DATA_0):])
        self.assertEqual(line.sent[-1], TOKEN_TO_CPU)    # the token goes on before the exit
        # The MPI PDUs the CPU took: connect, ack, setup, ack 0, read, ack 1, disconnect.
        kinds = [p[:1].hex() for p in cpu.pg_pdus]
        self.assertEqual(kinds, ["e0", "05", "f1", "b0", "f1", "b0", "80"])
        self.assertEqual(cpu.pg_pdus[3], h("B0 01 00"))
        self.assertEqual(cpu.pg_pdus[5], h("B0 01 01"))
        self.assertEqual(cpu.pg_pdus[4][:2], h("F1 01"))
        self.assertEqual(cpu.pg_pdus[4][2:], S.read_db_bytes_request(2, 1, 0, 10))

    def test_fcb_toggles_per_responder(self):
        cpu = FakeCpu()
        rc, s, _ = run_pg(cpu)
        self.assertEqual(rc, 0, s)
        # First frame FCV=0 FCB=1 (6D), then FCV=1 with FCB toggled: 5D 7D 5D ...
        expect = [0x6D] + [0x5D if i % 2 == 0 else 0x7D for i in range(len(cpu.pg_fcs) - 1)]
        self.assertEqual(cpu.pg_fcs, expect)
        self.assertEqual(len(cpu.pg_fcs), 7)

    def test_retry_repeats_the_frame_unchanged(self):
        cpu = FakeCpu(drop_first={"05"})
        rc, s, line = run_pg(cpu)
        self.assertEqual(rc, 0, s)
        self.assertEqual(s["retries"], 1)
        self.assertEqual(line.sent.count(CONN_ACK_PG), 2)
        self.assertEqual(cpu.pg_fcs[:3], [0x6D, 0x5D, 0x5D])

    def test_a_repeated_frame_gets_the_stored_reply_and_is_taken_once(self):
        cpu = FakeCpu(repeat_answer=True)
        rc, s, _ = run_pg(cpu)
        self.assertEqual(rc, 0, s)
        self.assertEqual(s["repeats_answered"], 1)
        self.assertEqual(s["data_received"], 2)  # setup answer and read answer, once each
        self.assertEqual(s["repeats_received"], 0)

    def test_request_cut_by_a_lost_token_goes_again_with_the_same_fcb(self):
        cpu = FakeCpu(token_before_e5={"05"})
        rc, s, line = run_pg(cpu)
        self.assertEqual(rc, 0, s)
        self.assertEqual(s["token_losses"], 1)
        # 05 01 went twice with FCB 0 (5D): the CPU saw a repeat, not a new frame, and took it
        # once; the next new frame toggles (7D).
        self.assertEqual(cpu.pg_fcs[:4], [0x6D, 0x5D, 0x5D, 0x7D])
        self.assertEqual(line.sent.count(CONN_ACK_PG), 2)
        self.assertEqual([p[:1].hex() for p in cpu.pg_pdus], ["e0", "05", "f1", "b0", "f1", "b0", "80"])

    def test_cpu_sap_is_taken_from_the_confirm(self):
        cpu = FakeCpu(sap=0x15)
        rc, s, line = run_pg(cpu)
        self.assertEqual(rc, 0, s)
        self.assertEqual(s["cpu_sap"], 0x15)
        # 05 01 to DSAP 15 from 14: 82+80+5D+15+14+05+01 = 0x18E -> 8E
        self.assertIn(h("68 07 07 68 82 80 5D 15 14 05 01 8E 16"), line.sent)

    def test_long_read_is_split_by_the_pdu_size(self):
        cpu = FakeCpu(pdu_size=120, dbs={3: bytes(i & 0xFF for i in range(400))})
        rc, s, _ = run_pg(cpu, "--db", "3", "--start", "5", "--length", "250")
        self.assertEqual(rc, 0, s)
        self.assertEqual(s["pdu_size"], 120)
        self.assertEqual(s["reads"], 3)  # 102 + 102 + 46
        self.assertEqual(bytes.fromhex(s["data"]), bytes(i & 0xFF for i in range(5, 255)))

    def test_missing_db_is_an_error_and_still_disconnects(self):
        cpu = FakeCpu(dbs={})
        rc, s, _ = run_pg(cpu, "--db", "9")
        self.assertEqual(rc, 1)
        self.assertIn("Read Var DB9.DBB0 x 10", s["error"])
        self.assertIn("object does not exist", s["error"])
        self.assertTrue(s["disconnected"])
        self.assertTrue(cpu.disconnected)

    def test_refused_connection(self):
        cpu = FakeCpu(refuse_connect=True)
        rc, s, _ = run_pg(cpu)
        self.assertEqual(rc, 1)
        self.assertEqual(s["error"], "CPU 2 refused the connection: RR no resources")
        self.assertFalse(s["connected"])

    def test_token_pass_retried(self):
        cpu = FakeCpu(ignore_tokens=1)
        rc, s, line = run_pg(cpu)
        self.assertEqual(rc, 0, s)
        self.assertEqual(s["token_pass_retries"], 1)
        self.assertEqual(line.sent[3:5], [TOKEN_TO_CPU, TOKEN_TO_CPU])

    def test_silent_line_ends_at_max_time(self):
        rc, s, _ = run_pg(FakeCpu(silent=True), "--max-time", "3", "--step-timeout", "100")
        self.assertEqual(rc, 1)
        self.assertIn("--max-time 3.0 s reached while waiting for the first token", s["error"])

    def test_step_timeout(self):
        cpu = FakeCpu()
        cpu.take_pdu = lambda du: cpu.pg_pdus.append(du)  # a CPU that never confirms
        rc, s, _ = run_pg(cpu, "--step-timeout", "2")
        self.assertEqual(rc, 1)
        self.assertIn("waiting for the connect confirm (D0) from CPU 2", s["error"])


class NoAnswerCpu(FakeCpu):
    """Acknowledges data messages (B0) but never answers the S7 job."""

    def take_pdu(self, du):
        if du[0] == 0xF1:
            self.pg_pdus.append(du)
            self.queue_pdu(h("B0 01") + du[1:2])
            return
        super().take_pdu(du)


class StepTimeoutWhileConnected(unittest.TestCase):
    def test_no_s7_answer_ends_with_a_disconnect(self):
        cpu = NoAnswerCpu()
        rc, s, _ = run_pg(cpu, "--step-timeout", "2")
        self.assertEqual(rc, 1)
        self.assertIn("waiting for the answer to Setup Communication", s["error"])
        self.assertTrue(s["disconnected"])
        self.assertTrue(cpu.disconnected)
        self.assertEqual(s["acks_received"], 1)


class ScriptedLink:
    """A link that plays a fixed script: after each frame the PG sends, the replies queued for
    it (by the frame's octets) are delivered."""

    def __init__(self, first, answers):
        self.t = 0.0
        self.to_pg = deque(first)
        self.answers = answers
        self.sent = []

    def now(self):
        return self.t

    def send(self, f):
        self.sent.append(bytes(f))
        self.t += 0.001
        self.to_pg.extend(self.answers.pop(bytes(f), []))

    def read(self, deadline):
        if self.to_pg:
            return self.to_pg.popleft()
        self.t = max(self.t, deadline)
        return None


class NoUser:
    def __init__(self):
        self.indications = []

    def next_request(self):
        return None

    def on_result(self, req, result, reply):
        pass

    def on_indication(self, sa, dsap, ssap, du):
        self.indications.append((sa, dsap, ssap, du))
        return dsap == 0x14

    def finished(self):
        return False


class StationDetails(unittest.TestCase):
    def test_ready_station_in_the_scan_becomes_ns(self):
        # An OP at 1 answers the PG's poll "ready" (01+00+20... reply 10 00 01 20 21 16).
        link = ScriptedLink([GAP_POLL_TO_PG], {READY_REPLY: [TOKEN_TO_PG],
                                              POLL_1: [h("10 00 01 20 21 16")],
                                              h("DC 01 00"): [h("DC 02 01")]})
        st = ActiveStation(link, 0, NoUser(), reply_timeout=0.05)
        st.run_until(lambda: False, 1.0)
        self.assertEqual(st.ns, 1)
        self.assertEqual(link.sent[:3], [READY_REPLY, POLL_1, h("DC 01 00")])
        self.assertEqual(st.live, {1: 0x20})

    def test_wrong_sap_is_refused_with_rs_and_a_repeat_gets_the_stored_reply(self):
        # After holding the token: SRD low from 2 to SAP 0x15 -> RS with "in ring" (0x33).
        to_15 = frame(0x80, 0x82, 0x6C, h("15 14 05 01"))
        to_14 = frame(0x80, 0x82, 0x5C, h("14 14 05 01"))
        link = ScriptedLink([GAP_POLL_TO_PG], {READY_REPLY: [TOKEN_TO_PG],
                                              TOKEN_TO_CPU: [to_15, to_14, to_14]})
        user = NoUser()
        st = ActiveStation(link, 0, user, reply_timeout=0.05)
        st.run_until(lambda: False, 1.0)
        self.assertEqual(link.sent[-3:], [RS_IN_RING, h("E5"), h("E5")])
        self.assertEqual(len(user.indications), 2)  # the repeat did not reach the user
        self.assertEqual(st.count["repeats_answered"], 1)

    def test_gap_poll_after_g_visits(self):
        tokens = [TOKEN_TO_PG]
        link = ScriptedLink([GAP_POLL_TO_PG], {READY_REPLY: tokens})
        st = ActiveStation(link, 0, NoUser(), reply_timeout=0.05, gap_factor=2)

        class Ring:
            def send(self_, f):
                link.sent.append(bytes(f))
                if f == TOKEN_TO_CPU or f == READY_REPLY:
                    link.to_pg.append(TOKEN_TO_PG)
        link.send = Ring().send
        st.run_until(lambda: st.count["token_visits"] >= 8, 10.0)
        polls = [i for i, f in enumerate(link.sent) if f == POLL_1]
        # Visit 1: the first scan (address 1 only, then complete); G = 2 visits waiting (2, 3);
        # visit 4: poll 1; visit 5 finds the scan complete; 6, 7 wait; visit 8: poll 1.
        self.assertEqual(len(polls), 3)
        self.assertEqual(st.ns, 2)

    def test_first_scan_spreads_over_visits_and_finds_ns(self):
        # PG at 3, CPU at 2 (PS), HSA 6, a master at 0 that answers "in ring"; 2 polls a visit.
        link = ScriptedLink([], {})
        st = ActiveStation(link, 3, NoUser(), hsa=6, reply_timeout=0.05, scan_per_visit=2)
        token_from_2 = h("DC 03 02")
        link.to_pg.append(token_from_2)

        def send(f):
            link.sent.append(bytes(f))
            if f[0] == 0xDC:
                link.to_pg.append(token_from_2 if f[1] == 2 else h("DC 02 00"))
            elif f == h("10 00 03 49 4C 16"):          # 00+03+49 = 4C: poll to 0
                link.to_pg.append(h("10 03 00 30 33 16"))  # 03+00+30 = 33: in the ring
        link.send = send
        st.run_until(lambda: st.count["token_visits"] >= 2 and link.sent[-1][0] == 0xDC, 5.0)
        polls = [f[1] for f in link.sent if f[0] == 0x10]
        tokens = [f for f in link.sent if f[0] == 0xDC]
        self.assertEqual(polls, [4, 5, 6, 0])  # 4, 5 in visit 1; 6, 0 in visit 2
        self.assertEqual(tokens, [h("DC 02 03"), h("DC 00 03")])
        self.assertEqual(st.ns, 0)
        self.assertEqual(st.live, {0: 0x30})

    def test_request_fc_bits(self):
        self.assertEqual(F.request_fc(F.FN_SRD_HIGH, fcv=False, fcb=True), 0x6D)
        self.assertEqual(F.request_fc(F.FN_SRD_HIGH, fcv=True, fcb=False), 0x5D)
        self.assertEqual(F.request_fc(F.FN_SRD_HIGH, fcv=True, fcb=True), 0x7D)
        self.assertEqual(F.request_fc(F.FN_FDL_STATUS), 0x49)


class Options(unittest.TestCase):
    def parse_error(self, *args):
        with redirect_stderr(io.StringIO()) as err, self.assertRaises(SystemExit) as e:
            outside_pg.options(["--port", "x"] + list(args))
        self.assertEqual(e.exception.code, 2)
        return err.getvalue()

    def test_bad_options(self):
        self.assertIn("--address and --cpu must differ", self.parse_error("--address", "2"))
        self.assertIn("0..126", self.parse_error("--cpu", "127"))
        self.assertIn("--pdu-size", self.parse_error("--pdu-size", "480"))
        self.assertIn("speed", self.parse_error("--speed", "0"))

    def test_default_timeouts_scale_with_speed(self):
        a = outside_pg.options(["--port", "x", "--baud", "187.5k", "--speed", "1/100"])
        # reply: (415 + 66 + 33) = 514 bits at 187500 bit/s = 2.7413 ms virtual, x 100, + 10 ms
        self.assertAlmostEqual(a.timeout, 0.27413 + 0.01, places=5)
        # token: (415 + 2805 + 33) = 3253 bits = 17.349 ms virtual, x 100, + 10 ms
        self.assertAlmostEqual(a.token_timeout, 1.73493 + 0.01, places=5)
        self.assertEqual(a.max_time, 60.0)
        self.assertEqual(outside_pg.options(["--port", "x", "--speed", "1/1000"]).max_time, 600.0)
        b = outside_pg.options(["--port", "x", "--baud", "45.45k", "--tsl", "100"])
        # 199 bits at 45450 bit/s = 4.378 ms, + 10 ms
        self.assertAlmostEqual(b.timeout, 0.004378 + 0.01, places=6)

    def test_missing_port(self):
        with redirect_stderr(io.StringIO()) as err:
            rc = outside_pg.main(["--port", "/nonexistent/pg", "--wait-port", "0"])
        self.assertEqual(rc, 2)
        self.assertIn("/nonexistent/pg does not exist", err.getvalue())


def have_serial():
    try:
        import serial  # noqa: F401
        return True
    except ImportError:
        return False


@unittest.skipUnless(have_serial(), "needs python3-serial (run with /usr/bin/python3)")
class SerialLinkOnAPty(unittest.TestCase):
    def test_garbage_and_an_incomplete_telegram_are_dropped(self):
        import pty
        master, slave = pty.openpty()
        try:
            link = outside_pg.SerialLink(os.ttyname(slave), 187500, resync=0.05)
            # Garbage, then a connect confirm that loses its last 3 octets, then a token.
            os.write(master, h("00 FF") + CONNECT_CONFIRM[:-3])
            self.assertIsNone(link.read(link.now() + 0.2))  # incomplete: dropped after 50 ms
            os.write(master, TOKEN_TO_PG + CONN_ACK_PLC)
            self.assertEqual(link.read(link.now() + 1.0), TOKEN_TO_PG)
            self.assertEqual(link.read(link.now() + 1.0), CONN_ACK_PLC)
            self.assertEqual(link.garbage, 2 + len(CONNECT_CONFIRM) - 3)
            link.send(TOKEN_TO_CPU)
            self.assertEqual(os.read(master, 16), TOKEN_TO_CPU)
            link.close()
        finally:
            os.close(master)
            os.close(slave)


@unittest.skipUnless(have_serial(), "needs python3-serial (run with /usr/bin/python3)")
class OverAPty(unittest.TestCase):
    """The whole program, main() included, on a real pty with the fake CPU on its other side."""

    def test_program_on_a_pty(self):
        import pty
        import tty
        master, slave = pty.openpty()
        tty.setraw(slave)
        path = os.ttyname(slave)
        cpu = FakeCpu()
        stop = threading.Event()

        class PtyLine:
            def __init__(self):
                self.to_pg = deque()

            def flush(self):
                while self.to_pg:
                    os.write(master, self.to_pg.popleft())

        line = PtyLine()
        cpu.line = line

        def serve():
            d = F.Deframer()
            import select
            import time
            polled = 0.0
            while not stop.is_set():
                if not cpu.admitted and time.monotonic() - polled > 0.2:
                    # The GAP poll again until the PG has opened the port and answered; garbage
                    # in front of it, which the PG drops.
                    os.write(master, h("00 00") + GAP_POLL_TO_PG)
                    polled = time.monotonic()
                r, _, _ = select.select([master], [], [], 0.05)
                if r:
                    try:
                        d.feed(os.read(master, 4096))
                    except OSError:
                        return
                    while True:
                        f = d.next()
                        if f is None:
                            break
                        cpu.on_pg_frame(f)
                        line.flush()

        t = threading.Thread(target=serve, daemon=True)
        t.start()
        try:
            out = io.StringIO()
            with redirect_stdout(out):
                rc = outside_pg.main(["--port", path, "--timeout", "0.3", "--token-timeout", "0.3",
                                      "--max-time", "20"])
        finally:
            stop.set()
            t.join(2)
            os.close(master)
            os.close(slave)
        s = json.loads(out.getvalue())
        self.assertEqual(rc, 0, s)
        self.assertGreaterEqual(s["garbage_octets"], 0)
        self.assertEqual(s["data"], "00 01 02 03 04 05 06 07 08 09")
        self.assertEqual(s["pdu_size"], 240)
        self.assertTrue(s["disconnected"])


if __name__ == "__main__":
    unittest.main()
