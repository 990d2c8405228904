//! The report's text: the introduction and the per-case table (`study.csv`); the conclusions
//! are in [`super::conclusions`].

use super::cases::SectionStats;
use super::drive::Drive;
use super::params::{
    ACCEL_BIAS_MPS2, ACCEL_VIBRATION_MPS2, BIAS_TAU_S, CASE3_TILT_DEG, GNSS_SPEED_SIGMA_MPS,
    GNSS_VEL_SIGMA_MPS, GYRO_BIAS_OFFSET_V, GYRO_NOISE_V, ODO_SCALE_ERROR, OUTAGE_DELAY_S,
    SECTIONS, SF_N_M_PER_PULSE,
};
use super::summary::Gathered;
use super::DrArgs;
use crate::report::{fmt, Table};
use std::fmt::Write as _;

pub(super) fn intro_md(args: &DrArgs, drive: &Drive, hilly: &Drive) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Seed 000 (Seo, Sung, Lee 1999) fuses a vehicle's gyro and odometer with GPS in two ways: \
         the conventional 4-state filter (eq. 7: position, heading, odometer scale; GPS position \
         updates) and the proposed 8-state filter (eqs. 5-14: position, velocity, heading, gyro \
         scale `Sf_G`, gyro zero-rate voltage `V_nom`, odometer scale; GPS position *and* carrier \
         velocity updates). Seed 002 (Yeom et al.) carries speed through GPS gaps with an \
         accelerometer (KF1 smoothing, KF2 `[v, a, r]`). This study reproduces both on a \
         simulated drive.\n"
    );
    let _ = writeln!(
        s,
        "- **Drive**: {} ({:.0} s, {:.1} km), from `samples/scenarios/urban-drive.toml`, \
         tabulated by the simulator's motion model.",
        drive.description,
        drive.duration_s,
        drive.distance_m() / 1000.0
    );
    let _ = writeln!(
        s,
        "- **DR sensors** (10 Hz, raw): gyro 45.045 deg/s/V nominal with its zero-rate voltage \
         {:.0} mV above the nominal 2.5 V ({:.2} deg/s of bias) and {:.0} mV of noise per row; \
         odometer {SF_N_M_PER_PULSE} m/pulse nominal, {:.0} % scale error, whole pulses. Case 3 \
         tilts the gyro by {CASE3_TILT_DEG} deg (it senses cos 20 deg of the yaw rate). Both \
         filters start from the nominal parameters.",
        GYRO_BIAS_OFFSET_V * 1e3,
        GYRO_BIAS_OFFSET_V * 45.045,
        GYRO_NOISE_V * 1e3,
        ODO_SCALE_ERROR * 100.0
    );
    let _ = writeln!(
        s,
        "- **GNSS** (fast path, 1 Hz, no IF): positions = truth + white noise + a Gauss-Markov \
         bias (tau {BIAS_TAU_S} s) that jumps to a new draw at every satellite-set change; \
         velocities = truth + {GNSS_VEL_SIGMA_MPS} m/s white noise per axis (carrier-based, \
         unbiased). Per section:\n"
    );
    let _ = writeln!(
        s,
        "| section | road | white sigma (m) | bias sigma (m) | satellite-set change every (s) |\n|---|---|---|---|---|"
    );
    for sec in SECTIONS {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} |",
            sec.name, sec.environment, sec.white_sigma_m, sec.bias_sigma_m, sec.set_change_every_s
        );
    }
    let _ = writeln!(
        s,
        "\n- **Case 2**: GNSS removed for 60, 90 or 120 s starting {OUTAGE_DELAY_S} s after a \
         satellite-set change (the bias has just jumped), at placements spread over the drive \
         after 400 s, each on its own run. **Speed filter**: accelerometer at 50 Hz with a \
         {ACCEL_BIAS_MPS2} m/s^2 bias, {ACCEL_VIBRATION_MPS2} m/s^2 vibration and the slope term \
         `g sin(pitch)`; GNSS speed (3-D carrier speed, sigma {GNSS_SPEED_SIGMA_MPS} m/s) \
         removed over 20-60 s gaps with a minute of GNSS between them, on seed 002's kind of \
         road: {} ({:.0} s, {:.1} km), and on the urban drive.\n",
        hilly.description,
        hilly.duration_s,
        hilly.distance_m() / 1000.0
    );
    let _ = writeln!(
        s,
        "Run: `gpsrx study dr --out DIR{} --seed {}`. The table below is `study.csv`: one row per \
         section (Cases 1 and 3: mean and variance of the horizontal position error), outage \
         (Case 2) and gap (speed filter: RMS speed error, filter vs hold), `ratio` = proposed / \
         conventional (or filter / hold).",
        if args.common.quick { " --quick" } else { "" },
        args.common.seed
    );
    s
}

fn section_row(case: &str, seed: u64, x: &SectionStats) -> Vec<String> {
    let name = SECTIONS
        .get(x.index)
        .map_or("whole drive".to_string(), |s| {
            format!("{} ({})", s.name, s.environment)
        });
    vec![
        case.into(),
        name,
        seed.to_string(),
        fmt(x.span.0, 0),
        fmt(x.span.1, 0),
        "m, m^2".into(),
        fmt(x.proposed.0, 2),
        fmt(x.proposed.1, 1),
        fmt(x.conventional.0, 2),
        fmt(x.conventional.1, 1),
        fmt(x.gnss.0, 2),
        fmt(x.gnss.1, 1),
        fmt(x.proposed.0 / x.conventional.0, 3),
    ]
}

pub(super) fn table(seed: u64, g: &Gathered) -> Table {
    let mut t = Table::new(&[
        "case",
        "item",
        "seed",
        "t_start_s",
        "t_end_s",
        "units",
        "proposed_or_filter",
        "proposed_var",
        "conventional_or_hold",
        "conventional_var",
        "gnss_alone",
        "gnss_var",
        "ratio",
    ]);
    for x in g.case1.1 {
        t.push(section_row("1", seed, x));
    }
    for o in &g.outages {
        t.push(vec![
            "2".into(),
            format!(
                "outage {} s after the change at {:.0} s",
                OUTAGE_DELAY_S, o.change_s
            ),
            o.seed.to_string(),
            fmt(o.window.0, 0),
            fmt(o.window.1, 0),
            "m, m^2".into(),
            fmt(o.proposed.0, 2),
            fmt(o.proposed.1, 1),
            fmt(o.conventional.0, 2),
            fmt(o.conventional.1, 1),
            "-".into(),
            "-".into(),
            fmt(o.ratio(), 3),
        ]);
    }
    for x in g.case3.1 {
        t.push(section_row("3", seed, x));
    }
    let roads = g
        .speed
        .iter()
        .map(|x| (x, "hilly road"))
        .chain(g.speed_urban.iter().map(|x| (x, "urban drive")));
    for ((s, gaps), road) in roads {
        for r in gaps.iter() {
            t.push(vec![
                "speed".into(),
                format!(
                    "{road}: gap {:.0} s (climb {:+.1} m, speed change {:+.1} m/s)",
                    r.window.1 - r.window.0,
                    r.climb_m,
                    r.speed_change_mps
                ),
                s.to_string(),
                fmt(r.window.0, 0),
                fmt(r.window.1, 0),
                "m/s RMS".into(),
                fmt(r.rms_filter_mps, 3),
                "-".into(),
                fmt(r.rms_hold_mps, 3),
                "-".into(),
                "-".into(),
                "-".into(),
                fmt(r.rms_filter_mps / r.rms_hold_mps, 3),
            ]);
        }
    }
    t
}
