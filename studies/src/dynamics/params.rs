//! The experiment's fixed parameters: timing, trajectory, oscillator, INS and loop bandwidths.

use crate::if_sim::Oscillator;

/// Bandwidth ratio between consecutive narrowing stages (`NARROW_RATIO` of
/// `tracking/src/channel/narrowing.rs`, private to the channel).
pub const NARROW_RATIO: f64 = 2.0;
/// Length of a narrowing stage in units of its own `1 / Bn` (`STAGE_BN_S` there).
pub const STAGE_BN_S: f64 = 2.0;

/// GPS time of week of the first sample (week 2190, 2022-01-01 14:00 GPS time: 12 satellites
/// above 5 deg at Seoul, 10 of them healthy; G22 and G28 are flagged unhealthy), s.
pub const START_TOW_S: f64 = 568_800.0;
/// Sampling rate of the simulated IF (complex baseband), Hz.
pub const FS_HZ: f64 = 2.048e6;
/// Vehicle speed before the manoeuvre, m/s (an aircraft: a 10 g turn at 200 m/s turns at
/// `a / v` = 0.49 rad/s, so the line-of-sight jerk is `a^2 / v` = 48 m/s^3).
pub const SPEED_MPS: f64 = 200.0;
/// Cruise before the manoeuvre of the scenarios whose narrowest loop is [`HEADLINE_BN_HZ`] or
/// wider ([`lead_in_s`]), s: the channels hand over from pull-in (15 Hz) by about 1.5 s and
/// narrow in stages (Bn halved per stage, each held `2 / Bn`: [`narrowing_s`]) to 0.4 Hz by
/// about 9.8 s, then settle for `1.2 / Bn` = 3 s (2.3 time constants `1 / w0` at 2nd order).
pub const LEAD_IN_S: f64 = 13.0;
/// Time from the start to the hand-over from pull-in to tracking (pull-in, bit
/// synchronisation at a bit edge) allowed for in the lead-in, s.
pub const HAND_OVER_S: f64 = 1.5;
/// Settling time allowed after the last narrowing stage, in units of the target loop's `1 / Bn`
/// (`Bn t` = 1.2: 2.3 time constants `1 / w0` of a 2nd-order loop, `w0 = Bn / 0.53`).
pub const SETTLE_BN_S: f64 = 1.2;
/// Acceleration ramp in and out of the manoeuvre (bounded jerk), s.
pub const RAMP_S: f64 = 1.0;
/// Length of a turn segment (ramp-in included), s.
pub const TURN_S: f64 = 8.0;
/// Length of an acceleration-step segment (ramp-in included), s.
pub const STEP_S: f64 = 4.0;
/// Cruise after the end of the ramp-out, s.
pub const TAIL_S: f64 = 2.0;
/// Pull-in loop bandwidth the narrowing starts from, Hz
/// (`gpsrx_tracking::ChannelConfig::default().pull_in`).
pub const PULL_IN_BN_HZ: f64 = 15.0;
/// The receiver oscillator (the simulator's two-state clock): white FM of Allan deviation 1e-11
/// at 1 s and random-walk FM h_-2 = 3e-24 (sigma_y = 1.09e-11 at 1 s, 1.44e-11 at 10 s), a
/// quiet OCXO-class oscillator between `Oscillator::OCXO` and `Oscillator::TCXO`.
/// `oracles.md`: the oscillator jitter of a 2nd-order loop is about `144 sigma_A f_L1 / Bn` deg,
/// 5.7 deg at 0.4 Hz, 1.1 deg at 2 Hz.
pub const OSCILLATOR: Oscillator = Oscillator {
    name: "OCXO-class",
    allan_deviation_1s: 1.0e-11,
    h_m2: 3.0e-24,
};
/// Nominal receiver clock drift, s/s (shifts every Doppler by `-f_L1 d` = -47 Hz).
pub const CLOCK_DRIFT_S_S: f64 = 3.0e-8;
/// One milli-g, m/s^2.
pub const MG_MPS2: f64 = 9.806_65e-3;
/// Accelerometer bias magnitudes of INS 1 for the narrow (seed 004) rows, mg; INS 2 has twice
/// each. Along `(1, 1, 1)/sqrt(3)`, the line-of-sight part `B_V` is at most `B`; the 2nd-order
/// 0.4 Hz loop's static offset `B_V / (lambda w0^2)` is then at most 0.045, 0.09 and 0.18 cycle
/// for INS 1 and twice that for INS 2 (a Costas loop slips at 0.25).
pub const NARROW_INS1_BIAS_MG: [f64; 3] = [0.5, 1.0, 2.0];
/// INS 1 bias of the narrow rows other than the bias grid's (Bn other than [`HEADLINE_BN_HZ`]),
/// mg.
pub const NARROW_DEFAULT_BIAS_MG: f64 = 1.0;
/// Accelerometer bias magnitude of INS 1 for the wide (2-18 Hz) and 1st-order rows, m/s^2
/// (about 5 mg; INS 2 has twice it): large enough for the bias's effect to stand out of the
/// noise of a wide loop (2nd-order 3 Hz: 1.7 deg mean error; 1st-order 18 Hz: 0.76 deg/s).
pub const WIDE_INS1_BIAS_MPS2: f64 = 0.05;
/// INS output rate, Hz.
pub const INS_RATE_HZ: f64 = 100.0;
/// Sampling interval of the satellites-tracked count, s.
pub const TICK_S: f64 = 0.1;
/// Bandwidth of the headline comparison (seed 004 Figs. 12 and 15, Table 3), Hz.
pub const HEADLINE_BN_HZ: f64 = 0.4;
/// Bandwidths of the narrow rows, Hz (seed 004 Fig. 14 used 0.1, 0.5 and 0.8 Hz).
pub const NARROW_BN_HZ: [f64; 4] = [0.1, 0.2, HEADLINE_BN_HZ, 0.8];
/// Bandwidths of the wide rows, Hz.
pub const WIDE_BN_HZ: [f64; 5] = [2.0, 3.0, 5.0, 10.0, 18.0];
/// Bandwidth of the aided 1st-order loops, Hz: wide enough that INS 2's growing error
/// `theta_1(t)` stays inside the Costas discriminator's linear range to the end of the run.
pub const ORDER1_BN_HZ: f64 = 18.0;

/// Time the staged narrowing takes from the pull-in loop to a loop of `bn_hz`, s: the stages
/// at `PULL_IN_BN_HZ / 2^k` (k >= 1) down to the last one within [`NARROW_RATIO`] of the
/// target, each held [`STAGE_BN_S`] / Bn (`tracking/src/channel/narrowing.rs`).
pub fn narrowing_s(bn_hz: f64) -> f64 {
    let (mut bw, mut t) = (PULL_IN_BN_HZ, 0.0);
    while bn_hz > 0.0 && bn_hz * NARROW_RATIO < bw {
        bw /= NARROW_RATIO;
        t += STAGE_BN_S / bw;
    }
    t
}

/// Lead-in for a scenario whose narrowest loop is `bn_hz`: [`LEAD_IN_S`], or longer when the
/// hand-over, the narrowing and the settling ([`SETTLE_BN_S`]) of that loop need more, rounded
/// up to whole seconds.
pub fn lead_in_s(bn_hz: f64) -> f64 {
    let need = HAND_OVER_S + narrowing_s(bn_hz) + SETTLE_BN_S / bn_hz;
    LEAD_IN_S.max(need.ceil())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lead_in_covers_the_narrowing() {
        // 15 Hz -> 7.5, 3.75, 1.875, 0.9375, 0.469 Hz stages, then 0.4 Hz: 8.27 s.
        let t = narrowing_s(0.4);
        assert!((t - 8.2667).abs() < 1e-3, "{t}");
        assert_eq!(narrowing_s(18.0), 0.0);
        assert_eq!(lead_in_s(0.4), LEAD_IN_S);
        assert_eq!(lead_in_s(3.0), LEAD_IN_S);
        // 0.1 Hz: two more stages (0.234, 0.117 Hz: 25.6 s), 1.5 s hand-over, 12 s settling.
        assert_eq!(lead_in_s(0.1), 48.0);
        assert!(lead_in_s(0.2) < 48.0 && lead_in_s(0.2) > LEAD_IN_S);
    }
}
