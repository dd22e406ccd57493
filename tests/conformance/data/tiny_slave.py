#!/usr/bin/python3
"""A DP slave program for the battery's pty tests (tests/conformance/battery_pty_test.cpp).

Answers, at FDL address 3 with ident 0x0A01, only what STA-01 needs: the reset Set_Prm with SC
(E5) and Slave_Diag with the unparameterised diagnosis 02 05 00 FF 0A 01. With --broken the
diagnosis lacks Prm_Req (02 04 00 FF 0A 01): the deliberately broken behaviour the battery must
catch. Usage: tiny_slave.py LINK [--broken]; waits up to 10 s for LINK, serves until the pty
closes or 30 s have passed.
"""
import os
import sys
import time

import serial

link = sys.argv[1]
broken = "--broken" in sys.argv[2:]
deadline = time.time() + 10
while not os.path.exists(link):
    if time.time() > deadline:
        sys.exit("no pty at " + link)
    time.sleep(0.01)
port = serial.Serial(link, timeout=0.05)
port.reset_input_buffer()


def frame_len(b):
    if not b:
        return 0
    if b[0] == 0xE5:
        return 1
    if b[0] == 0xDC:
        return 3
    if b[0] == 0x10:
        return 6
    if b[0] == 0xA2:
        return 14
    if b[0] == 0x68:
        return b[1] + 6 if len(b) > 1 else 0
    return -1


def reply(req):
    # SD2 request to 3 with SAPs: 68 LE LE 68 DA SA FC DSAP SSAP ...
    if req[0] != 0x68 or (req[4] & 0x7F) != 3 or not (req[4] & 0x80):
        return None
    master, dsap = req[5] & 0x7F, req[7]
    if dsap == 61:  # Set_Prm
        return bytes([0xE5])
    if dsap == 60:  # Slave_Diag: SD3 A2 DA SA FC DSAP SSAP DU(6) FCS 16
        du = [0x02, 0x04 if broken else 0x05, 0x00, 0xFF, 0x0A, 0x01]
        body = [0x80 | master, 0x83, 0x08, req[8], 60] + du
        return bytes([0xA2] + body + [sum(body) & 0xFF, 0x16])
    return None


buf = b""
end = time.time() + 30
while time.time() < end:
    try:
        chunk = port.read(64)
    except (serial.SerialException, OSError):
        break
    buf += chunk
    while buf:
        n = frame_len(buf)
        if n < 0:
            buf = buf[1:]
            continue
        if n == 0 or len(buf) < n:
            break
        req, buf = buf[:n], buf[n:]
        r = reply(req)
        if r:
            port.write(r)
