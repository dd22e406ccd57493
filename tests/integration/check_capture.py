#!/usr/bin/env python3
"""Independent protocol check of a pbvbus pcapng capture (PROFIBUS FDL on USER0 interfaces).

Written against the specifications only, standard library only: its own pcapng reader
(draft-ietf-opsawg-pcapng: SHB, IDB, EPB, SPB, either byte order, if_tsresol/if_tsoffset) and
its own FDL frame decoder (IEC 61158-4-3: SD1, SD2, SD3, SD4, SC, FCS, FC). It shares no code
with pbvbus (neither the C++ reader nor the Lua dissector), so a bug there cannot hide itself.

What an analyzer at the capture's probe point would tell a commissioning engineer:
  collisions       records that overlap the previous activity on their interface, and records
                   with epb_flags error bits (collision, CRC, too short, ...);
  order            records whose timestamp is earlier than the one before (file order);
  timing           idle before a request or token < TSYN (33 bit times); a response after
                   less than min TSDR idle; a response that starts more than TSL after the end
                   of its request (the requester would have given up);
  live list        stations that sent a frame (SA of intact frames; an SC counts for the DA of
                   the request it answers), against an expected set;
  token conflicts  a token frame from a station that was not the last token receiver, except the
                   legitimate ones: the first token seen, a repeated pass by the last passer when
                   nothing was heard after its pass (Check_Token_Pass retry, or giving up and
                   passing to the next station), and a claim (DC n n) after at least
                   TTO(n) = 6*TSL + 2*n*TSL of silence (also when n was the last holder: a
                   lone master's token to itself after TTO of silence is a claim; listed
                   under "claims" with the idle before it);
  ring membership  token passes (SA>DA) per time window.

Times are in seconds in the arguments and the report (ns inside). Bit times use the baud from
the interface's if_speed.

Usage: check_capture.py FILE [--interface NAME] [--tsl BITS] [--min-tsdr BITS] [--window S]
         [--allow T0:T1]... [--expect-clean] [--expect-live A,B,...]
         [--expect-silent ADDR@T0:T1]... [--expect-no-token-to ADDR@T0:T1]...
         [--expect-token-to ADDR@T0:T1]... [--expect-rotation-at-most ADDR@T0:T1=BITS]...
         [--json]
Exit status: 0 every expectation holds, 1 one does not, 2 the file cannot be read.
"""

import argparse
import json
import struct
import sys
from fractions import Fraction

NS = 10**9
TSYN = 33  # bit times of idle before a request or token (IEC 61158-4-3)

# --- pcapng ------------------------------------------------------------------------------------

BLOCK_SHB = 0x0A0D0D0A
BLOCK_IDB = 0x00000001
BLOCK_SPB = 0x00000003
BLOCK_EPB = 0x00000006
LINKTYPE_USER0 = 147
LINKTYPE_PROFIBUS_DL = 257


class PcapngError(Exception):
    pass


class Interface:
    def __init__(self, link_type):
        self.link_type = link_type
        self.name = ""
        self.description = ""
        self.speed = 0
        self.tsresol = 6
        self.tsoffset = 0

    def ts_to_ns(self, ts):
        r = self.tsresol
        if r & 0x80:
            ns = (ts * NS) >> (r & 0x7F)
        elif r <= 9:
            ns = ts * 10 ** (9 - r)
        else:
            ns = ts // 10 ** (r - 9)
        return ns + self.tsoffset * NS


class Record:
    __slots__ = ("index", "iface", "ts", "data", "flags", "comment")

    def __init__(self, index, iface, ts, data, flags, comment):
        self.index = index
        self.iface = iface
        self.ts = ts  # ns
        self.data = data
        self.flags = flags
        self.comment = comment


def read_options(buf, off, end, endian):
    """Yields (code, value bytes) until opt_endofopt or the end of the block body."""
    while off + 4 <= end:
        code, length = struct.unpack_from(endian + "HH", buf, off)
        off += 4
        if code == 0:
            return
        if off + length > end:
            raise PcapngError("option %d overruns its block at offset %d" % (code, off))
        yield code, bytes(buf[off:off + length])
        off += (length + 3) & ~3


def read_pcapng(path):
    with open(path, "rb") as f:
        buf = f.read()
    interfaces = []  # all sections
    section_base = 0
    endian = None
    records = []
    off = 0
    while off < len(buf):
        if off + 12 > len(buf):
            raise PcapngError("truncated block header at offset %d" % off)
        raw_type = struct.unpack_from("<I", buf, off)[0]
        if raw_type == BLOCK_SHB:
            magic = buf[off + 8:off + 12]
            if magic == b"\x4d\x3c\x2b\x1a":
                endian = "<"
            elif magic == b"\x1a\x2b\x3c\x4d":
                endian = ">"
            else:
                raise PcapngError("bad byte-order magic at offset %d" % off)
            section_base = len(interfaces)
        elif endian is None:
            raise PcapngError("no section header block at offset %d" % off)
        btype, blen = struct.unpack_from(endian + "II", buf, off)
        if blen < 12 or blen % 4 or off + blen > len(buf):
            raise PcapngError("bad block length %d at offset %d" % (blen, off))
        if struct.unpack_from(endian + "I", buf, off + blen - 4)[0] != blen:
            raise PcapngError("trailing block length differs at offset %d" % off)
        body, end = off + 8, off + blen - 4
        if btype == BLOCK_IDB:
            link_type = struct.unpack_from(endian + "H", buf, body)[0]
            itf = Interface(link_type)
            for code, val in read_options(buf, body + 8, end, endian):
                if code == 2:
                    itf.name = val.decode("utf-8", "replace")
                elif code == 3:
                    itf.description = val.decode("utf-8", "replace")
                elif code == 8 and len(val) == 8:
                    itf.speed = struct.unpack(endian + "Q", val)[0]
                elif code == 9 and len(val) >= 1:
                    itf.tsresol = val[0]
                elif code == 14 and len(val) == 8:
                    itf.tsoffset = struct.unpack(endian + "q", val)[0]
            interfaces.append(itf)
        elif btype == BLOCK_EPB:
            if_id, ts_hi, ts_lo, cap_len, _orig = struct.unpack_from(endian + "IIIII", buf, body)
            if section_base + if_id >= len(interfaces):
                raise PcapngError("packet of undeclared interface %d at offset %d" % (if_id, off))
            itf_index = section_base + if_id
            data = bytes(buf[body + 20:body + 20 + cap_len])
            flags, comment = 0, ""
            for code, val in read_options(buf, body + 20 + ((cap_len + 3) & ~3), end, endian):
                if code == 2 and len(val) == 4:
                    flags = struct.unpack(endian + "I", val)[0]
                elif code == 1:
                    comment = val.decode("utf-8", "replace")
            ts = interfaces[itf_index].ts_to_ns((ts_hi << 32) | ts_lo)
            records.append(Record(len(records), itf_index, ts, data, flags, comment))
        elif btype == BLOCK_SPB:
            orig = struct.unpack_from(endian + "I", buf, body)[0]
            records.append(Record(len(records), section_base, None,
                                  bytes(buf[body + 4:body + 4 + orig]), 0, ""))
        off += blen
    return interfaces, records


# --- FDL ---------------------------------------------------------------------------------------

# Request function codes (FC bit 6 set) that expect a reply.
REQ_WITH_REPLY = {0x3, 0x5, 0x9, 0xC, 0xD, 0xE, 0xF}


class Telegram:
    __slots__ = ("kind", "da", "sa", "fc")

    def __init__(self, kind, da=None, sa=None, fc=None):
        self.kind = kind  # "SD1", "SD2", "SD3", "SD4", "SC"
        self.da = da
        self.sa = sa
        self.fc = fc

    @property
    def is_request(self):
        return self.fc is not None and bool(self.fc & 0x40)

    @property
    def is_response(self):
        return self.kind == "SC" or (self.fc is not None and not self.fc & 0x40)

    @property
    def expects_reply(self):
        return self.is_request and (self.fc & 0x0F) in REQ_WITH_REPLY


def fcs_ok(octets, fcs):
    return sum(octets) & 0xFF == fcs


def decode(b):
    """A Telegram, or None if the octets are not one intact FDL frame."""
    if not b:
        return None
    sd = b[0]
    if sd == 0xE5:
        return Telegram("SC") if len(b) == 1 else None
    if sd == 0xDC:
        return Telegram("SD4", b[1] & 0x7F, b[2] & 0x7F) if len(b) == 3 else None
    if sd == 0x10:
        if len(b) != 6 or b[5] != 0x16 or not fcs_ok(b[1:4], b[4]):
            return None
        return Telegram("SD1", b[1] & 0x7F, b[2] & 0x7F, b[3])
    if sd == 0xA2:
        if len(b) != 14 or b[13] != 0x16 or not fcs_ok(b[1:12], b[12]):
            return None
        return Telegram("SD3", b[1] & 0x7F, b[2] & 0x7F, b[3])
    if sd == 0x68:
        if len(b) < 9:
            return None
        le = b[1]
        if b[2] != le or b[3] != 0x68 or le < 3 or le > 249 or len(b) != le + 6:
            return None
        if b[-1] != 0x16 or not fcs_ok(b[4:4 + le], b[4 + le]):
            return None
        return Telegram("SD2", b[4] & 0x7F, b[5] & 0x7F, b[6])
    return None


# --- the checks --------------------------------------------------------------------------------


def parse_window(text):
    a, b = text.split(":")
    return (int(Fraction(a) * NS), int(Fraction(b) * NS))


def parse_station_window(text):
    addr, win = text.split("@")
    return int(addr), parse_window(win)


def in_any(t, windows):
    return any(a <= t < b for a, b in windows)


def sec(ns):
    return "%.6f" % (ns / NS)


class Frame:
    __slots__ = ("rec", "start", "end", "tel", "flags")

    def __init__(self, rec, start, end, tel):
        self.rec = rec
        self.start = start
        self.end = end
        self.tel = tel
        self.flags = rec.flags


def analyse(itf, recs, args, allow):
    baud = itf.speed
    if not baud:
        raise PcapngError("interface %s has no if_speed" % itf.name)

    def bits(ns):  # nearest whole bit time (timestamps are rounded down to ns)
        return int(round(Fraction(ns * baud, NS)))

    def dur(n):  # n octets of 11 bits
        return n * 11 * NS // baud

    frames = [Frame(r, r.ts, r.ts + dur(len(r.data)), decode(r.data)) for r in recs]
    rep = {"interface": itf.name, "description": itf.description, "baud": baud,
           "frames": len(frames)}
    out_of_order = [f for p, f in zip(frames, frames[1:]) if f.start < p.start]
    rep["out_of_order"] = [{"t": sec(f.start), "record": f.rec.index} for f in out_of_order]

    # Collisions: overlap with earlier activity, or error flags.
    overlaps, flagged = [], []
    busy_until = None
    for f in frames:
        if busy_until is not None and f.start < busy_until:
            overlaps.append(f)
        busy_until = f.end if busy_until is None else max(busy_until, f.end)
        if f.flags & 0xFFFF0000:
            flagged.append(f)
    rep["overlaps"] = [{"t": sec(f.start), "allowed": in_any(f.start, allow)} for f in overlaps]
    rep["flagged"] = [{"t": sec(f.start), "flags": "0x%08x" % f.flags, "comment": f.rec.comment,
                       "allowed": in_any(f.start, allow)} for f in flagged]
    overlapping = set(id(f) for f in overlaps)

    # Timing.
    timing = []
    live = {}
    busy_until = None
    prev = None
    for f in frames:
        idle = None if busy_until is None else f.start - busy_until
        t = f.tel
        is_reply = (prev is not None and prev.tel is not None and prev.tel.expects_reply and
                    t is not None and t.is_response and
                    (t.kind == "SC" or (t.da == prev.tel.sa and t.sa == prev.tel.da)))
        if t is not None and f.flags == 0 and idle is not None and id(f) not in overlapping:
            b = bits(idle)
            problem = None
            if is_reply:
                if b < args.min_tsdr:
                    problem = "response after %d bit times of idle (< min TSDR %d)" % (b, args.min_tsdr)
                elif b > args.tsl:
                    problem = "response %d bit times after its request (> TSL %d)" % (b, args.tsl)
            elif b < TSYN:
                problem = "%s after %d bit times of idle (< TSYN %d)" % (t.kind, b, TSYN)
            if problem:
                timing.append({"t": sec(f.start), "problem": problem,
                               "allowed": in_any(f.start, allow)})
        if t is not None and f.flags == 0:
            who = t.sa if t.kind != "SC" else (prev.tel.da if is_reply else None)
            if who is not None:
                e = live.setdefault(who, [f.start, f.start, 0])
                e[1] = f.start
                e[2] += 1
        busy_until = f.end if busy_until is None else max(busy_until, f.end)
        prev = f
    rep["timing"] = timing
    rep["live"] = {str(a): {"first": sec(v[0]), "last": sec(v[1]), "frames": v[2]}
                   for a, v in sorted(live.items())}

    # Tokens.
    tokens, conflicts, claims = [], [], []
    holder, last_pass, heard_since_pass = None, None, True
    busy_until = None
    for f in frames:
        idle = None if busy_until is None else f.start - busy_until
        busy_until = f.end if busy_until is None else max(busy_until, f.end)
        t = f.tel
        if t is None or t.kind != "SD4" or f.flags != 0:
            if last_pass is not None:
                heard_since_pass = True
            continue
        sa, da = t.sa, t.da
        tto = 6 * args.tsl + 2 * sa * args.tsl
        if holder is None:
            kind = "first"
        elif sa == da and idle is not None and bits(idle) >= tto:
            # Before "pass": a lone master's token to itself (n>n) is a claim too when it
            # follows TTO(n) of silence (the ring was lost, e.g. a master module that took over
            # the address of one that failed); a working holder never leaves the line idle
            # that long (TTO is what makes every other master claim).
            kind = "claim"
            claims.append({"t": sec(f.start), "token": "%d>%d" % (sa, da), "idle_bits": bits(idle)})
        elif sa == holder:
            kind = "pass"
        elif last_pass is not None and sa == last_pass[0] and not heard_since_pass:
            kind = "retry" if da == last_pass[1] else "next"
        else:
            kind = "conflict"
        tokens.append((f.start, sa, da, kind))
        if kind == "conflict":
            conflicts.append({"t": sec(f.start), "token": "%d>%d" % (sa, da),
                              "holder": holder, "allowed": in_any(f.start, allow)})
        holder, last_pass, heard_since_pass = da, (sa, da), False
    rep["token_conflicts"] = conflicts
    rep["claims"] = claims
    rep["token_kinds"] = {}
    for _, _, _, k in tokens:
        rep["token_kinds"][k] = rep["token_kinds"].get(k, 0) + 1

    # Ring membership per window.
    step = int(Fraction(args.window) * NS)
    windows = {}
    for start, sa, da, _ in tokens:
        windows.setdefault(start // step, set()).add((sa, da))
    rep["membership"] = [{"from": sec(k * step), "to": sec((k + 1) * step),
                          "passes": ["%d>%d" % p for p in sorted(v)]}
                         for k, v in sorted(windows.items())]
    return rep, tokens, frames


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("file")
    ap.add_argument("--interface", help="interface name (default: the first USER0 interface)")
    ap.add_argument("--tsl", type=int, default=300, help="slot time in bit times (default 300)")
    ap.add_argument("--min-tsdr", type=int, default=11, help="min TSDR in bit times (default 11)")
    ap.add_argument("--window", default="0.1", help="membership window in s (default 0.1)")
    ap.add_argument("--allow", action="append", default=[], metavar="T0:T1",
                    help="window (s) around a ring change where collisions, damaged frames, "
                         "timing violations and token conflicts are reported but tolerated")
    ap.add_argument("--expect-clean", action="store_true",
                    help="outside --allow windows: no collision, no damaged frame, no timing "
                         "violation, no token conflict; nowhere: records out of order")
    ap.add_argument("--expect-live", help="comma-separated addresses: the live list must be this")
    ap.add_argument("--expect-silent", action="append", default=[], metavar="ADDR@T0:T1",
                    help="no frame from ADDR in the window")
    ap.add_argument("--expect-no-token-to", action="append", default=[], metavar="ADDR@T0:T1",
                    help="no token frame to ADDR from another station in the window")
    ap.add_argument("--expect-token-to", action="append", default=[], metavar="ADDR@T0:T1",
                    help="at least one token frame to ADDR from another station in the window")
    ap.add_argument("--expect-rotation-at-most", action="append", default=[],
                    metavar="ADDR@T0:T1=BITS",
                    help="successive tokens to ADDR (from others) in the window are at most BITS "
                         "bit times apart")
    ap.add_argument("--json", action="store_true", help="print the report as JSON")
    args = ap.parse_args()

    try:
        interfaces, records = read_pcapng(args.file)
    except (OSError, PcapngError, struct.error) as e:
        print("check_capture: %s: %s" % (args.file, e), file=sys.stderr)
        return 2
    candidates = [i for i, itf in enumerate(interfaces)
                  if itf.link_type in (LINKTYPE_USER0, LINKTYPE_PROFIBUS_DL) and
                  (args.interface is None or itf.name == args.interface)]
    if not candidates:
        print("check_capture: %s: no FDL interface %s" % (args.file, args.interface or ""),
              file=sys.stderr)
        return 2
    ix = candidates[0]
    allow = [parse_window(w) for w in args.allow]
    try:
        rep, tokens, frames = analyse(interfaces[ix], [r for r in records if r.iface == ix],
                                      args, allow)
    except PcapngError as e:
        print("check_capture: %s: %s" % (args.file, e), file=sys.stderr)
        return 2

    failures = []
    if args.expect_clean:
        if rep["out_of_order"]:
            failures.append("%d records out of time order, first at %s s" %
                            (len(rep["out_of_order"]), rep["out_of_order"][0]["t"]))
        for key, what in (("overlaps", "overlapping frames (collision)"),
                          ("flagged", "damaged frames"), ("timing", "timing violations"),
                          ("token_conflicts", "token-holder conflicts")):
            bad = [x for x in rep[key] if not x["allowed"]]
            if bad:
                failures.append("%d %s outside the allowed windows, first at %s s" %
                                (len(bad), what, bad[0]["t"]))
    if args.expect_live is not None:
        want = sorted(int(a) for a in args.expect_live.split(",") if a)
        got = sorted(int(a) for a in rep["live"])
        if got != want:
            failures.append("live list %s, expected %s (phantoms %s, missing %s)" %
                            (got, want, sorted(set(got) - set(want)), sorted(set(want) - set(got))))
    for spec in args.expect_silent:
        addr, (a, b) = parse_station_window(spec)
        heard = [f for f in frames if a <= f.start < b and f.tel is not None and f.flags == 0 and
                 f.tel.kind != "SC" and f.tel.sa == addr]
        if heard:
            failures.append("station %d sent %d frames in %s, first at %s s" %
                            (addr, len(heard), spec.split("@")[1], sec(heard[0].start)))
    for spec in args.expect_no_token_to:
        addr, (a, b) = parse_station_window(spec)
        got = [t for t in tokens if a <= t[0] < b and t[2] == addr and t[1] != addr]
        if got:
            failures.append("%d tokens to %d in %s, first %d>%d at %s s" %
                            (len(got), addr, spec.split("@")[1], got[0][1], got[0][2],
                             sec(got[0][0])))
    for spec in args.expect_token_to:
        addr, (a, b) = parse_station_window(spec)
        if not any(a <= t[0] < b and t[2] == addr and t[1] != addr for t in tokens):
            failures.append("no token to %d in %s" % (addr, spec.split("@")[1]))
    for spec in args.expect_rotation_at_most:
        station, limit = spec.split("=")
        addr, (a, b) = parse_station_window(station)
        times = [t[0] for t in tokens if a <= t[0] < b and t[2] == addr and t[1] != addr]
        gaps = [int(round(Fraction((y - x) * rep["baud"], NS))) for x, y in zip(times, times[1:])]
        if not gaps:
            failures.append("fewer than two tokens to %d in %s" % (addr, station.split("@")[1]))
        elif max(gaps) > int(limit):
            failures.append("tokens to %d up to %d bit times apart in %s (more than %s)" %
                            (addr, max(gaps), station.split("@")[1], limit))
    rep["failures"] = failures

    if args.json:
        json.dump(rep, sys.stdout, indent=1)
        print()
    else:
        print("interface %s (%s), %d bit/s: %d frames" %
              (rep["interface"], rep["description"], rep["baud"], rep["frames"]))
        print("records out of time order: %d" % len(rep["out_of_order"]))
        for key, what in (("overlaps", "collisions (overlapping frames)"),
                          ("flagged", "damaged frames (epb_flags)"),
                          ("timing", "timing violations"),
                          ("token_conflicts", "token-holder conflicts")):
            items = rep[key]
            allowed = sum(1 for x in items if x["allowed"])
            print("%s: %d (%d in allowed windows)" % (what, len(items), allowed))
            for x in items[:20]:
                print("  %s s %s" % (x["t"], ", ".join("%s=%s" % (k, v) for k, v in x.items()
                                                      if k not in ("t", "allowed"))))
        print("live list: %s" % ", ".join(rep["live"].keys()))
        for a, v in rep["live"].items():
            print("  %3s: %6d frames, %s s .. %s s" % (a, v["frames"], v["first"], v["last"]))
        print("tokens: %s" % ", ".join("%s %d" % kv for kv in sorted(rep["token_kinds"].items())))
        print("token passes per %s s:" % args.window)
        for w in rep["membership"]:
            print("  %s .. %s s: %s" % (w["from"], w["to"], " ".join(w["passes"])))
        for f in failures:
            print("FAILED: %s" % f)
        print("OK" if not failures else "%d expectations failed" % len(failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
