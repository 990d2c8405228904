//! The receiver's products as pandas-ready columns: a dict of equal-length columns, numbers as
//! numpy arrays (NaN where a value is missing), text as lists of str.

use gpsrx_receiver::output::ChannelRow;
use gpsrx_receiver::pipeline::{FixReport, ObservablesReport, ReceiverEvent};
use gpsrx_receiver::snapshot::output::utc_text;
use gpsrx_receiver::snapshot::SnapshotOutcome;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::collections::BTreeMap;

/// Columns being filled row by row.
#[derive(Default)]
struct Columns {
    numbers: BTreeMap<&'static str, Vec<f64>>,
    integers: BTreeMap<&'static str, Vec<i64>>,
    texts: BTreeMap<&'static str, Vec<String>>,
    order: Vec<&'static str>,
}

impl Columns {
    fn note(&mut self, name: &'static str) {
        if !self.order.contains(&name) {
            self.order.push(name);
        }
    }
    fn num(&mut self, name: &'static str, v: f64) {
        self.note(name);
        self.numbers.entry(name).or_default().push(v);
    }
    fn opt(&mut self, name: &'static str, v: Option<f64>) {
        self.num(name, v.unwrap_or(f64::NAN));
    }
    fn int(&mut self, name: &'static str, v: i64) {
        self.note(name);
        self.integers.entry(name).or_default().push(v);
    }
    fn text(&mut self, name: &'static str, v: String) {
        self.note(name);
        self.texts.entry(name).or_default().push(v);
    }

    /// The dict of columns (each name once, in the order first set).
    fn into_dict<'py>(
        mut self,
        py: Python<'py>,
        names: &[&'static str],
    ) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        // Empty tables still have their columns.
        for n in names {
            self.note(n);
        }
        for name in self.order {
            if let Some(v) = self.numbers.remove(name) {
                d.set_item(name, PyArray1::from_vec(py, v))?;
            } else if let Some(v) = self.integers.remove(name) {
                d.set_item(name, PyArray1::from_vec(py, v))?;
            } else if let Some(v) = self.texts.remove(name) {
                d.set_item(name, v)?;
            } else {
                d.set_item(name, PyArray1::<f64>::zeros(py, 0, false))?;
            }
        }
        Ok(d)
    }
}

/// Columns of a fix table.
pub const FIX_COLUMNS: [&str; 25] = [
    "t_stream_s",
    "week",
    "tow_s",
    "x_m",
    "y_m",
    "z_m",
    "lat_deg",
    "lon_deg",
    "h_m",
    "vx_mps",
    "vy_mps",
    "vz_mps",
    "clock_bias_m",
    "clock_drift_mps",
    "n_sv",
    "pdop",
    "hdop",
    "vdop",
    "quality",
    "raim",
    "used_prns",
    "week_known",
    "sigma_e_m",
    "sigma_n_m",
    "sigma_u_m",
];

/// The fixes as columns.
pub fn fixes<'py>(py: Python<'py>, fixes: &[FixReport]) -> PyResult<Bound<'py, PyDict>> {
    let mut c = Columns::default();
    for r in fixes {
        let f = &r.fix;
        c.num("t_stream_s", r.t_stream_s);
        c.int("week", i64::from(f.time.week));
        c.num("tow_s", f.time.tow_s);
        c.num("x_m", f.ecef_m[0]);
        c.num("y_m", f.ecef_m[1]);
        c.num("z_m", f.ecef_m[2]);
        c.num("lat_deg", f.llh.lat_rad.to_degrees());
        c.num("lon_deg", f.llh.lon_rad.to_degrees());
        c.num("h_m", f.llh.h_m);
        let v = f.vel_ecef_mps;
        c.opt("vx_mps", v.map(|v| v[0]));
        c.opt("vy_mps", v.map(|v| v[1]));
        c.opt("vz_mps", v.map(|v| v[2]));
        c.num("clock_bias_m", f.clock_bias_m);
        c.opt("clock_drift_mps", f.clock_drift_mps);
        c.int("n_sv", f.n_sv as i64);
        c.num("pdop", f.pdop);
        c.num("hdop", f.hdop);
        c.num("vdop", f.vdop);
        c.text("quality", f.quality.name().to_string());
        c.text("raim", f.raim.clone());
        c.text("used_prns", prn_list(&f.used_prns));
        c.int("week_known", i64::from(f.week_known));
        let s = f.sigma_enu_m;
        c.opt("sigma_e_m", s.map(|s| s[0]));
        c.opt("sigma_n_m", s.map(|s| s[1]));
        c.opt("sigma_u_m", s.map(|s| s[2]));
    }
    c.into_dict(py, &FIX_COLUMNS)
}

/// Columns of a channel table.
pub const CHANNEL_COLUMNS: [&str; 13] = [
    "t_stream_s",
    "channel",
    "prn",
    "state",
    "cn0_dbhz",
    "doppler_hz",
    "code_phase_chips",
    "pll_lock_indicator",
    "code_lock",
    "carrier_lock",
    "bit_sync",
    "frame_sync",
    "tow_s",
];

/// Channel rows as columns.
pub fn channels<'py>(py: Python<'py>, rows: &[ChannelRow]) -> PyResult<Bound<'py, PyDict>> {
    let mut c = Columns::default();
    for r in rows {
        c.num("t_stream_s", r.t_stream_s);
        c.int("channel", i64::from(r.channel));
        c.int("prn", i64::from(r.prn));
        c.text("state", r.state.clone());
        c.opt("cn0_dbhz", r.cn0_dbhz);
        c.opt("doppler_hz", r.doppler_hz);
        c.opt("code_phase_chips", r.code_phase_chips);
        c.opt("pll_lock_indicator", r.pll_lock_indicator);
        c.int("code_lock", i64::from(r.code_lock));
        c.int("carrier_lock", i64::from(r.carrier_lock));
        c.int("bit_sync", i64::from(r.bit_sync));
        c.int("frame_sync", i64::from(r.frame_sync));
        c.opt("tow_s", r.time.map(|t| t.tow_s));
    }
    c.into_dict(py, &CHANNEL_COLUMNS)
}

/// Columns of an observables table (one row per satellite per epoch).
pub const OBSERVABLE_COLUMNS: [&str; 9] = [
    "week",
    "tow_s",
    "prn",
    "pseudorange_m",
    "carrier_cycles",
    "doppler_hz",
    "cn0_dbhz",
    "loss_of_lock",
    "clock_offset_s",
];

/// Observable epochs as columns, one row per satellite.
pub fn observables<'py>(
    py: Python<'py>,
    epochs: &[ObservablesReport],
) -> PyResult<Bound<'py, PyDict>> {
    let mut c = Columns::default();
    for e in epochs {
        for s in &e.epoch.sats {
            c.int("week", i64::from(e.epoch.time.week));
            c.num("tow_s", e.epoch.time.tow_s);
            c.int("prn", i64::from(s.prn));
            c.opt("pseudorange_m", s.pseudorange_m);
            c.opt("carrier_cycles", s.carrier_cycles);
            c.opt("doppler_hz", s.doppler_hz);
            c.opt("cn0_dbhz", s.cn0_dbhz);
            c.int("loss_of_lock", i64::from(s.loss_of_lock));
            c.opt("clock_offset_s", e.epoch.clock_offset_s);
        }
    }
    c.into_dict(py, &OBSERVABLE_COLUMNS)
}

/// Events as a list of dicts, each with its `kind`.
pub fn events<'py>(py: Python<'py>, events: &[ReceiverEvent]) -> PyResult<Vec<Bound<'py, PyDict>>> {
    events
        .iter()
        .map(|e| {
            let d = PyDict::new(py);
            match e {
                ReceiverEvent::Acquired {
                    prn,
                    t_s,
                    doppler_hz,
                    cn0_dbhz,
                } => {
                    d.set_item("kind", "acquired")?;
                    d.set_item("prn", prn)?;
                    d.set_item("t_s", t_s)?;
                    d.set_item("doppler_hz", doppler_hz)?;
                    d.set_item("cn0_dbhz", cn0_dbhz)?;
                }
                ReceiverEvent::Lost { prn, t_s } => {
                    d.set_item("kind", "lost")?;
                    d.set_item("prn", prn)?;
                    d.set_item("t_s", t_s)?;
                }
                ReceiverEvent::FrameSync { prn, tow_s } => {
                    d.set_item("kind", "frame_sync")?;
                    d.set_item("prn", prn)?;
                    d.set_item("tow_s", tow_s)?;
                }
                ReceiverEvent::EphemerisDecoded { prn, iode } => {
                    d.set_item("kind", "ephemeris_decoded")?;
                    d.set_item("prn", prn)?;
                    d.set_item("iode", iode)?;
                }
                ReceiverEvent::ClockStep { ms } => {
                    d.set_item("kind", "clock_step")?;
                    d.set_item("ms", ms)?;
                }
                ReceiverEvent::SampleGap { t_s } => {
                    d.set_item("kind", "sample_gap")?;
                    d.set_item("t_s", t_s)?;
                }
                ReceiverEvent::GapMeasured { t_s, length_ms } => {
                    d.set_item("kind", "gap_measured")?;
                    d.set_item("t_s", t_s)?;
                    d.set_item("length_ms", length_ms)?;
                }
                ReceiverEvent::CoarseTime {
                    t_s,
                    satellites,
                    time_correction_s,
                } => {
                    d.set_item("kind", "coarse_time")?;
                    d.set_item("t_s", t_s)?;
                    d.set_item("satellites", satellites)?;
                    d.set_item("time_correction_s", time_correction_s)?;
                }
                ReceiverEvent::VectorTracking { t_s, engaged } => {
                    d.set_item("kind", "vector_tracking")?;
                    d.set_item("t_s", t_s)?;
                    d.set_item("engaged", engaged)?;
                }
                ReceiverEvent::CoarseTimeDropped { t_s } => {
                    d.set_item("kind", "coarse_time_dropped")?;
                    d.set_item("t_s", t_s)?;
                }
            }
            Ok(d)
        })
        .collect()
}

fn prn_list(prns: &[u8]) -> String {
    prns.iter().map(u8::to_string).collect::<Vec<_>>().join(" ")
}

/// Columns of a snapshot table (one row per input snapshot, as `snapshots.csv`).
pub const SNAPSHOT_COLUMNS: [&str; 26] = [
    "index",
    "label",
    "time_utc",
    "week",
    "tow_s",
    "lat_deg",
    "lon_deg",
    "h_m",
    "x_m",
    "y_m",
    "z_m",
    "n_sv",
    "hdop",
    "pdop",
    "quality",
    "reason",
    "residual_rms_m",
    "time_correction_s",
    "clock_bias_m",
    "fe_offset_hz",
    "searched",
    "detected",
    "used_prns",
    "excluded_prns",
    "rejected_prns",
    "h_error_m",
];

/// Snapshot rows as columns (NaN where a row has no value; `week` -1 without a time);
/// `errors` parallel to `rows` or empty.
pub fn snapshots<'py>(
    py: Python<'py>,
    rows: &[SnapshotOutcome],
    errors: &[Option<f64>],
) -> PyResult<Bound<'py, PyDict>> {
    let mut c = Columns::default();
    for (k, o) in rows.iter().enumerate() {
        let time = o.time.or(o.apriori_time);
        let llh = o.llh;
        let x = o.ecef_m;
        c.int("index", o.index as i64);
        c.text("label", o.label.clone());
        c.text("time_utc", time.map_or_else(String::new, utc_text));
        c.int("week", time.map_or(-1, |t| i64::from(t.week)));
        c.opt("tow_s", time.map(|t| t.tow_s));
        c.opt("lat_deg", llh.map(|l| l.lat_rad.to_degrees()));
        c.opt("lon_deg", llh.map(|l| l.lon_rad.to_degrees()));
        c.opt("h_m", llh.map(|l| l.h_m));
        c.opt("x_m", x.map(|x| x.x));
        c.opt("y_m", x.map(|x| x.y));
        c.opt("z_m", x.map(|x| x.z));
        c.int("n_sv", o.used_prns.len() as i64);
        c.opt("hdop", o.hdop);
        c.opt("pdop", o.pdop);
        c.text("quality", o.quality.name().to_string());
        c.text("reason", o.reason.clone());
        c.opt("residual_rms_m", o.residual_rms_m);
        c.opt("time_correction_s", o.time_correction_s);
        c.opt("clock_bias_m", o.clock_bias_m);
        c.opt("fe_offset_hz", o.fe_offset_hz);
        c.int("searched", o.searched as i64);
        c.int("detected", o.detected as i64);
        c.text("used_prns", prn_list(&o.used_prns));
        c.text("excluded_prns", prn_list(&o.excluded_prns));
        c.text("rejected_prns", prn_list(&o.rejected_prns));
        c.opt("h_error_m", errors.get(k).copied().flatten());
    }
    c.into_dict(py, &SNAPSHOT_COLUMNS)
}
