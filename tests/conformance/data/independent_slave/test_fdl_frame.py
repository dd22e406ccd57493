"""Framing, FCS and resynchronisation tests. Golden bytes from protocol-facts.md Appendix 1."""

import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from fdl_frame import Deframer, encode, fcs  # noqa: E402


def h(s):
    return bytes.fromhex(s)


class FcsAndEncode(unittest.TestCase):
    def test_fcs_of_published_traces(self):
        # S11 trace: 68 05 05 68 8A 81 6D 3C 3E F2 16
        self.assertEqual(fcs(h("8A 81 6D 3C 3E")), 0xF2)
        # S4 trace: 10 05 02 49 50 16
        self.assertEqual(fcs(h("05 02 49")), 0x50)

    def test_sd1(self):
        self.assertEqual(encode(0x03, 0x01, 0x49), h("10 03 01 49 4D 16"))
        self.assertEqual(encode(0x01, 0x03, 0x00), h("10 01 03 00 04 16"))
        self.assertEqual(encode(0x01, 0x05, 0x30), h("10 01 05 30 36 16"))

    def test_sd2(self):
        self.assertEqual(encode(0x8A, 0x81, 0x6D, h("3C 3E")), h("68 05 05 68 8A 81 6D 3C 3E F2 16"))
        self.assertEqual(encode(0x0A, 0x01, 0x5D, h("AA 55")), h("68 05 05 68 0A 01 5D AA 55 67 16"))
        self.assertEqual(encode(0x01, 0x0A, 0x08, h("3C")), h("68 04 04 68 01 0A 08 3C 4F 16"))
        self.assertEqual(encode(0xFF, 0x81, 0x46, h("3A 3E 02 00")),
                         h("68 07 07 68 FF 81 46 3A 3E 02 00 40 16"))
        self.assertEqual(encode(0x8A, 0x81, 0x5D, h("3D 3E 88 0A 0A 0B 12 34 00")),
                         h("68 0C 0C 68 8A 81 5D 3D 3E 88 0A 0A 0B 12 34 00 D0 16"))

    def test_sd3_when_du_is_8(self):
        self.assertEqual(encode(0x81, 0x8A, 0x08, h("3E 3C 02 05 00 FF 12 34")),
                         h("A2 81 8A 08 3E 3C 02 05 00 FF 12 34 D9 16"))
        self.assertEqual(encode(0x0A, 0x01, 0x7D, h("01 02 03 04 05 06 07 08")),
                         h("A2 0A 01 7D 01 02 03 04 05 06 07 08 AC 16"))

    def test_too_long(self):
        with self.assertRaises(ValueError):
            encode(1, 2, 0x08, bytes(247))


class Deframing(unittest.TestCase):
    def kinds(self, tels):
        return [t.kind for t in tels]

    def test_each_kind(self):
        d = Deframer()
        stream = h("10 03 01 49 4D 16  DC 05 02  E5  68 05 05 68 8A 81 6D 3C 3E F2 16"
                   "  A2 0A 01 7D 01 02 03 04 05 06 07 08 AC 16")
        tels = d.feed(stream)
        self.assertEqual(self.kinds(tels), ["SD1", "SD4", "SC", "SD2", "SD3"])
        self.assertEqual(tels[3].da, 0x8A)
        self.assertEqual(tels[3].sa, 0x81)
        self.assertEqual(tels[3].fc, 0x6D)
        self.assertEqual(tels[3].data, h("3C 3E"))
        self.assertEqual(tels[4].data, h("01 02 03 04 05 06 07 08"))
        self.assertEqual(d.junk, 0)
        self.assertFalse(d.pending())

    def test_split_octet_by_octet(self):
        d = Deframer()
        out = []
        for b in h("68 05 05 68 8A 81 6D 3C 3E F2 16"):
            out += d.feed(bytes([b]))
        self.assertEqual(self.kinds(out), ["SD2"])

    def test_junk_before_and_between(self):
        d = Deframer()
        tels = d.feed(h("00 FF 12 10 03 01 49 4D 16 77 68 99 10 03 01 49 4D 16"))
        self.assertEqual(self.kinds(tels), ["SD1", "SD1"])
        self.assertEqual(d.junk, 6)

    def test_bad_fcs_and_bad_ed(self):
        d = Deframer()
        self.assertEqual(d.feed(h("10 03 01 49 4E 16")), [])      # FCS wrong
        self.assertEqual(d.feed(h("10 03 01 49 4D 17")), [])      # ED wrong
        self.assertFalse(d.pending())
        self.assertEqual(self.kinds(d.feed(h("10 03 01 49 4D 16"))), ["SD1"])

    def test_le_mismatch_and_range(self):
        d = Deframer()
        self.assertEqual(d.feed(h("68 05 06 68")), [])
        self.assertEqual(d.feed(h("68 02 02 68")), [])            # LE below 3
        self.assertEqual(d.feed(h("68 FA FA 68")), [])            # LE above 249
        # the last 68 may still start a telegram: only that octet waits
        self.assertEqual(bytes(d.buf), h("68"))
        self.assertEqual(self.kinds(d.feed(h("05 05 68 8A 81 6D 3C 3E F2 16"))), ["SD2"])

    def test_truncated_long_candidate_then_good_frame(self):
        # a broken SD2 header claiming 0x40 octets, then a complete request: the request
        # is recognised at once, without waiting for the gap timer
        d = Deframer()
        tels = d.feed(h("68 40 40 68 8A 81") + h("10 03 01 49 4D 16"))
        self.assertEqual(self.kinds(tels), ["SD1"])

    def test_truncated_telegram_dropped_on_gap(self):
        d = Deframer()
        self.assertEqual(d.feed(h("68 05 05 68 8A 81")), [])
        self.assertTrue(d.pending())
        self.assertEqual(d.flush_stale(), [])
        self.assertFalse(d.pending())
        self.assertEqual(self.kinds(d.feed(h("10 03 01 49 4D 16"))), ["SD1"])

    def test_junk_token_delimiter_does_not_eat_a_frame(self):
        d = Deframer()
        tels = d.feed(h("DC 10 03 01 49 4D 16"))
        self.assertEqual(self.kinds(tels), ["SD1"])

    def test_sd4_with_ext_bit_is_junk(self):
        d = Deframer()
        self.assertEqual(d.feed(h("DC 85 02")), [])
        self.assertFalse(d.pending())

    def test_random_noise_never_raises(self):
        import random
        rnd = random.Random(7)
        d = Deframer()
        good = h("68 05 05 68 8A 81 6D 3C 3E F2 16")
        seen = 0
        for _ in range(300):
            noise = bytes(rnd.randrange(256) for _ in range(rnd.randrange(0, 20)))
            seen += sum(1 for t in d.feed(noise) if t.raw == good)
            d.flush_stale()                       # a gap after the noise
            seen += sum(1 for t in d.feed(good) if t.raw == good)
        self.assertGreaterEqual(seen, 300)


if __name__ == "__main__":
    unittest.main()
