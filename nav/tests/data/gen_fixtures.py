#!/usr/bin/env python3
"""Generate independent-truth fixtures for gpsrx-nav tests.

Truth comes from RTKLIB 2.4.3 (through the `pyrtklib` Python binding) and from `pymap3d`;
none of it shares code with gpsrx-nav. See README.md for versions and the exact command.

Usage: python gen_fixtures.py /path/to/brdc0010.22n   (writes the CSVs next to this script)
"""
import csv
import math
import os
import sys

import pymap3d
import pyrtklib as rtk

HERE = os.path.dirname(os.path.abspath(__file__))
CLIGHT = 299792458.0


def gpst(week, tow):
    return rtk.gpst2time(week, tow)


def norm_week_tow(week, tow):
    while tow >= 604800.0:
        tow -= 604800.0
        week += 1
    while tow < 0.0:
        tow += 604800.0
        week -= 1
    return week, tow


def arr(values):
    a = rtk.Arr1Ddouble(len(values))
    for i, v in enumerate(values):
        a[i] = v
    return a


def toe_week_tow(eph):
    w = rtk.Arr1Dint(1)
    tow = rtk.time2gpst(eph.toe, w)
    return w[0], tow


def sat_positions(nav_path):
    obs, nav, sta = rtk.obs_t(), rtk.nav_t(), rtk.sta_t()
    ok = rtk.readrnx(nav_path, 1, "", obs, nav, sta)
    assert ok, "readrnx failed"
    offsets = [-7200.0, -3600.0, -900.0, 0.0, 450.5, 3600.0, 7200.0, 14400.0]
    h = 0.1  # central-difference step for the velocity, s
    rows = []
    for i in range(nav.n):
        eph = nav.eph[i]
        prn = rtk.Arr1Dint(1)
        sys_ = rtk.satsys(eph.sat, prn)
        if sys_ != rtk.SYS_GPS:
            continue
        week, toe = toe_week_tow(eph)
        for dt in offsets:
            w, tow = norm_week_tow(week, toe + dt)
            rs, dts, var = rtk.Arr1Ddouble(6), rtk.Arr1Ddouble(2), rtk.Arr1Ddouble(1)
            rtk.eph2pos(gpst(w, tow), eph, rs, dts, var)
            rp, dp, vp = rtk.Arr1Ddouble(6), rtk.Arr1Ddouble(2), rtk.Arr1Ddouble(1)
            rm, dm, vm = rtk.Arr1Ddouble(6), rtk.Arr1Ddouble(2), rtk.Arr1Ddouble(1)
            wp, tp = norm_week_tow(w, tow + h)
            wm, tm = norm_week_tow(w, tow - h)
            rtk.eph2pos(gpst(wp, tp), eph, rp, dp, vp)
            rtk.eph2pos(gpst(wm, tm), eph, rm, dm, vm)
            vel = [(rp[k] - rm[k]) / (2 * h) for k in range(3)]
            rows.append({
                "prn": prn[0], "iode": eph.iode, "iodc": eph.iodc,
                "toe_week": week, "toe_tow_s": repr(toe),
                "t_week": w, "t_tow_s": repr(tow),
                "x_m": repr(rs[0]), "y_m": repr(rs[1]), "z_m": repr(rs[2]),
                "vx_mps": repr(vel[0]), "vy_mps": repr(vel[1]), "vz_mps": repr(vel[2]),
                # RTKLIB eph2pos clock: af0 + af1 dt + af2 dt^2 + relativity; no TGD.
                "dts_s": repr(dts[0]),
                "tgd_s": repr(eph.tgd[0]),
            })
    with open(os.path.join(HERE, "rtklib_sat_pos.csv"), "w", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        wr.writeheader()
        wr.writerows(rows)
    print(f"rtklib_sat_pos.csv: {len(rows)} rows from {nav.n} ephemerides")
    return nav


def klobuchar(nav_ion):
    """RTKLIB ionmodel (L1 delay in metres) on a grid, for two parameter sets."""
    param_sets = {
        "brdc0010": nav_ion,
        # A high-activity set (values in ICD range) to exercise the cosine branch strongly.
        "high": [3.82e-08, 1.49e-08, -1.79e-07, 0.0, 1.43e05, 0.0, -3.28e05, 1.13e05],
    }
    sites = [(37.5665, 126.978, 40.0), (0.0, 0.0, 0.0), (-33.9, 18.4, 10.0),
             (64.1, -21.9, 50.0), (-77.8, 166.7, 20.0), (40.0, -105.0, 1600.0)]
    rows = []
    for name, ion in param_sets.items():
        for lat, lon, hgt in sites:
            pos = arr([math.radians(lat), math.radians(lon), hgt])
            for tow in [0.0, 21600.0, 43200.0, 50400.0, 57600.0, 64800.0, 518400.0 + 49000.0]:
                for az in [0.0, 45.0, 135.0, 225.0, 315.0]:
                    for el in [5.0, 15.0, 30.0, 60.0, 90.0]:
                        azel = arr([math.radians(az), math.radians(el)])
                        d = rtk.ionmodel(gpst(2190, tow), arr(ion), pos, azel)
                        rows.append([name] + ion + [lat, lon, hgt, tow, az, el, repr(d)])
    with open(os.path.join(HERE, "rtklib_klobuchar.csv"), "w", newline="") as f:
        wr = csv.writer(f)
        wr.writerow(["set", "a0", "a1", "a2", "a3", "b0", "b1", "b2", "b3",
                     "lat_deg", "lon_deg", "h_m", "tow_s", "az_deg", "el_deg", "delay_m"])
        wr.writerows(rows)
    print(f"rtklib_klobuchar.csv: {len(rows)} rows")


def troposphere():
    rows = []
    for lat in [0.0, 37.5665, -45.0, 70.0]:
        for hgt in [-50.0, 0.0, 40.0, 1000.0, 3000.0, 8000.0]:
            for el in [3.0, 5.0, 10.0, 30.0, 60.0, 90.0]:
                pos = arr([math.radians(lat), math.radians(10.0), hgt])
                azel = arr([0.0, math.radians(el)])
                d = rtk.tropmodel(gpst(2190, 0.0), pos, azel, 0.7)
                rows.append([lat, hgt, el, repr(d)])
    with open(os.path.join(HERE, "rtklib_saastamoinen.csv"), "w", newline="") as f:
        wr = csv.writer(f)
        wr.writerow(["lat_deg", "h_m", "el_deg", "delay_m"])
        wr.writerows(rows)
    print(f"rtklib_saastamoinen.csv: {len(rows)} rows")


def frames():
    """pymap3d geodetic <-> ECEF and az/el (WGS-84)."""
    rows = []
    sites = [(37.5665, 126.978, 40.0), (0.0, 0.0, 0.0), (89.9, 45.0, 100.0), (-89.99, -170.0, 5.0),
             (-33.9, 18.4, -30.0), (51.5, -0.1, 8848.0), (10.0, 179.9, 20200e3)]
    sats = [(15600e3, 7540e3, 20140e3), (-12000e3, 20000e3, 10000e3), (26560e3, 0.0, 0.0),
            (-5000e3, -24000e3, 9000e3)]
    for lat, lon, h in sites:
        x, y, z = pymap3d.geodetic2ecef(lat, lon, h)
        for sx, sy, sz in sats:
            az, el, rng = pymap3d.ecef2aer(sx, sy, sz, lat, lon, h)
            rows.append([lat, lon, h, repr(float(x)), repr(float(y)), repr(float(z)), sx, sy, sz,
                         repr(float(az)), repr(float(el))])
    with open(os.path.join(HERE, "pymap3d_frames.csv"), "w", newline="") as f:
        wr = csv.writer(f)
        wr.writerow(["lat_deg", "lon_deg", "h_m", "x_m", "y_m", "z_m",
                     "sv_x_m", "sv_y_m", "sv_z_m", "az_deg", "el_deg"])
        wr.writerows(rows)
    print(f"pymap3d_frames.csv: {len(rows)} rows")


def lnav_decode():
    """RTKLIB decode_word (parity, complement) + decode_frame of the subframes our encoder
    transmits (lnav_subframes.csv, made by `cargo run --example lnav_dump`)."""
    U8 = getattr(rtk, "Arr1Dunsigned char")
    src = os.path.join(HERE, "lnav_subframes.csv")
    rows, page18 = [], None
    with open(src) as f:
        for rec in csv.DictReader(f):
            eph = rtk.eph_t()
            ion, utc = rtk.Arr1Ddouble(8), rtk.Arr1Ddouble(8)
            # This RTKLIB 2.4.3 build's decode_frame takes the whole frame: subframes 1-5,
            # parity removed, 30 bytes each. Ephemeris and ion/utc are decoded in two calls
            # because its almanac step rejects our dummy pages before reaching page 18.
            frame = U8(150)
            hows = []
            for k in range(1, 6):
                value = int(rec[f"sf{k}"], 16) >> 4  # drop the 4 padding bits
                bits = [(value >> (299 - i)) & 1 for i in range(300)]
                prev = 0  # D29*, D30* before word 1: word 10 of the previous subframe = 00
                for w in range(10):
                    word30 = 0
                    for b in bits[30 * w:30 * w + 30]:
                        word30 = (word30 << 1) | b
                    data = U8(3)
                    ok = rtk.decode_word((prev << 30) | word30, data)
                    assert ok == 1, f"RTKLIB parity failure: row {rec['index']} sf{k} word {w + 1}"
                    for j in range(3):
                        frame[30 * (k - 1) + 3 * w + j] = data[j]
                    prev = word30 & 3
                base = 240 * (k - 1)
                hows.append(rtk.getbitu(frame, base + 24, 17))
                sf_id = rtk.getbitu(frame, base + 43, 3)
                assert sf_id == k, (sf_id, k)
            # (pybind accepts None here only for eph and alm; the status of the first call is
            # 0 when the almanac step fails, so check the content instead.)
            rtk.decode_frame(frame, eph, None, rtk.Arr1Ddouble(8), rtk.Arr1Ddouble(8))
            assert eph.iode == int(rec["iode"]), (eph.iode, rec["iode"])
            assert rtk.decode_frame(frame, None, None, ion, utc) == 1
            if page18 is None:
                page18 = [ion[i] for i in range(8)] + [utc[i] for i in range(8)]
            wk = rtk.Arr1Dint(1)
            toc_tow = rtk.time2gpst(eph.toc, wk)
            rows.append({
                "index": rec["index"], "prn": rec["prn"],
                "week_mod_1024": eph.week % 1024, "how_tow_count_sf1": hows[0],
                "iodc": eph.iodc, "iode": eph.iode, "ura_index": eph.sva, "sv_health": eph.svh,
                "codes_on_l2": eph.code, "l2p_flag": eph.flag, "tgd_s": repr(eph.tgd[0]),
                "toc_tow_s": repr(toc_tow), "af0_s": repr(eph.f0), "af1_s_s": repr(eph.f1),
                "af2_s_s2": repr(eph.f2), "crs_m": repr(eph.crs), "delta_n_rad_s": repr(eph.deln),
                "m0_rad": repr(eph.M0), "cuc_rad": repr(eph.cuc), "e": repr(eph.e),
                "cus_rad": repr(eph.cus), "a_m": repr(eph.A), "toe_tow_s": repr(eph.toes),
                "fit_h": repr(eph.fit), "cic_rad": repr(eph.cic), "omega0_rad": repr(eph.OMG0),
                "cis_rad": repr(eph.cis), "i0_rad": repr(eph.i0), "crc_m": repr(eph.crc),
                "omega_rad": repr(eph.omg), "omega_dot_rad_s": repr(eph.OMGd),
                "idot_rad_s": repr(eph.idot),
            })
    with open(os.path.join(HERE, "rtklib_lnav_decode.csv"), "w", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        wr.writeheader()
        wr.writerows(rows)
    with open(os.path.join(HERE, "rtklib_lnav_page18.csv"), "w", newline="") as f:
        wr = csv.writer(f)
        wr.writerow(["a0", "a1", "a2", "a3", "b0", "b1", "b2", "b3",
                     "utc0", "utc1", "utc2", "utc3", "utc4", "utc5", "utc6", "utc7"])
        wr.writerow([repr(v) for v in page18])
    print(f"rtklib_lnav_decode.csv: {len(rows)} rows; page 18: {page18}")


def main():
    nav_path = sys.argv[1]
    nav = sat_positions(nav_path)
    klobuchar([nav.ion_gps[k] for k in range(8)])
    troposphere()
    frames()
    lnav_decode()


if __name__ == "__main__":
    main()
