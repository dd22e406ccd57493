"""End-to-end test of dp_slave.py as a program: a pty, junk on the line, the wall-clock
watchdog scaled by --speed, waiting for the port to appear. Takes about 2 s."""

import os
import select
import subprocess
import sys
import tempfile
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from fdl_frame import Deframer, encode  # noqa: E402


def h(s):
    return bytes.fromhex(s)


class Program(unittest.TestCase):
    def setUp(self):
        self.master, self.slave = os.openpty()   # keep the slave side open, as pbvbus does
        import tty
        tty.setraw(self.master)
        self.dir = tempfile.TemporaryDirectory()
        self.link = os.path.join(self.dir.name, "pty")
        self.logfile = os.path.join(self.dir.name, "log")
        self.proc = subprocess.Popen(
            ["/usr/bin/python3", os.path.join(HERE, "dp_slave.py"), "--port", self.link,
             "--address", "5", "--baud", "9600", "--speed", "1/2", "--wait-port", "5",
             "--log", self.logfile, "--trace"],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        time.sleep(0.3)                            # the program waits for the path
        os.symlink(os.ttyname(self.slave), self.link)
        time.sleep(0.4)                            # let it open and flush
        self.fcb = 0      # after the first frame (6D) the next FCB is 0

    def tearDown(self):
        self.proc.terminate()
        try:
            self.proc.wait(5)
        finally:
            self.proc.stderr.close()
            os.close(self.master)
            os.close(self.slave)
            self.dir.cleanup()

    def exchange(self, frame, wait=1.0):
        os.write(self.master, frame)
        d = Deframer()
        end = time.monotonic() + wait
        while time.monotonic() < end:
            r, _, _ = select.select([self.master], [], [], end - time.monotonic())
            if r:
                tels = d.feed(os.read(self.master, 1024))
                if tels:
                    return tels[0].raw
        return None

    def srd(self, dsap, du=b""):
        fc = 0x5D if self.fcb == 0 else 0x7D
        self.fcb ^= 1
        return self.exchange(encode(0x85, 0x81, fc, bytes([dsap, 0x3E]) + du))

    def test_program(self):
        # junk, then an FDL status request in the same write
        self.assertEqual(self.exchange(h("00 FF 68 33 10") + h("10 05 01 49 4F 16")),
                         h("10 01 05 00 06 16"))
        # a request to another station and a broken one: no reply
        self.assertIsNone(self.exchange(h("10 06 01 49 50 16"), wait=0.3))
        self.assertIsNone(self.exchange(h("68 05 05 68 85 81 6D 3C 3E 00 16"), wait=0.3))
        # a truncated telegram, silence, then a good one
        os.write(self.master, h("68 05 05 68 85 81"))
        time.sleep(0.15)
        r = self.exchange(h("68 05 05 68 85 81 6D 3C 3E ED 16"))
        self.assertEqual(r, encode(0x81, 0x85, 0x08, h("3E 3C 02 05 00 FF 0A 01")))
        # Set_Prm with WD 1 x 5 x 10 ms = 50 ms virtual = 100 ms wall at --speed 1/2
        self.assertEqual(self.srd(0x3D, h("88 01 05 0B 0A 01 00 00")), h("E5"))
        self.assertEqual(self.srd(0x3E, h("11 21")), h("E5"))
        for _ in range(5):                          # kept alive by Data_Exchange every 30 ms
            time.sleep(0.03)
            r = self.exchange(encode(0x05, 0x01, 0x5D if self.fcb == 0 else 0x7D, h("12 34")))
            self.fcb ^= 1
            self.assertIsNotNone(r)
            self.assertEqual(r[6], 0x08, r.hex(" "))
        self.assertEqual(self.srd(0x3C)[6:12], h("00 0C 00 01 0A 01"))
        time.sleep(0.3)                              # the watchdog expires
        self.assertEqual(self.srd(0x3C)[6:12], h("02 05 00 FF 0A 01"))
        with open(self.logfile) as f:
            self.assertIn("watchdog expired", f.read())


if __name__ == "__main__":
    unittest.main()
