"""An FDL active station (a master in the token ring) in wall time, for a program behind a pty.

Written from protocol-facts.md §B and §C and the behaviour of pbvbus's ActiveStation described in
docs/fdl-stations.md (which decides how a new master is admitted), not from the C++ code.

The station talks to a link with three calls: send(octets), read(deadline) -> one telegram's
octets or None at the deadline, now() -> seconds (monotonic). It keeps no bus timing of its own:
behind a pbvbus serial attachment with `timing: INTERFACE` the attachment holds requests and
tokens until the line has been idle TSYN and the previous reply or slot time is over.

What it does:
  - Ring entry (§C.4, §C.5): a Request FDL Status (FC 0x49) addressed to it is answered
    "master ready to enter the ring" (`10 SA TS 20 FCS 16`): the poller is about to make it its
    NS, as pbvbus's ActiveStation does when polled by a master of its LAS. A token `DC TS x`
    is accepted from anyone (x becomes PS).
  - Its NS: at the first token the only station it knows to be in the ring is PS, so NS = PS,
    and it scans its GAP (the addresses after its own up to NS, cyclic, wrapping after HSA to 0,
    HSA itself polled) with Request FDL Status, `scan_per_visit` addresses per visit; the first
    that answers "ready" (0x20) or "in the ring" (0x30) becomes NS (and gets the token at the
    end of this visit). Later scans: one address per visit, a new scan `gap_factor` visits
    after the last (§C.5).
  - Per token visit at most `per_visit` request cycles (SRD high, FCB/FCV per responder: first
    frame FCV=0 FCB=1, then FCV=1 with FCB toggled after every valid reply; a retry repeats the
    frame unchanged; after the retries the responder is non-operational and the next frame is a
    first frame again, §C.6), then the token pass `DC NS TS`. Any frame within the token
    timeout after the token counts as NS's activity (the attachment forwards the first frame
    after the program's telegram within the slot time); three attempts in total (§C.4), then NS
    is dropped and found again at the next token.
  - Requests addressed to it (not holding the token): SRD/SDA with SAPs go to the user, who
    accepts (SC E5) or refuses (SD1 with status RS); a repeat (FCV=1 and the same FCB as that
    SA's previous frame) gets the stored reply again and does not reach the user (§C.6).
    SDN is given to the user without a reply. Ident and LSAP status are refused (RS).
  - A foreign request or token heard while it holds the token means the token is lost (a second
    token on the line, §C.4): the visit ends at once, the frame is handled as usual. A request
    whose reply was awaited then goes again, the same frame (same FCB), at the next token.
"""

from collections import deque

import fdl_frames as F


class TokenLost(Exception):
    pass


class Request:
    """What the user asks the station to send while it holds the token."""

    def __init__(self, da, dsap, ssap, du, tag=None, fn=F.FN_SRD_HIGH):
        self.da, self.dsap, self.ssap, self.du, self.tag, self.fn = da, dsap, ssap, du, tag, fn


class ActiveStation:
    def __init__(self, link, address, user, hsa=31, reply_timeout=0.5, token_timeout=None,
                 retries=1, token_attempts=3, gap_factor=10, per_visit=1, scan_per_visit=4,
                 log=None, trace=None):
        if not 0 <= address <= 126:
            raise ValueError("station address %d is not 0..126" % address)
        self.link, self.ts, self.user = link, address, user
        self.hsa, self.reply_timeout, self.retries = hsa, reply_timeout, retries
        self.token_timeout = reply_timeout if token_timeout is None else token_timeout
        self.token_attempts, self.gap_factor, self.per_visit = token_attempts, gap_factor, per_visit
        self.log = log or (lambda msg: None)
        self.trace = trace  # called with every telegram in ("<") and out (">")
        self.in_ring = False
        self.ps = None
        self.ns = None
        self.live = {}            # address -> station type answered (0x00/0x10/0x20/0x30)
        self.fcb = {}             # responder -> FCB of our last frame that got a valid reply
        self.memory = {}          # initiator SA -> (its last FCB, our reply octets)
        self.pending = deque()    # telegrams read while waiting, to be handled by the main loop
        self.interrupted = None   # (request, frame, FCB, next attempt) cut short by a lost token
        self.gap_next = None
        self.gap_wait = 0
        self.scanning = False
        self.scan_per_visit = scan_per_visit
        self.count = {"frames_sent": 0, "frames_received": 0, "invalid_frames": 0,
                      "requests_sent": 0, "retries": 0, "no_answer": 0, "refused": 0,
                      "token_visits": 0, "tokens_passed": 0, "token_pass_retries": 0,
                      "token_losses": 0, "gap_polls": 0, "fdl_status_answered": 0,
                      "requests_answered": 0, "repeats_answered": 0}

    # --- link ---------------------------------------------------------------------------------

    def send(self, frame):
        self.count["frames_sent"] += 1
        if self.trace:
            self.trace("> " + frame.hex(" ").upper())
        self.link.send(frame)

    def next_frame(self, deadline):
        """A telegram from the pending queue or the link, decoded; None at the deadline."""
        while True:
            again = bool(self.pending)
            raw = self.pending.popleft() if again else self.link.read(deadline)
            if raw is None:
                return None
            if self.trace and not again:
                self.trace("< " + raw.hex(" ").upper())
            t = F.decode(raw)
            if t is None:
                self.count["invalid_frames"] += 1
                continue
            self.count["frames_received"] += 1
            return t

    # --- the main loop ------------------------------------------------------------------------

    def run_until(self, finished, deadline, on_idle=None):
        """Handles frames until finished() (checked after each) or the deadline; True if finished."""
        while not finished():
            now = self.link.now()
            if now >= deadline:
                return False
            t = self.next_frame(min(deadline, now + 0.1))
            if t is not None:
                self.handle(t)
            if on_idle is not None:
                on_idle(self.link.now())
        return True

    def handle(self, t):
        if t.is_token:
            if t.da == self.ts:
                self.use_token(t.sa)
            return
        if t.is_request and t.da in (self.ts, F.BROADCAST):
            self.answer(t)
        # Anything else (a late reply, others' traffic) is not for us.

    # --- responder ----------------------------------------------------------------------------

    def my_type(self):
        return F.TYPE_IN_RING if self.in_ring else F.TYPE_READY

    def answer(self, t):
        broadcast = t.da == F.BROADCAST
        if t.fn == F.FN_FDL_STATUS:
            if broadcast:
                return
            # The poller makes us its NS next (docs/fdl-stations.md, §C.5): "ready".
            self.in_ring = False
            self.send(F.encode(t.sa, self.ts, F.TYPE_READY | F.ST_OK))
            self.count["fdl_status_answered"] += 1
            return
        reply_expected = t.fn in F.EXPECTS_REPLY and not broadcast
        if reply_expected and t.fn in F.USES_FCB and t.fcv:
            last = self.memory.get(t.sa)
            if last is not None and last[0] == t.fcb:
                self.send(last[1])
                self.count["repeats_answered"] += 1
                return
        if t.fn in (F.FN_IDENT, F.FN_LSAP_STATUS) or t.dsap is None or t.ssap is None:
            accepted = False
        else:
            accepted = self.user.on_indication(t.sa, t.dsap, t.ssap, t.data)
        if not reply_expected:
            return
        reply = bytes([F.SC]) if accepted else F.encode(t.sa, self.ts, self.my_type() | F.ST_RS)
        if t.fn in F.USES_FCB:
            self.memory[t.sa] = (t.fcb, reply)
        self.send(reply)
        self.count["requests_answered"] += 1

    # --- holding the token --------------------------------------------------------------------

    def await_reply(self, da):
        """The reply to our request to da, or None (no valid reply within the timeout).
        Raises TokenLost when someone else sends a request or a token meanwhile."""
        deadline = self.link.now() + self.reply_timeout
        while True:
            t = self.next_frame(deadline)
            if t is None:
                return None
            if t.kind == "SC":
                return t
            if t.is_response and t.da == self.ts and t.sa == da:
                return t
            if t.is_token or t.is_request:
                self.pending.appendleft(t.raw)
                raise TokenLost()

    def transaction(self, req):
        """One request cycle with retries: ("delivered"|"refused", reply) or ("no_answer", None).

        A request cut short by a lost token is kept with its frame (self.interrupted) and sent
        again, unchanged, as the first thing at the next token: the responder may have taken
        it, and only the same FCB lets it tell a repeat from a new frame (§C.6)."""
        uses_fcb = req.fn in F.USES_FCB
        if self.interrupted is not None and self.interrupted[0] is req:
            _, frame, fcb, first_attempt = self.interrupted
            self.interrupted = None
        else:
            last = self.fcb.get(req.da)
            fcv, fcb = (False, True) if last is None else (True, not last)
            fc = F.request_fc(req.fn, fcv, fcb) if uses_fcb else F.request_fc(req.fn)
            frame = F.encode(req.da, self.ts, fc, req.dsap, req.ssap, req.du)
            self.count["requests_sent"] += 1
            first_attempt = 0
        for attempt in range(first_attempt, 1 + self.retries):
            if attempt:
                self.count["retries"] += 1
            self.send(frame)
            try:
                r = self.await_reply(req.da)
            except TokenLost:
                self.interrupted = (req, frame, fcb, min(attempt + 1, self.retries))
                raise
            if r is None:
                continue
            if uses_fcb:
                self.fcb[req.da] = fcb
            if r.status in (F.ST_OK, F.ST_DL, F.ST_DH, F.ST_NR):
                return "delivered", r
            self.count["refused"] += 1
            return "refused", r
        self.count["no_answer"] += 1
        self.fcb.pop(req.da, None)  # non-operational: the next frame is a first frame
        return "no_answer", None

    def fdl_status(self, a):
        """Request FDL Status to a (one attempt): the station type it answers, or None."""
        self.count["gap_polls"] += 1
        self.send(F.encode(a, self.ts, F.request_fc(F.FN_FDL_STATUS)))
        r = self.await_reply(a)
        if r is None or r.kind == "SC":
            self.live.pop(a, None)
            return None
        self.live[a] = r.station_type
        return r.station_type

    def after(self, a):
        """The address polled after a: ascending, after HSA comes 0 (§C.5)."""
        return 0 if a >= self.hsa else a + 1

    def in_gap(self, a):
        """Whether a lies between TS and NS (exclusive), within 0..HSA."""
        if self.ns is None or a == self.ts or a > self.hsa:
            return False
        return (a - self.ts) % 128 < (self.ns - self.ts) % 128

    def gap_poll(self):
        """GAP polls (§C.5): the first scan after entering the ring (NS unknown, PS taken for it)
        asks up to scan_per_visit addresses per visit, later scans one per visit, a new scan
        gap_factor visits after the last. A station answering "ready" (0x20) or "in the ring"
        (0x30) lies between us and NS in the ring: it becomes NS."""
        if self.gap_wait > 0:
            self.gap_wait -= 1
            return
        for _ in range(self.scan_per_visit if self.scanning else 1):
            if self.gap_next is None:
                self.gap_next = self.after(self.ts)
            if not self.in_gap(self.gap_next):
                self.scanning = False
                self.gap_wait = self.gap_factor
                self.gap_next = self.after(self.ts)
                return
            a = self.gap_next
            self.gap_next = self.after(a)
            if self.fdl_status(a) in (F.TYPE_READY, F.TYPE_IN_RING):
                self.log("station %d answered the GAP poll: it is NS now" % a)
                self.ns = a
                return

    def use_token(self, sender):
        self.count["token_visits"] += 1
        self.ps = sender
        self.in_ring = True
        try:
            if self.ns is None:
                # The only station known to be in the ring is PS; the scan finds what lies
                # between us and it.
                self.ns = sender
                self.gap_next = self.after(self.ts)
                self.gap_wait = 0
                self.scanning = True
            for _ in range(self.per_visit):
                req = self.interrupted[0] if self.interrupted else self.user.next_request()
                if req is None:
                    break
                result, reply = self.transaction(req)
                self.user.on_result(req, result, reply)
            if not self.user.finished():
                self.gap_poll()
            self.pass_token()
        except TokenLost:
            self.count["token_losses"] += 1
            self.in_ring = False
            self.log("token lost: a foreign frame while holding it")

    def pass_token(self):
        for attempt in range(self.token_attempts):
            if attempt:
                self.count["token_pass_retries"] += 1
            self.send(F.encode_token(self.ns, self.ts))
            t = self.next_frame(self.link.now() + self.token_timeout)
            if t is not None:
                self.count["tokens_passed"] += 1
                self.pending.appendleft(t.raw)
                self.count["frames_received"] -= 1  # counted again when handled
                return True
        self.log("token pass to %d failed %d times: NS dropped" % (self.ns, self.token_attempts))
        self.live.pop(self.ns, None)
        self.ns = None
        self.in_ring = False
        return False
