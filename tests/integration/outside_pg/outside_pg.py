#!/usr/bin/python3
"""An MPI PG outside pbvbus: joins an MPI line's token ring through a serial port (a pbvbus pty),
connects to a CPU, reads DB bytes over S7 communication, disconnects, prints a JSON summary.

It is written from protocol-facts.md §B, §C (FDL frames, token ring, GAP, FCB) and §H (MPI
connection layer, S7 PDUs) and docs/mpi.md (the byte tables), without pbvbus's C++ code, so that
it checks pbvbus's MPI stations from the outside, as a real PG behind an interface would.

Files (this folder; Debian's python3 and python3-serial only):
  fdl_frames.py   FDL telegrams: encode (SD1/SD2/SD3 by §B.1), tokens, decode, Deframer
  fdl_station.py  the FDL active station in wall time: ring entry, token, GAP, FCB, responder
  mpi_pdus.py     MPI connection-layer PDUs (§H.3)
  s7_pdus.py      S7 Setup Communication and Read Var (§H.4)
  pg_session.py   the PG's connection: connect, setup, read, disconnect (the station's user)
  outside_pg.py   this program: the serial link, options, the summary
  test_outside_pg.py  unit tests (hand-worked frames, a fake line playing the CPU)

Running it against pbvbus
-------------------------
A scenario with an MPI line, a CPU at MPI address 2 and a serial STATION attachment at the PG's
address (the scenario names the pty's link path), e.g. examples/mpi.textproto with

    serial { line: "MPI" mode: STATION address: 0 timing: INTERFACE link: "/tmp/pbvbus-pg" }

    ./pbvbus run examples/mpi.textproto --speed 1/100 &
    /usr/bin/python3 tests/integration/outside_pg/outside_pg.py --port /tmp/pbvbus-pg \\
        --address 0 --cpu 2 --db 1 --start 0 --length 10 --speed 1/100

`timing: INTERFACE` makes the attachment hold the program's requests and tokens until the line
has been idle TSYN and the previous reply (or slot time) is over, so the program keeps no bus
timing. What it cannot escape is the other stations' timing: the CPU awaits the PG's SC within
its slot time TSL (415 bit times = 2.2 ms at 187.5 kbit/s) and retries once, and the stations
claim the token after TTO = (6 + 2n) TSL of silence (§C.2). A Python program behind a pty
usually answers within a millisecond, but not always. So pace the run (pbvbus `--speed 1/10`
or slower) and give the program the same --speed (it scales the default timeouts). Tried
against pbvbus's MPI CPU (devices/mpi_station: a CPU at 2 and the pty at 0 on one line at
187.5 kbit/s, TSL 415; a harness outside the repository): at --speed 1, 6 runs of 45 failed (the
PG's SC came after the CPU's slot time twice, the CPU's FDL gave up on the PG and dropped the
connection, and the PG's next frame was refused RS); at 1/10 (20 runs, with and without an OP
at 1 or 5) and at 1/100 every run succeeded.
With the CPU's GAP walk (HSA 31, one address per token visit) the PG waits up to about 30 token
visits for its first poll: about 0.1 s at speed 1, 11 s at 1/100.

Exit status: 0 = connected, the PDU size negotiated, every byte read (and disconnected);
1 = a protocol failure (the summary's "error" says which); 2 = bad options or no port.
The JSON summary on stdout: connected, pdu_size, cpu_sap, data (hex), bytes_read, the FDL
figures (frames sent and received, retries, token visits, ...), the MPI figures, ps, ns, live,
elapsed_s, error.

Decisions where the sources are silent (also in the docstrings of the modules):
  - Ring entry without listening. A pbvbus pty in STATION mode forwards only the frames for its
    address and the first frame after each of the program's telegrams, so the program cannot
    build its LAS from the tokens of the others (§C.4 Listen_Token). It answers every FDL
    Status poll "ready to enter the ring" (0x20), the way pbvbus's ActiveStation answers a
    master of its LAS (docs/fdl-stations.md), and takes the token from whoever passes it (that
    one is PS). NS starts as PS, the only station known to be in the ring; the GAP scan that
    follows (--scan-per-visit addresses per visit, then one per visit every --gap-factor
    visits) makes the first station between that answers "ready" or "in ring" NS. A ring
    member skipped meanwhile is re-admitted by that scan (pbvbus's masters answer "ready" to a
    master of their LAS). With the defaults PG 0, OP 1, CPU 2 the scan is one address. Its
    other SD1 replies carry "in ring" (0x30) once it has held the token.
  - One request cycle per token visit (--per-visit), then the GAP poll(s) when due, then the
    token. The program cannot measure the virtual token rotation time, so it keeps no TTR.
  - A token or request heard while the PG awaits a reply means its token is gone (the CPU
    retried its token pass because the PG's first frame came late, or claimed the token): the
    visit ends and the frame is handled. The request in flight goes again at the next token as
    the same frame with the same FCB, so the CPU answers a repeat with its stored reply
    instead of taking it twice (§C.6); a new frame with an unchanged FCB would be taken for a
    repeat and silently dropped.
  - FDL retries: --retries (1, the §C.1 default); the token pass: 3 attempts (§C.4, S2), then NS
    is forgotten and found again at the next token.
  - Timeouts are wall time, worked out from the line's figures (--tsl, --baud) scaled by
    --speed, plus 10 ms for the pty. A reply (SC or SD1) must start within TSL: --timeout is
    TSL + 66 + 33 bit times. It must stay short, because while the PG waits for an empty address
    the line is silent, and the other stations claim the token after TTO = (6 + 2n) TSL (§C.2).
    The token taker's first frame may be the longest one, forwarded when it has ended:
    --token-timeout is TSL + 2805 + 33 bit times. At 187.5 kbit/s and TSL 415 (pbvbus's MPI
    bus parameters): 2.7 ms and 17.5 ms virtual, 0.28 s and 1.76 s of wall time at 1/100.
  - The first token is awaited until --max-time (the CPU's GAP walk reaches the PG's address
    only every few dozen token visits); every later step of the connection has --step-timeout.
    Both defaults grow as --speed slows down (--max-time 60 s, at 1/1000 600 s).
  - The PG asks for PDU size 240 (the largest S7 PDU that fits one MPI data message with
    headroom, §B.1: 242); a read longer than the negotiated PDU allows is split into several
    Read Var jobs.
"""

import argparse
import json
import os
import select
import sys
import time
from fractions import Fraction

import fdl_frames as F
import mpi_pdus as M
import s7_pdus as S
from fdl_station import ActiveStation
from pg_session import PgSession

LONGEST_FRAME_BITS = 255 * 11
SD1_BITS = 6 * 11
TSYN_BITS = 33
PTY_ALLOWANCE_S = 0.01  # wall time the pty and the scheduler may add to a reply


class SerialLink:
    """A serial port (a pty) opened 8E1 raw; telegrams split from the byte stream. An incomplete
    telegram that gets no further octet for `resync` seconds is dropped (counted as garbage), so
    one lost octet does not swallow the telegrams after it."""

    def __init__(self, port, baud, resync=0.05):
        import serial  # Debian python3-serial; imported here so the unit tests need none
        self.ser = serial.Serial(port, baudrate=baud, bytesize=8, parity=serial.PARITY_EVEN,
                                 stopbits=1, timeout=0)
        self.deframer = F.Deframer()
        self.resync = resync
        self.last_octet = 0.0
        self.ser.reset_input_buffer()  # whatever was queued before we opened the port

    @property
    def garbage(self):
        return self.deframer.garbage

    def now(self):
        return time.monotonic()

    def send(self, frame):
        self.ser.write(frame)
        self.ser.flush()

    def read(self, deadline):
        while True:
            t = self.deframer.next()
            if t is not None:
                return t
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            # select() instead of the port's own timeout: changing that reconfigures the port.
            if self.deframer.buf:
                stale_at = self.last_octet + self.resync
                if time.monotonic() >= stale_at:
                    self.deframer.garbage += len(self.deframer.buf)
                    self.deframer.clear()
                    continue
                left = min(left, stale_at - time.monotonic())
            ready, _, _ = select.select([self.ser.fileno()], [], [], max(0.0, left))
            if ready:
                self.deframer.feed(self.ser.read(max(1, self.ser.in_waiting)))
                self.last_octet = time.monotonic()

    def close(self):
        self.ser.close()


def parse_speed(text):
    try:
        v = Fraction(text)
    except (ValueError, ZeroDivisionError):
        raise argparse.ArgumentTypeError("speed must be N or N/M, e.g. 1/100")
    if v <= 0:
        raise argparse.ArgumentTypeError("speed must be positive")
    return v


def parse_baud(text):
    t = text.strip().lower()
    scale = 1
    if t.endswith("k"):
        t, scale = t[:-1], 1000
    elif t.endswith("m"):
        t, scale = t[:-1], 1000000
    try:
        v = float(t) * scale
    except ValueError:
        raise argparse.ArgumentTypeError("baud must be a number like 187500 or 187.5k")
    if v <= 0:
        raise argparse.ArgumentTypeError("baud must be positive")
    return int(v)


def default_timeout(tsl, baud, speed):
    """Awaiting a reply: it starts within TSL and is at most an SD1 (the CPU's SC or status
    reply, an FDL Status reply), plus TSYN of margin; as wall time at speed, plus the pty's
    allowance. Short on purpose: while the PG waits for an empty address the line is silent, and
    the other stations claim the token after TTO = (6 + 2n) TSL of silence (§C.2)."""
    return float(Fraction(tsl + SD1_BITS + TSYN_BITS, baud) / speed) + PTY_ALLOWANCE_S


def default_token_timeout(tsl, baud, speed):
    """Awaiting the token taker's first frame: it starts within TSL and may be the longest
    frame; the attachment forwards it when it has ended."""
    return float(Fraction(tsl + LONGEST_FRAME_BITS + TSYN_BITS, baud) / speed) + PTY_ALLOWANCE_S


def address(text):
    v = int(text, 0)
    if not 0 <= v <= 126:
        raise argparse.ArgumentTypeError("an address is 0..126")
    return v


def options(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--port", required=True, help="the serial port or the pty's link path")
    ap.add_argument("--address", type=address, default=0, help="the PG's MPI address (0)")
    ap.add_argument("--cpu", type=address, default=2, help="the CPU's MPI address (2)")
    ap.add_argument("--sap", type=lambda s: int(s, 0), default=M.DEFAULT_PG_SAP,
                    help="the PG's SAP (0x14)")
    ap.add_argument("--db", type=int, default=1, help="the DB to read (1)")
    ap.add_argument("--start", type=int, default=0, help="first byte (DBB) to read (0)")
    ap.add_argument("--length", type=int, default=10, help="bytes to read (10)")
    ap.add_argument("--pdu-size", type=int, default=S.PG_PDU_SIZE,
                    help="PDU size asked for in Setup Communication (240)")
    ap.add_argument("--baud", type=parse_baud, default=187500,
                    help="the line's baud rate (187.5k; a pty ignores it; sets the timeouts)")
    ap.add_argument("--speed", type=parse_speed, default=Fraction(1),
                    help="virtual / wall time of a paced pbvbus run (pbvbus --speed), for the "
                         "default timeouts")
    ap.add_argument("--hsa", type=int, default=31, help="highest station address (31, §H.1)")
    ap.add_argument("--tsl", type=int, default=415,
                    help="the line's slot time in bit times, for the default timeouts (415: "
                         "pbvbus's MPI bus parameters at 187.5 kbit/s)")
    ap.add_argument("--timeout", type=float, default=None,
                    help="wall seconds to await a reply (default from --tsl, --baud, --speed)")
    ap.add_argument("--token-timeout", type=float, default=None,
                    help="wall seconds to await the token taker's first frame (default from "
                         "--tsl, --baud, --speed)")
    ap.add_argument("--retries", type=int, default=1, help="FDL retries per request (1)")
    ap.add_argument("--per-visit", type=int, default=1, help="request cycles per token visit")
    ap.add_argument("--gap-factor", type=int, default=10, help="G: visits between GAP scans")
    ap.add_argument("--scan-per-visit", type=int, default=4,
                    help="GAP polls per token visit in the first scan after entering the ring")
    ap.add_argument("--step-timeout", type=float, default=None,
                    help="wall seconds any step of the connection may take (default: 40 x "
                         "--timeout, at least 5 s)")
    ap.add_argument("--max-time", type=float, default=None,
                    help="give up after this many wall seconds (60, or 0.6 / --speed if longer)")
    ap.add_argument("--wait-port", type=float, default=10.0,
                    help="wait this long for the port to appear (10 s)")
    ap.add_argument("--no-disconnect", action="store_true", help="leave the connection open")
    ap.add_argument("-v", "--verbose", action="store_true", help="log to stderr")
    ap.add_argument("--trace", action="store_true",
                    help="every telegram in (<) and out (>) to stderr, with wall time")
    a = ap.parse_args(argv)
    if not 0 <= a.sap <= 63:
        ap.error("--sap must be 0..63")
    if a.address == a.cpu:
        ap.error("--address and --cpu must differ")
    if not 0 <= a.db <= 65535 or not 0 <= a.start <= 0xFFFF or not 0 <= a.length <= 65535:
        ap.error("--db, --start, --length must be 0..65535")
    if not 19 <= a.pdu_size <= S.PG_PDU_SIZE:
        ap.error("--pdu-size must be 19..%d (one MPI data message)" % S.PG_PDU_SIZE)
    if not a.address <= a.hsa <= 126:
        ap.error("--hsa must be 0..126 and not below --address")
    if a.max_time is None:
        a.max_time = max(60.0, float(Fraction(6, 10) / a.speed))
    if a.tsl <= 0:
        ap.error("--tsl must be positive")
    if a.timeout is None:
        a.timeout = default_timeout(a.tsl, a.baud, a.speed)
    if a.token_timeout is None:
        a.token_timeout = max(a.timeout, default_token_timeout(a.tsl, a.baud, a.speed))
    if a.step_timeout is None:
        a.step_timeout = max(5.0, 40 * a.token_timeout)
    if min(a.timeout, a.token_timeout, a.max_time) <= 0 or a.per_visit < 1 or a.retries < 0 \
            or a.scan_per_visit < 1 or a.gap_factor < 0:
        ap.error("timeouts and --max-time must be positive, --per-visit and --scan-per-visit "
                 ">= 1, --retries and --gap-factor >= 0")
    return a


def run(link, a, log, trace=None):
    """Runs the PG on a link; returns (exit status, summary)."""
    t0 = link.now()
    session = PgSession(a.cpu, a.db, a.start, a.length, link.now, pg_sap=a.sap,
                        pdu_size=a.pdu_size, step_timeout=a.step_timeout,
                        disconnect=not a.no_disconnect, log=log)
    station = ActiveStation(link, a.address, session, hsa=a.hsa, reply_timeout=a.timeout,
                            token_timeout=a.token_timeout,
                            retries=a.retries, gap_factor=a.gap_factor, per_visit=a.per_visit,
                            scan_per_visit=a.scan_per_visit,
                            log=log, trace=trace)
    finished = station.run_until(session.finished, t0 + a.max_time, on_idle=session.check)
    if not finished:
        session.fail("--max-time %.1f s reached while waiting for %s" % (a.max_time,
                                                                          session.waiting_for))
    complete = len(session.data) == a.length and session.pdu_size is not None
    ok = session.error is None and complete and (session.disconnected or a.no_disconnect)
    summary = {
        "ok": ok,
        "address": a.address,
        "cpu": a.cpu,
        "connected": session.connected or session.disconnected,
        "disconnected": session.disconnected,
        "pg_sap": a.sap,
        "cpu_sap": session.cpu_sap,
        "pdu_size": session.pdu_size,
        "db": a.db,
        "start": a.start,
        "length": a.length,
        "bytes_read": len(session.data),
        "data": bytes(session.data).hex(" ").upper(),
        "ps": station.ps,
        "ns": station.ns,
        "live": {str(k): v for k, v in sorted(station.live.items())},
        "elapsed_s": round(link.now() - t0, 3),
        "error": session.error,
    }
    summary.update(station.count)
    summary.update(session.count)
    return (0 if ok else 1), summary


def main(argv=None):
    a = options(sys.argv[1:] if argv is None else argv)

    def log(msg):
        if a.verbose:
            sys.stderr.write("outside_pg: %s\n" % msg)

    t0 = time.monotonic()

    def trace(msg):
        sys.stderr.write("%10.6f %s\n" % (time.monotonic() - t0, msg))

    until = time.monotonic() + a.wait_port
    while not os.path.exists(a.port) and time.monotonic() < until:
        time.sleep(0.05)
    if not os.path.exists(a.port):
        sys.stderr.write("outside_pg: %s does not exist (waited %.1f s for it)\n"
                         % (a.port, a.wait_port))
        return 2
    try:
        link = SerialLink(a.port, a.baud)
    except ImportError:
        sys.stderr.write("outside_pg: no serial module (Debian: apt-get install python3-serial; "
                         "run with /usr/bin/python3)\n")
        return 2
    except Exception as e:  # serial.SerialException, OSError
        sys.stderr.write("outside_pg: cannot open %s: %s\n" % (a.port, e))
        return 2
    try:
        rc, summary = run(link, a, log, trace if a.trace else None)
    finally:
        link.close()
    summary["garbage_octets"] = link.garbage
    json.dump(summary, sys.stdout)
    sys.stdout.write("\n")
    if summary["error"]:
        sys.stderr.write("outside_pg: %s\n" % summary["error"])
    return rc


if __name__ == "__main__":
    sys.exit(main())
