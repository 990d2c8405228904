//! Plain-language observations on an [`InfoReport`]: the usual mistakes when reading a
//! recording (wrong format, real read as complex, signed/unsigned mix-up) and front-end trouble
//! (clipping, low level, DC spike, narrowband lines).

use crate::format::SampleFormat;
use crate::info::{ComponentStats, Histogram, InfoReport};

/// I/Q correlation above which samples look like real data read as complex.
const IQ_CORRELATION_LIMIT: f64 = 0.5;
/// Share of values at the extreme codes above which we call it clipping.
const CLIP_LIMIT: f64 = 0.01;
/// DC spike (dB over the median bin) worth a note.
const DC_SPIKE_LIMIT_DB: f64 = 10.0;
/// Narrowband line (dB over the median bin) worth a note.
const LINE_LIMIT_DB: f64 = 15.0;

/// Share of a component's values beyond `level` in magnitude (exact histograms only).
fn share_beyond(c: &ComponentStats, level: f64) -> Option<f64> {
    match &c.histogram {
        Histogram::Values { values, counts } => {
            let total: u64 = counts.iter().sum();
            let far: u64 = values
                .iter()
                .zip(counts)
                .filter(|(v, _)| v.abs() > level)
                .map(|(_, c)| c)
                .sum();
            Some(far as f64 / total.max(1) as f64)
        }
        Histogram::Binned { .. } => None,
    }
}

fn distinct_values(c: &ComponentStats) -> Option<&[f64]> {
    match &c.histogram {
        Histogram::Values { values, .. } => Some(values),
        Histogram::Binned { .. } => None,
    }
}

/// The notes for `r`, read as `format`.
pub(crate) fn notes(r: &InfoReport, format: &SampleFormat) -> Vec<String> {
    let mut notes = Vec::new();
    if r.analysed_samples == 0 {
        return notes;
    }
    let comps: Vec<(&str, &ComponentStats)> = match &r.q {
        Some(q) => vec![("I", &r.i), ("Q", q)],
        None => vec![("real", &r.i)],
    };
    let dead = |c: &ComponentStats| c.std == 0.0 && c.mean == 0.0;
    if comps.iter().all(|(_, c)| dead(c)) {
        notes.push("every analysed sample is zero: a dead front end, or the wrong skip?".into());
        return notes;
    }
    if let Some(q) = &r.q {
        if q.std == 0.0 && r.i.std > 0.0 {
            notes.push(format!(
                "Q is constant ({}): looks like real data read as complex; try a real format (ri8, ri16_le, rf32_le, ri2) with an IF",
                q.mean
            ));
        }
    }
    if let Some(rho) = r.iq_correlation {
        if rho.abs() > IQ_CORRELATION_LIMIT {
            notes.push(format!(
                "I and Q are strongly correlated (r = {rho:.2}): looks like real data read as complex (or a faulty I/Q front end)"
            ));
        }
    }

    let fs = f64::from(format.full_scale());
    let integer = !format.is_float();
    let far_from_zero: Vec<String> = comps
        .iter()
        .filter(|(_, c)| c.mean.abs() > 0.25 * c.std && (!integer || c.mean.abs() > 0.02 * fs))
        .map(|(n, c)| format!("{n} mean {:.3}", c.mean))
        .collect();
    if !far_from_zero.is_empty() {
        let hint = match format {
            SampleFormat::Ci8 | SampleFormat::Ri8 => "is this cu8 read as ci8?",
            SampleFormat::Cu8 { .. } => "is the cu8 zero level right, or is this ci8 read as cu8?",
            _ => "a DC offset in the front end?",
        };
        notes.push(format!(
            "mean far from zero ({}): {hint}",
            far_from_zero.join(", ")
        ));
    }

    if matches!(
        format,
        SampleFormat::Ci8 | SampleFormat::Ri8 | SampleFormat::Cu8 { .. }
    ) {
        let piled = comps
            .iter()
            .filter_map(|(_, c)| share_beyond(c, 0.75 * fs))
            .fold(0.0f64, f64::max);
        if piled > 0.5 {
            notes.push(format!(
                "{:.0}% of values lie beyond 3/4 of full scale: a signed/unsigned mix-up (cu8 read as ci8, or ci8 read as cu8)?",
                100.0 * piled
            ));
        }
    }
    if let Some(clip) = r.clip_fraction {
        if clip > CLIP_LIMIT {
            notes.push(format!(
                "{:.2}% of values sit at the extreme codes: clipping; lower the front-end gain",
                100.0 * clip
            ));
        }
    }
    if integer && !format.is_packed() {
        let values = distinct_values(&r.i);
        match values {
            Some(v) if v.len() <= 16 => {
                let bits = (v.len() as f64).log2().ceil().max(1.0);
                let list: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
                notes.push(format!(
                    "only {} distinct values ({}): a {bits}-bit front end stored as {}",
                    v.len(),
                    list.join(", "),
                    format.name()
                ));
            }
            _ => {
                if r.i.std < 1.0 {
                    notes.push(format!(
                        "very low level (std {:.2} codes of {fs}): few bits in use; raise the front-end gain",
                        r.i.std
                    ));
                }
            }
        }
    }
    if let Some(s) = &r.spectrum {
        if s.dc_spike_db > DC_SPIKE_LIMIT_DB {
            notes.push(format!(
                "DC spike {:.1} dB above the median bin: LO leakage or a DC offset",
                s.dc_spike_db
            ));
        }
        if s.peak_bin_over_median_db > LINE_LIMIT_DB {
            notes.push(format!(
                "narrowband line at {:.4} MHz, {:.1} dB above the median bin: interference, a spur or an IF carrier (is the IF given right?)",
                s.peak_bin_hz / 1e6,
                s.peak_bin_over_median_db
            ));
        }
    }
    notes
}
