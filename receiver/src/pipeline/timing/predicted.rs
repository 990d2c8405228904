//! SV time from vector tracking's prediction, before frame sync (A-GPS "fine time").
//!
//! While the navigation filter drives the channels it predicts every satellite's SV time at
//! any sample (`crate::pipeline::vector::Snapshot::sv_tow_s`), to its range error over `c`:
//! tens of nanoseconds. A channel's own bit synchronisation places its data-bit edges, where
//! the SV time is a whole number of 20 ms bits; rounding the prediction at an edge to the bit
//! gives the exact SV time as long as the prediction is within half a bit. It must lie within
//! [`EDGE_TOLERANCE_MS`] of the edge: a bit synchronisation that is wrong by whole
//! milliseconds (the histogram's false rate, 1e-4 per synchronisation at the design C/N0)
//! falls at least 1 ms off and is refused. The decoder then decodes subframes from that time
//! on and its first HOW confirms it (`NavEvent::TowMismatch` otherwise), as with an SV time
//! carried over an outage (`super::sv_time`). A satellite at 24 dB-Hz gives pseudoranges
//! from its first bit edge in phase lock instead of 6-12 s later at frame sync.

use crate::pipeline::timing::modulo::nearest_remainder;
use gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
use gpsrx_tracking::ChannelEpoch;

/// Largest distance of the predicted SV time from a channel's bit edge, ms (the prediction
/// is good to well under a microsecond; a wrong bit edge is whole milliseconds off).
pub const EDGE_TOLERANCE_MS: f64 = 0.01;

/// The SV time (TOW, s) of the bit edge that opens report `e`, from the SV time predicted at
/// its first sample, `predicted_sv_tow_s`: the prediction at the code period's start rounded
/// to the 20 ms bit; `Err(offset ms)` when it falls more than [`EDGE_TOLERANCE_MS`] off.
pub fn edge_sv_tow_s(e: &ChannelEpoch, predicted_sv_tow_s: f64) -> Result<f64, f64> {
    let edge_ms = (predicted_sv_tow_s - e.code_phase_chips / CA_CHIP_RATE_HZ) * 1e3;
    let off_ms = nearest_remainder(edge_ms, 20.0);
    if off_ms.abs() <= EDGE_TOLERANCE_MS {
        Ok((edge_ms - off_ms) * 1e-3)
    } else {
        Err(off_ms)
    }
}

/// The data-bit edges of report `e`'s channel from the SV time predicted at its first sample:
/// the `ms_count`s modulo 20 of the code periods that start a bit (the period `j` ms into a
/// bit, `j` the prediction at the period's start modulo 20 ms, has `ms_count - j` as its
/// bit's first). None when the prediction at the period's start is more than
/// [`EDGE_TOLERANCE_MS`] off a whole millisecond (the report's code phase is not where the
/// prediction puts the code: no edges from it).
pub fn bit_edge_phase(e: &ChannelEpoch, predicted_sv_tow_s: f64) -> Option<usize> {
    let start_ms = (predicted_sv_tow_s - e.code_phase_chips / CA_CHIP_RATE_HZ) * 1e3;
    let in_bit_ms = start_ms.rem_euclid(20.0);
    let j = in_bit_ms.round();
    if (in_bit_ms - j).abs() > EDGE_TOLERANCE_MS {
        return None;
    }
    let j = (j as u64) % 20;
    Some(((e.ms_count % 20 + 20 - j) % 20) as usize)
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64;

    fn report(code_phase_chips: f64) -> ChannelEpoch {
        let mut e = crate::pipeline::test_support::report(
            16,
            7000,
            Complex64::new(1.0, 0.0),
            0.0,
            0.0,
            24.0,
        );
        e.code_phase_chips = code_phase_chips;
        e.bit_edge = true;
        e
    }

    #[test]
    fn a_prediction_at_the_bit_edge_gives_its_whole_bit() {
        // Code period starting at SV time 538206.140 s (a bit edge), 0.3 chip in at the sample.
        let e = report(0.3);
        let at_sample = 538_206.140 + 0.3 / CA_CHIP_RATE_HZ + 40e-9;
        let t = edge_sv_tow_s(&e, at_sample).expect("within the tolerance");
        assert!((t - 538_206.140).abs() < 1e-9, "{t}");
    }

    #[test]
    fn the_bit_edges_are_where_the_predicted_sv_time_is_a_whole_bit() {
        // Period ms_count 7000 (report's k) starts 13 ms into a bit: bits start at ms_count
        // 6987, 7007, ..., i.e. 7 modulo 20.
        let e = report(0.25);
        let at_sample = 538_206.153 + 0.25 / CA_CHIP_RATE_HZ - 30e-9;
        assert_eq!(bit_edge_phase(&e, at_sample), Some(7));
        // At an edge: its own ms_count.
        let at_edge = 538_206.160 + 0.25 / CA_CHIP_RATE_HZ;
        assert_eq!(bit_edge_phase(&e, at_edge), Some(0));
        // Half a millisecond off: the code is not where the prediction puts it.
        assert_eq!(bit_edge_phase(&e, at_edge + 0.5e-3), None);
    }

    #[test]
    fn a_bit_edge_a_millisecond_off_the_prediction_is_refused() {
        let e = report(0.0);
        let off = edge_sv_tow_s(&e, 538_206.141).expect_err("1 ms off a bit edge");
        assert!((off - 1.0).abs() < 1e-6, "{off}");
        assert!(edge_sv_tow_s(&e, 538_206.139).is_err());
    }
}
