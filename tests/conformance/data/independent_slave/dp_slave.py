#!/usr/bin/python3
"""An independently written PROFIBUS-DP (DP-V0) slave behind a serial port / pty, behaving as
the GSD PBVB0A01 describes (Ident 0x0A01, cfg 0x11 0x21). See README.md in this folder.

  /usr/bin/python3 dp_slave.py --port /tmp/pbvbus-dp --address 3 [--baud 45450]
      [--speed 1/20] [--bug NAME]... [--wait-port 10] [--log FILE] [-v]

Structure: fdl_frame (octets <-> telegrams), fdl_layer (address filter, FCB, SAPs, replies),
dp_state (DP services and state machine); this file holds the clock, the port and the loop.
"""

import argparse
import os
import select
import signal
import sys
import time
import traceback
from fractions import Fraction

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import fdl_frame        # noqa: E402
import fdl_layer        # noqa: E402
import dp_state         # noqa: E402
from bugs import BUGS   # noqa: E402


class PacedClock:
    """Virtual time = wall time x N/M (pbvbus --speed N/M: virtual runs N/M times as fast)."""

    def __init__(self, ratio: Fraction):
        self.ratio = float(ratio)
        self.t0 = time.monotonic()

    def now(self) -> float:
        return (time.monotonic() - self.t0) * self.ratio

    def wall(self, virtual_seconds: float) -> float:
        return virtual_seconds / self.ratio


class Logger:
    def __init__(self, path=None, verbose=False):
        self.f = open(path, "a", buffering=1) if path else None
        self.verbose = verbose
        self.t0 = time.monotonic()

    def __call__(self, msg):
        line = "%10.3f %s" % (time.monotonic() - self.t0, msg)
        if self.f:
            self.f.write(line + "\n")
        if self.verbose:
            sys.stderr.write(line + "\n")


def parse_speed(text: str) -> Fraction:
    if "/" in text:
        n, m = text.split("/", 1)
        r = Fraction(int(n), int(m))
    else:
        r = Fraction(text)
    if r <= 0:
        raise argparse.ArgumentTypeError("speed must be positive")
    return r


def open_port(path, baud, wait, log):
    import serial
    deadline = time.monotonic() + wait
    last_err = None
    while True:
        if os.path.exists(path):
            try:
                ser = serial.Serial(port=path, baudrate=baud, bytesize=serial.EIGHTBITS,
                                    parity=serial.PARITY_EVEN, stopbits=serial.STOPBITS_ONE,
                                    timeout=0, xonxoff=False, rtscts=False, dsrdtr=False)
                ser.reset_input_buffer()    # frames queued before we came are stale
                log("opened %s (%d baud 8E1)" % (path, baud))
                return ser
            except (OSError, ValueError, serial.SerialException) as e:
                last_err = e
        if time.monotonic() >= deadline:
            raise SystemExit("dp_slave: cannot open %s within %.1f s%s"
                             % (path, wait, (": %s" % last_err) if last_err else ""))
        time.sleep(0.05)


def hexs(b):
    return b.hex(" ")


class SlaveProgram:
    """The main loop: read octets, deframe, answer, keep the watchdog."""

    def __init__(self, args, log):
        self.args = args
        self.log = log
        self.clock = PacedClock(args.speed)
        bugs = frozenset(args.bug or ())
        self.dp = dp_state.DpSlave(args.address, bugs=bugs, log=log,
                                   lplus_missing_after=args.lplus_missing_after)
        self.fdl = fdl_layer.FdlResponder(self.dp, bugs=bugs, log=log)
        self.deframer = fdl_frame.Deframer()
        self.resync_gap = args.resync_ms / 1000.0   # wall seconds without octets
        self.last_rx = 0.0
        self.stop = False
        self.rx_frames = self.tx_frames = 0

    def reply_not_before(self, rx_wall):
        """min TSDR (§C.1/§D.2): a reply starts no earlier than min TSDR bit times after the
        request's end. Through a pty this is only approximate: the request's end is taken as
        the moment its octets were read, and the bit time is that of --baud in virtual time."""
        if self.args.no_tsdr_delay:
            return rx_wall
        return rx_wall + self.clock.wall(self.dp.min_tsdr / float(self.args.baud))

    def handle_telegrams(self, telegrams, now, rx_wall):
        for tel in telegrams:
            self.rx_frames += 1
            try:
                reply = self.fdl.handle(tel, now)
            except Exception:                         # never let one telegram kill us
                self.log("internal error on %s:\n%s" % (hexs(tel.raw), traceback.format_exc()))
                continue
            if self.args.trace:
                self.log("rx %s" % hexs(tel.raw))
            if reply:
                delay = self.reply_not_before(rx_wall) - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
                self.ser.write(reply)
                self.tx_frames += 1
                if self.args.trace:
                    self.log("tx %s" % hexs(reply))

    def run(self):
        self.ser = open_port(self.args.port, self.args.baud, self.args.wait_port, self.log)
        fd = self.ser.fileno()
        self.log("station %d, bugs: %s, speed %s" % (self.args.address,
                 ",".join(sorted(self.args.bug or ())) or "none", self.args.speed))
        while not self.stop:
            timeout = 0.25
            dl = self.dp.next_deadline()
            if dl is not None:
                timeout = min(timeout, max(0.0, self.clock.wall(dl - self.clock.now())))
            if self.deframer.pending():
                timeout = min(timeout, max(0.0, self.last_rx + self.resync_gap - time.monotonic()))
            try:
                ready, _, _ = select.select([fd], [], [], timeout)
            except InterruptedError:
                continue
            now = self.clock.now()
            self.dp.check_watchdog(now)          # expiry before the frame that came too late
            if ready:
                try:
                    data = os.read(fd, 4096)
                except OSError as e:
                    self.log("port read error: %s; exiting" % e)
                    return 0
                if not data:
                    self.log("port closed; exiting")
                    return 0
                self.last_rx = time.monotonic()
                self.handle_telegrams(self.deframer.feed(data), now, self.last_rx)
            elif self.deframer.pending() and time.monotonic() - self.last_rx >= self.resync_gap:
                self.handle_telegrams(self.deframer.flush_stale(), now, time.monotonic())
        return 0

    def summary(self):
        self.log("summary: state %s owner %s address %d min_tsdr %d rx %d tx %d junk %d "
                 "repeats %d dx %d" % (self.dp.state, self.dp.owner, self.dp.address,
                                       self.dp.min_tsdr, self.rx_frames, self.tx_frames,
                                       self.deframer.junk, self.fdl.repeats, self.dp.dx_count))


def main(argv=None):
    ap = argparse.ArgumentParser(description="Independent DP-V0 slave (GSD PBVB0A01).")
    ap.add_argument("--port", required=True, help="serial port or pty path")
    ap.add_argument("--address", type=int, required=True, help="station address 0..126")
    ap.add_argument("--baud", type=int, default=45450, help="baud rate set on the port (8E1)")
    ap.add_argument("--speed", type=parse_speed, default=Fraction(1),
                    help="virtual/wall time ratio N/M of the paced pbvbus run (default 1)")
    ap.add_argument("--bug", action="append", choices=sorted(BUGS),
                    help="plant one bug (repeatable); without it the slave is honest")
    ap.add_argument("--wait-port", type=float, default=10.0,
                    help="seconds to wait for the port to appear (default 10)")
    ap.add_argument("--log", help="append a log to FILE")
    ap.add_argument("--trace", action="store_true", help="log every telegram in and out")
    ap.add_argument("-v", "--verbose", action="store_true", help="log to stderr too")
    ap.add_argument("--no-tsdr-delay", action="store_true",
                    help="answer at once instead of waiting min TSDR (virtual bit times)")
    ap.add_argument("--resync-ms", type=float, default=50.0,
                    help="wall ms of silence after which an incomplete telegram is dropped")
    ap.add_argument("--lplus-missing-after", type=int, default=None, metavar="N",
                    help="unit diagnosis 'Load voltage L+ missing' appears after N "
                         "Data_Exchanges (reported if User_Prm_Data bit 1 enables it)")
    ap.add_argument("--list-bugs", action="store_true", help="print the bug names and exit")
    if argv is None and "--list-bugs" in sys.argv[1:]:
        for name, text in sorted(BUGS.items()):
            print("%-24s %s" % (name, text))
        return 0
    args = ap.parse_args(argv)
    if not 0 <= args.address <= 126:
        ap.error("--address must be 0..126")
    log = Logger(args.log, args.verbose)
    prog = SlaveProgram(args, log)

    def on_signal(signum, frame):
        prog.stop = True
    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)
    try:
        return prog.run()
    finally:
        prog.summary()


if __name__ == "__main__":
    sys.exit(main())
