#!/usr/bin/env python3
"""Builds nav/assets/egm96_1deg.i16, the 1-degree EGM96 geoid grid embedded in gpsrx-nav.

Source: the EGM96 5' grid of the `egm96` Python package (0.3.0, MIT licence; the grid is
GeographicLib's egm96-5 data set, the NGA EGM96 model, public domain), file
`egm96/data/egm96-5.npz`: second differences of the undulation in integer centimetres,
latitudes -90..90, longitudes -180..180 (5' spacing). Every 12th node is kept (1 degree).

Output: 181 x 361 little-endian int16 values in centimetres, row-major, latitude -90..90
(rows), longitude -180..180 (columns, the +180 column repeating -180).

Usage: make_geoid_grid.py EGM96-5.NPZ OUT.I16 (needs no numpy).
"""
import io
import struct
import sys
import zipfile


def read_npy(blob):
    assert blob[:6] == b"\x93NUMPY"
    major = blob[6]
    if major == 1:
        hlen = struct.unpack("<H", blob[8:10])[0]
        start = 10
    else:
        hlen = struct.unpack("<I", blob[8:12])[0]
        start = 12
    header = eval(blob[start:start + hlen].decode("latin1"))  # a Python dict literal
    data = blob[start + hlen:]
    shape = header["shape"]
    assert not header["fortran_order"]
    code = {"<f8": "d", "<i2": "h"}[header["descr"]]
    n = 1
    for s in shape:
        n *= s
    return shape, struct.unpack("<%d%s" % (n, code), data[: n * struct.calcsize(code)])


def main(npz, out):
    z = zipfile.ZipFile(npz)
    (nlat,), lats = read_npy(z.read("latitudes.npy"))
    (nlon,), lons = read_npy(z.read("longitudes.npy"))
    (rows, cols), d2 = read_npy(z.read("undulation_d2.npy"))
    assert (rows, cols) == (nlat, nlon) == (2161, 4321)
    assert lats[0] == -90.0 and lats[-1] == 90.0 and lons[0] == -180.0 and lons[-1] == 180.0
    # Undo the latitude difference, then the longitude difference (cumulative sums).
    cm = [list(d2[r * cols:(r + 1) * cols]) for r in range(rows)]
    for r in range(1, rows):
        prev, cur = cm[r - 1], cm[r]
        for c in range(cols):
            cur[c] += prev[c]
    for r in range(rows):
        row = cm[r]
        for c in range(1, cols):
            row[c] += row[c - 1]
    buf = io.BytesIO()
    for r in range(0, rows, 12):
        for c in range(0, cols, 12):
            buf.write(struct.pack("<h", cm[r][c]))
    open(out, "wb").write(buf.getvalue())
    if len(sys.argv) > 3:
        # Check points: the full 5' grid, bilinear, for comparison.
        def full(lat, lon):
            fi = (lat + 90.0) * 12.0
            fj = ((lon + 180.0) % 360.0) * 12.0
            i, j = min(int(fi), rows - 2), min(int(fj), cols - 2)
            di, dj = fi - i, fj - j
            v = (cm[i][j] * (1 - di) * (1 - dj) + cm[i][j + 1] * (1 - di) * dj
                 + cm[i + 1][j] * di * (1 - dj) + cm[i + 1][j + 1] * di * dj)
            return v / 100.0
        for arg in sys.argv[3:]:
            lat, lon = map(float, arg.split(","))
            print("%s: %.3f m" % (arg, full(lat, lon)))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
