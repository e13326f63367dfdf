"""Rasterise datasets/horse_silhouette_2d.obj into an RGBA alpha mask (datasets/horse_mask.png).

Half the resolution of the original 400 x 328 silhouette: pixel (col, row) covers
x in [2 col, 2 col + 2), y = 327 - (2 row + 1) ... (y up in the mesh, rows down in the image).
Standard library only: python3 datasets/tools/horse_mask.py
"""
import struct
import zlib
from pathlib import Path

here = Path(__file__).resolve().parent.parent
V, F = [], []
for line in open(here / "horse_silhouette_2d.obj"):
    p = line.split()
    if p and p[0] == "v":
        V.append((float(p[1]), float(p[2])))
    elif p and p[0] == "f":
        F.append([int(x.split("/")[0]) - 1 for x in p[1:4]])
W, H, S = 200, 164, 2.0
inside = [[False] * W for _ in range(H)]
for a, b, c in F:
    (ax, ay), (bx, by), (cx, cy) = V[a], V[b], V[c]
    d = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    xs, ys = (ax, bx, cx), (ay, by, cy)
    c0, c1 = int(min(xs) / S) - 1, int(max(xs) / S) + 1
    r0, r1 = int((327 - max(ys)) / S) - 1, int((327 - min(ys)) / S) + 1
    for r in range(max(r0, 0), min(r1, H - 1) + 1):
        for col in range(max(c0, 0), min(c1, W - 1) + 1):
            x, y = S * col + 1.0, 327 - (S * r + 1.0)
            w0 = ((bx - x) * (cy - y) - (by - y) * (cx - x)) / d
            w1 = ((cx - x) * (ay - y) - (cy - y) * (ax - x)) / d
            if w0 >= 0 and w1 >= 0 and w0 + w1 <= 1:
                inside[r][col] = True
raw = b"".join(b"\0" + b"".join(bytes((255, 255, 255, 255 if v else 0)) for v in row) for row in inside)
def chunk(t, data):
    return struct.pack(">I", len(data)) + t + data + struct.pack(">I", zlib.crc32(t + data) & 0xFFFFFFFF)
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 6, 0, 0, 0)) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
(here / "horse_mask.png").write_bytes(png)
print(sum(map(sum, inside)), "of", W * H, "pixels inside")
