#!/usr/bin/python3
"""A small class-1 PROFIBUS-DP master behind a serial port, for pbvbus's integration tests.

It is written the way PC programs that drive a serial PROFIBUS adapter usually are: it keeps no
bus timing of its own and writes its next request IMMEDIATELY after reading a reply. On a real
line the receivers drop such requests (less than TSYN = 33 bit times of idle before them); a
pbvbus serial attachment with `timing: INTERFACE` holds them like a DP interface ASIC would,
one with `timing: RAW` does not (tests/integration/outside_master_test.cpp runs both).

What it does (protocol-facts.md §B, §C.6, §D):
  - FDL framing: SD1 without data, SD3 for exactly 8 octets of DU (SAPs included), SD2
    otherwise; FCS = sum of DA..DU mod 256; replies are checked (delimiters, length, FCS, DA,
    SA). SC (E5) is accepted as the reply to Set_Prm and Chk_Cfg.
  - FCB/FCV per slave: the first frame FCV=0/FCB=1, then FCV=1 with FCB toggled after every
    valid reply; a retry repeats the frame unchanged; a slave that does not answer after the
    retries is "non-operational" and starts again with a first frame.
  - Start-up per slave: Slave_Diag (SAP 60), Set_Prm (SAP 61: lock, watchdog, min TSDR 11,
    the ident and User_Prm_Data of its GSD), Chk_Cfg (SAP 62: the modules' configuration
    octets), Slave_Diag again (must show neither Station_Not_Ready, Cfg_Fault, Prm_Fault nor
    Prm_Req); then cyclic Data_Exchange (SRD high to the default SAP with the output octets,
    inputs in the reply). A refusal (RS) or a lost slave restarts its start-up; DH in a
    Data_Exchange reply makes it read the diagnosis once.
  - Retries: no valid reply within --timeout seconds of wall time -> the same frame again, up
    to --retries times.
  - Slaves are served round-robin, one request each, until each has done --cycles
    Data_Exchanges (or --max-time seconds have passed).
At the end it prints a JSON summary on stdout: requests sent and answered, retries, and per
slave its state, the services answered, the outputs it wrote last and the inputs it read last.

Usage:
  outside_master.py --port /tmp/pbvbus-dp --slave 3:0x0A01:12:1121:2:2 --cycles 200
  --slave ADDR:IDENT:PRM:CFG:INLEN:OUTLEN  (PRM = User_Prm_Data in hex, CFG = Chk_Cfg octets in
                                            hex, both "" or "-" for none)
"""

import argparse
import json
import select
import sys
import time

import serial

SD1, SD2, SD3, SD4, SC, ED = 0x10, 0x68, 0xA2, 0xDC, 0xE5, 0x16
SAP_MS0, SAP_DIAG, SAP_PRM, SAP_CFG = 62, 60, 61, 62
FC_SRD_HIGH = 0x4D
FCB, FCV = 0x20, 0x10
ST_DL, ST_DH, ST_RS = 0x08, 0x0A, 0x03


def encode(da, sa, fc, dsap=None, ssap=None, data=b""):
    du = bytes(data)
    d, s = da, sa
    if dsap is not None:
        d |= 0x80
        s |= 0x80
        du = bytes([dsap, ssap]) + du
    body = bytes([d, s, fc]) + du
    fcs = sum(body) & 0xFF
    if not du:
        return bytes([SD1]) + body + bytes([fcs, ED])
    if len(du) == 8:
        return bytes([SD3]) + body + bytes([fcs, ED])
    return bytes([SD2, len(body), len(body), SD2]) + body + bytes([fcs, ED])


def telegram_length(buf):
    """Length of the telegram at the start of buf; 0 = need more; -1 = not a start."""
    if not buf:
        return 0
    sd = buf[0]
    if sd == SC:
        return 1
    if sd == SD4:
        return 3
    if sd == SD1:
        return 6
    if sd == SD3:
        return 14
    if sd == SD2:
        if len(buf) < 4:
            return 0
        le = buf[1]
        if buf[2] != le or buf[3] != SD2 or le < 4 or le > 249:
            return -1
        return le + 6
    return -1


class Reply:
    def __init__(self, kind, da=0, sa=0, fc=0, dsap=None, ssap=None, data=b""):
        self.kind, self.da, self.sa, self.fc = kind, da, sa, fc
        self.dsap, self.ssap, self.data = dsap, ssap, data

    @property
    def status(self):
        return self.fc & 0x0F


def decode(frame):
    """A reply frame -> Reply, or None if it is not a valid response."""
    if frame == bytes([SC]):
        return Reply("SC")
    sd = frame[0]
    if sd in (SD1, SD3):
        body = frame[1:-2]
    elif sd == SD2:
        body = frame[4:-2]
    else:
        return None
    if frame[-1] != ED or (sum(body) & 0xFF) != frame[-2] or len(body) < 3:
        return None
    da, sa, fc = body[0], body[1], body[2]
    if fc & 0x40:
        return None  # a request, not a reply
    du = body[3:]
    dsap = ssap = None
    if da & 0x80:
        dsap, du = du[0] & 0x3F, du[1:]
    if sa & 0x80:
        ssap, du = du[0] & 0x3F, du[1:]
    return Reply("frame", da & 0x7F, sa & 0x7F, fc, dsap, ssap, bytes(du))


class Link:
    def __init__(self, port, baud):
        self.ser = serial.Serial(port, baudrate=baud, bytesize=8, parity=serial.PARITY_EVEN,
                                 stopbits=1, timeout=0)
        self.buf = bytearray()
        self.garbage = 0
        self.ser.reset_input_buffer()  # whatever was queued before we opened the port

    def send(self, frame):
        self.ser.write(frame)
        self.ser.flush()

    def flush_input(self):
        self.buf.clear()
        self.ser.reset_input_buffer()

    def read_frame(self, deadline):
        """The next whole telegram, or None at the deadline (wall time)."""
        while True:
            while self.buf:
                n = telegram_length(self.buf)
                if n < 0:
                    del self.buf[0]
                    self.garbage += 1
                    continue
                if n and len(self.buf) >= n:
                    frame = bytes(self.buf[:n])
                    del self.buf[:n]
                    return frame
                break
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            # select() instead of the port's own timeout: changing that reconfigures the port.
            ready, _, _ = select.select([self.ser.fileno()], [], [], left)
            if ready:
                self.buf.extend(self.ser.read(max(1, self.ser.in_waiting)))


class Slave:
    def __init__(self, spec):
        addr, ident, prm, cfg, inlen, outlen = spec.split(":")
        self.address = int(addr, 0)
        self.ident = int(ident, 0)
        self.prm = bytes.fromhex("" if prm == "-" else prm)
        self.cfg = bytes.fromhex("" if cfg == "-" else cfg)
        self.inlen, self.outlen = int(inlen), int(outlen)
        self.phase = "diag"
        self.fcv, self.fcb = False, True
        self.cycle = 0
        self.outputs = bytes(self.outlen)
        self.inputs = b""
        self.diag = b""
        self.count = {"sent": 0, "answered": 0, "retries": 0, "failed": 0, "restarts": 0,
                      "set_prm": 0, "chk_cfg": 0, "slave_diag": 0, "data_exchange": 0,
                      "refused": 0}

    def fc(self):
        return FC_SRD_HIGH | (FCB if self.fcb else 0) | (FCV if self.fcv else 0)

    def restart(self):
        self.phase = "diag"
        self.count["restarts"] += 1


class Master:
    def __init__(self, link, address, slaves, timeout, retries, watchdog_ms):
        self.link, self.address, self.slaves = link, address, slaves
        self.timeout, self.retries = timeout, retries
        self.watchdog_ms = watchdog_ms
        self.sent = self.answered = self.retried = 0

    def transaction(self, s, dsap, data):
        """One SRD with retries; the valid reply, or None (the slave is non-operational)."""
        frame = encode(s.address, self.address, s.fc(), dsap,
                       SAP_MS0 if dsap is not None else None, data)
        for attempt in range(1 + self.retries):
            if attempt:
                self.retried += 1
                s.count["retries"] += 1
                self.link.flush_input()
            self.link.send(frame)  # at once: no bus timing kept here
            self.sent += 1
            s.count["sent"] += 1
            deadline = time.monotonic() + self.timeout
            while True:
                raw = self.link.read_frame(deadline)
                if raw is None:
                    break
                r = decode(raw)
                if r is None:
                    continue
                if r.kind == "frame" and (r.da != self.address or r.sa != s.address):
                    continue  # not the reply to this request
                self.answered += 1
                s.count["answered"] += 1
                s.fcv, s.fcb = True, not s.fcb
                return r
        s.count["failed"] += 1
        s.fcv, s.fcb = False, True  # non-operational: the next frame is a first frame again
        return None

    def set_prm_du(self, s):
        if self.watchdog_ms:
            units = max(1, self.watchdog_ms // 10)
            f1 = 1
            while units // f1 > 255:
                f1 += 1
            status, wd1, wd2 = 0x88, f1, max(1, units // f1)
        else:
            status, wd1, wd2 = 0x80, 1, 1
        return bytes([status, wd1, wd2, 11, s.ident >> 8, s.ident & 0xFF, 0]) + s.prm

    def step(self, s):
        """One request to slave s, according to its phase."""
        if s.phase in ("diag", "diag2", "diag_dx"):
            r = self.transaction(s, SAP_DIAG, b"")
            if r is None:
                return s.restart()
            if r.kind != "frame" or r.status not in (ST_DL, ST_DH) or len(r.data) < 6:
                s.count["refused"] += 1
                return s.restart()
            s.count["slave_diag"] += 1
            s.diag = r.data
            if s.phase == "diag":
                s.phase = "prm"
            elif s.phase == "diag_dx":
                s.phase = "dx"
            else:
                bad = (r.data[0] & (0x01 | 0x02 | 0x04 | 0x40)) or (r.data[1] & 0x01)
                s.phase = "diag" if bad else "dx"
                if bad:
                    s.count["restarts"] += 1
        elif s.phase == "prm":
            r = self.transaction(s, SAP_PRM, self.set_prm_du(s))
            if r is None:
                return s.restart()
            if r.kind != "SC":
                s.count["refused"] += 1
                return s.restart()
            s.count["set_prm"] += 1
            s.phase = "cfg"
        elif s.phase == "cfg":
            r = self.transaction(s, SAP_CFG, s.cfg)
            if r is None:
                return s.restart()
            if r.kind != "SC":
                s.count["refused"] += 1
                return s.restart()
            s.count["chk_cfg"] += 1
            s.phase = "diag2"
        else:  # "dx"
            # The "PLC program": the outputs change every cycle.
            out = bytes((s.cycle + 17 * k + s.address) & 0xFF for k in range(s.outlen))
            r = self.transaction(s, None, out)
            if r is None:
                return s.restart()
            if r.kind == "SC" and s.inlen == 0:
                data, status = b"", ST_DL
            elif r.kind == "frame" and r.status in (ST_DL, ST_DH) and len(r.data) == s.inlen:
                data, status = r.data, r.status
            else:
                s.count["refused"] += 1
                return s.restart()
            s.count["data_exchange"] += 1
            s.outputs, s.inputs = out, data
            s.cycle += 1
            if status == ST_DH:
                s.phase = "diag_dx"

    def run(self, cycles, max_time):
        t0 = time.monotonic()
        while time.monotonic() - t0 < max_time:
            if all(s.count["data_exchange"] >= cycles for s in self.slaves):
                return True, time.monotonic() - t0
            for s in self.slaves:
                if s.count["data_exchange"] < cycles:
                    self.step(s)
        return False, time.monotonic() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--port", required=True)
    ap.add_argument("--address", type=int, default=2)
    ap.add_argument("--baud", type=int, default=19200,
                    help="the port's baud rate (a pty ignores it)")
    ap.add_argument("--slave", action="append", required=True)
    ap.add_argument("--cycles", type=int, default=200)
    ap.add_argument("--timeout", type=float, default=0.5)
    ap.add_argument("--retries", type=int, default=3)
    ap.add_argument("--max-time", type=float, default=40.0)
    ap.add_argument("--watchdog-ms", type=int, default=2000)
    a = ap.parse_args()

    link = Link(a.port, a.baud)
    slaves = [Slave(spec) for spec in a.slave]
    m = Master(link, a.address, slaves, a.timeout, a.retries, a.watchdog_ms)
    done, elapsed = m.run(a.cycles, a.max_time)
    summary = {
        "address": a.address,
        "completed": done,
        "elapsed_s": round(elapsed, 3),
        "requests_sent": m.sent,
        "requests_answered": m.answered,
        "retries": m.retried,
        "garbage_octets": link.garbage,
        "slaves": [
            dict(address=s.address, phase=s.phase, inputs=s.inputs.hex(" ").upper(),
                 outputs=s.outputs.hex(" ").upper(), diag=s.diag.hex(" ").upper(), **s.count)
            for s in slaves
        ],
    }
    json.dump(summary, sys.stdout)
    sys.stdout.write("\n")
    return 0 if done else 1


if __name__ == "__main__":
    sys.exit(main())
