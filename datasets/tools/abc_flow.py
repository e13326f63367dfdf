#!/usr/bin/env python3
"""Writes abc_flow_noisy_32x32x32.vti: an Arnold-Beltrami-Childress flow with noise.

u = (A sin z + C cos y, B sin x + A cos z, C sin y + B cos x), A = 1, B = sqrt(2/3), C = sqrt(1/3),
sampled at 32 points per axis on [0, 2 pi) (spacing 2 pi / 32, origin 0), plus independent
uniform noise in [-0.02, 0.02] * (the largest speed) on every component (Python's random,
seed 20), written as a VTK XML ImageData file with one 3-component Float32 point array
`velocity` in ASCII (x fastest). The flow is a Beltrami field: curl u = u, so its vorticity
magnitude equals its speed, which the tests use as the truth. Standard library only:

    python3 datasets/tools/abc_flow.py datasets/abc_flow_noisy_32x32x32.vti
"""
import math
import random
import sys

N = 32
A, B, C = 1.0, math.sqrt(2.0 / 3.0), math.sqrt(1.0 / 3.0)


def velocity(x, y, z):
    return (A * math.sin(z) + C * math.cos(y), B * math.sin(x) + A * math.cos(z), C * math.sin(y) + B * math.cos(x))


def main(path):
    h = 2.0 * math.pi / N
    rng = random.Random(20)
    points = [(i * h, j * h, k * h) for k in range(N) for j in range(N) for i in range(N)]
    clean = [velocity(*p) for p in points]
    top = max(math.sqrt(sum(c * c for c in u)) for u in clean)
    values = []
    for u in clean:
        values.extend(c + 0.02 * top * (2.0 * rng.random() - 1.0) for c in u)
    lines = [" ".join(f"{v:.7g}" for v in values[s:s + 12]) for s in range(0, len(values), 12)]
    extent = f"0 {N - 1} 0 {N - 1} 0 {N - 1}"
    text = "\n".join([
        '<?xml version="1.0"?>',
        '<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian">',
        f'  <ImageData WholeExtent="{extent}" Origin="0 0 0" Spacing="{h:.17g} {h:.17g} {h:.17g}">',
        f'    <Piece Extent="{extent}">',
        '      <PointData Vectors="velocity">',
        '        <DataArray type="Float32" Name="velocity" NumberOfComponents="3" format="ascii">',
        *lines,
        '        </DataArray>',
        '      </PointData>',
        '    </Piece>',
        '  </ImageData>',
        '</VTKFile>',
        '',
    ])
    with open(path, "w") as f:
        f.write(text)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "abc_flow_noisy_32x32x32.vti")
