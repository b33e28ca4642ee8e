#!/usr/bin/env python3
"""Writes the lattice_* seeds of corpus/fuzz_integrate (issue 42): oracle-mode cases whose scans
take the sensor onto a cell centre, corner or edge, the heading onto a multiple of pi / 4 and a
sector boundary along it (placeOnLattice in fuzz_integrate.cpp), among them the issue's case:
sensor (0.275, -0.275), theta pi / 4, one beam at -0.0086 rad returning 0.8 m, resolution 0.05.

The bytes are what FuzzedDataProvider (LLVM 14) decodes into the values below, in decode()'s
order: every value is taken from the end of the input, an integer in [min, max] from as many
bytes as the range needs (the first taken the most significant), a double in [lo, hi] from 8
(lo + (hi - lo) k / (2^64 - 1)), a float from 4. Run from anywhere:
    python3 test/fuzz/make_lattice_seeds.py
WAVOG_FUZZ_DESCRIBE=1 build-fuzz/fuzzers/fuzz_integrate <seed> prints what a seed decodes to.
"""
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "corpus", "fuzz_integrate")


class Encoder:
    """The inverse of FuzzedDataProvider for the calls decode() makes."""

    def __init__(self):
        self.taken = []  # bytes in the order they are taken (from the end of the input)

    def integer(self, value, lo, hi, size):
        assert lo <= value <= hi
        span, count = hi - lo, 0
        while count < size and (span >> (8 * count)) > 0:
            count += 1
        k = value - lo
        self.taken += list(k.to_bytes(count, "big")) if count else []

    def boolean(self, value):
        self.integer(1 if value else 0, 0, 255, 1)

    def real(self, value, lo, hi, bits=64):
        top = (1 << bits) - 1
        k = round((value - lo) / (hi - lo) * top)
        self.integer(min(max(k, 0), top), 0, top, bits // 8)

    def data(self):
        return bytes(reversed(self.taken))


INT, SIZE = 4, 8  # sizeof(int), sizeof(std::size_t)
RESOLUTIONS = [0.05, 0.1, 0.2, 0.15]
POLICIES = ["none", "max", "clamp", "forget", "clamp_lower", "clamp_upper"]


def encode(case):
    e = Encoder()
    e.boolean(True)  # oracle
    # decodeParams, oracle branch: policy, init, lazy, reflection, ndt, threads, half-life off.
    e.integer(POLICIES.index(case.get("policy", "clamp")), 0, 5, INT)
    for flag in ("empty_bound", "lazy", "reflection", "ndt", "threads"):
        e.boolean(case.get(flag, False))
    if case.get("ndt", False):
        e.integer(0, 0, 5, SIZE)  # ndt_min_weight 0.01
        e.integer(0, 0, 4, SIZE)  # ndt_max_weight 100
    e.integer(0, 0, 4, INT)  # forget_half_life 0
    e.integer(RESOLUTIONS.index(case["resolution"]), 0, 3, SIZE)
    e.integer(case.get("block_levels", 3), 2, 5, INT)
    e.boolean(False)  # the policy's own odds, gamma and clamps
    band = case.get("band_width", 0.0)
    e.boolean(band == 0.0)
    if band != 0.0:
        e.real(band, 0.0, 0.5)
    e.boolean(True)  # max_range 0
    clear = case.get("no_return_clear", 0.0)
    e.boolean(clear == 0.0)
    if clear != 0.0:
        e.real(clear, 0.0, 3.0)
    scans = case["scans"]
    e.integer(len(scans), 1, 4, INT)
    for s in scans:
        n = len(s["ranges"])
        e.integer(n, 1, 720, SIZE)
        e.real(s["x"], -1.0, 1.0)
        e.real(s["y"], -1.0, 1.0)
        e.real(s["theta"], -7.0, 7.0)
        e.real(s["angle_min"], -7.0, 7.0)
        e.real(abs(s["increment"]) * n, 0.0, 2 * math.pi)  # the field of view
        e.boolean(s["increment"] > 0)
        e.boolean(True)  # range_min 0
        e.real(s.get("range_max", 3.0), 0.1, 3.0)
        e.boolean(True)  # a period from the list: 0
        e.integer(0, 0, 5, SIZE)
        for z in s["ranges"]:
            if z is None:  # NaN (the hostile list's third)
                e.integer(0, 0, 7, INT)
                e.integer(2, 0, 12, SIZE)
            else:
                e.integer(2, 0, 7, INT)
                e.real(z, 0.0, 4.0, bits=32)
    for v in case.get("clear_box", (4.0, 4.0, 4.5, 4.5)):  # min x, min y, max x, max y
        e.real(v, -5.0, 5.0)
    for s in scans:  # placeOnLattice: place (1 centre .. 4), heading (1 eighth, 2 + boundary)
        e.integer(s.get("place", 1), 0, 4, INT)
        if s.get("place", 1) != 0:
            e.integer(s.get("heading", 1), 0, 2, INT)
    return e.data()


def fan(n, angle_min, increment, reach, seed):
    """n ranges between 0.2 and reach, a wall with steps, every seventh NaN."""
    out = []
    for j in range(n):
        if j % 7 == 6:
            out.append(None)
        else:
            out.append(0.2 + (reach - 0.2) * (((j * 37 + seed * 11) % 23) / 23.0))
    return dict(angle_min=angle_min, increment=increment, ranges=out)


def scan(x, y, theta, f, place, heading):
    s = dict(f)
    s.update(x=x, y=y, theta=theta, place=place, heading=heading)
    return s


PI = math.pi
CASES = {
    # The case, under the policies that wrote -0.4 there and a wider fan of one beam.
    "lattice_issue42_clamp": dict(resolution=0.05, policy="clamp", scans=[
        scan(0.27, -0.28, 0.78, dict(angle_min=-0.0086, increment=0.1, ranges=[0.8]), 1, 1)]),
    "lattice_issue42_none_wide": dict(resolution=0.05, policy="none", scans=[
        scan(0.27, -0.28, 0.78, dict(angle_min=-0.0086, increment=1.0, ranges=[0.8]), 1, 1),
        scan(0.27, -0.28, 0.78, dict(angle_min=-0.0086, increment=-0.5, ranges=[0.8]), 1, 1)]),
    # Cell centres, corners and edges, headings on eighths, boundaries along them.
    "lattice_centre_boundary": dict(resolution=0.1, policy="max", block_levels=2, scans=[
        scan(0.33, 0.47, 2.4, fan(90, -1.0, 2 * PI / 90, 2.5, 1), 1, 2),
        scan(-0.61, 0.12, -0.8, fan(45, 0.3, -PI / 45, 2.0, 2), 1, 2)]),
    "lattice_corner_axes": dict(resolution=0.05, policy="forget", block_levels=4, scans=[
        scan(0.51, -0.49, 0.02, fan(64, -PI, 2 * PI / 64, 2.8, 3), 2, 2),
        scan(0.2, 0.2, 1.55, fan(17, -0.4, 0.05, 1.5, 4), 2, 1)]),
    "lattice_edges_band": dict(resolution=0.15, policy="clamp_lower", band_width=0.4,
                               no_return_clear=2.0, scans=[
        scan(0.4, -0.1, 3.9, fan(120, -1.5, PI / 120, 2.9, 5), 3, 2),
        scan(-0.2, 0.7, -2.3, fan(33, 2.0, -0.09, 2.2, 6), 4, 2),
        scan(0.05, 0.05, 0.8, fan(3, -0.3, 0.4, 1.0, 7), 1, 1)]),
    "lattice_centre_payloads": dict(resolution=0.2, policy="clamp_upper", reflection=True,
                                    ndt=True, threads=True, scans=[
        scan(0.9, 0.9, -5.5, fan(200, -2.0, 2 * PI / 200, 3.0, 8), 1, 2),
        scan(0.1, -0.3, 6.3, fan(2, 0.1, 1.3, 0.9, 9), 1, 1)]),
    "lattice_centre_few_beams": dict(resolution=0.05, policy="clamp", block_levels=5, scans=[
        scan(-0.33, 0.71, 5.5, fan(4, 1.0, 0.3, 1.2, 10), 1, 1),
        scan(0.02, 0.02, -3.1, fan(1, 3.0, 2 * PI, 2.0, 11), 1, 1),
        scan(0.66, -0.66, 2.36, fan(2, -0.013, 0.02, 0.9, 12), 1, 1)]),
    # Narrow fans from cell centres that hold sensor bearing 0 but not -theta (the bearing the
    # reference gives the sensor's own cell): before the fix that cell was E, the reference's U.
    "lattice_centre_narrow_fans": dict(resolution=0.1, policy="forget", block_levels=3, scans=[
        scan(0.41, -0.27, 1.6, fan(24, -0.6, 0.05, 2.0, 13), 1, 1),
        scan(-0.52, 0.33, 3.1, fan(90, -PI / 2 + 0.01, PI / 90, 2.5, 14), 1, 1),
        scan(0.07, 0.88, -2.4, fan(40, 0.7, -0.035, 1.8, 15), 1, 1)]),
    "lattice_centre_narrow_max": dict(resolution=0.05, policy="max", block_levels=4, scans=[
        scan(-0.77, -0.12, -1.6, fan(60, -0.25, 0.01, 2.2, 16), 1, 1),
        scan(0.44, 0.61, 0.8, fan(100, -1.0, 0.012, 1.4, 17), 1, 2)]),
}


def main():
    os.makedirs(OUT, exist_ok=True)
    for name, case in sorted(CASES.items()):
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(encode(case))
        print(name)


if __name__ == "__main__":
    main()
