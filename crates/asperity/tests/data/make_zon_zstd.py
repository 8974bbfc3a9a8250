"""Writes zon-heights-64x48.zst: the height member of a Keyence ZON file (the layout of
SurfaceTopography's ZON.py: width, height, element size, row bytes as little-endian i32,
then the rows of i32 counts, here padded by 8 bytes each) compressed by the reference
`zstd` command-line tool (v1.5.4, level 19), as a KPK1 file holds it. The counts are
((37 x + 3 y^2) mod 1000) - 500; zon.rs's test computes the same numbers.

Run from this folder: python3 make_zon_zstd.py (needs the `zstd` program).
"""

import struct
import subprocess

W, H = 64, 48
data = struct.pack("<4i", W, H, 4, 4 * W + 8)
for y in range(H):
    row = [((37 * x + 3 * y * y) % 1000) - 500 for x in range(W)]
    data += struct.pack(f"<{W}i", *row) + b"\xab" * 8
subprocess.run(
    ["zstd", "-q", "-f", "-19", "-", "-o", "zon-heights-64x48.zst"],
    input=data,
    check=True,
)
