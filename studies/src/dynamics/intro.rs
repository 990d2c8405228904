//! The introduction of `study.md`: the setup and what the columns mean.

use super::params::{
    lead_in_s, CLOCK_DRIFT_S_S, FS_HZ, INS_RATE_HZ, LEAD_IN_S, NARROW_BN_HZ,
    NARROW_DEFAULT_BIAS_MG, NARROW_INS1_BIAS_MG, OSCILLATOR, RAMP_S, SPEED_MPS, STEP_S, TAIL_S,
    TICK_S, TURN_S, WIDE_INS1_BIAS_MPS2,
};
use super::DynamicsArgs;

pub(super) fn intro_md(args: &DynamicsArgs) -> String {
    format!(
        "Simulated IF (complex float, {fs} MHz, every visible satellite at one C/N0, data bits on) \
of a vehicle cruising at {SPEED_MPS} m/s for a lead-in of {LEAD_IN_S} s ({long} s for the \
scenarios of the loops narrower than 0.4 Hz), then a jerk-limited manoeuvre (acceleration ramped \
over {RAMP_S} s in and out): a level left turn at N g for {TURN_S} s, or a longitudinal \
acceleration step of N g for {STEP_S} s; then {TAIL_S} s of cruise after the ramp-out. Receiver \
oscillator: {osc} (two-state clock: white FM, Allan deviation {adev:e} at 1 s, random-walk FM \
h_-2 = {h:e}), drift {CLOCK_DRIFT_S_S:e} s/s. Channels start from truth at t = 0 and are set up \
as `gpsrx run` sets them up: unaided (`--no-aiding --pll-order N --pll-bw B`) the case's PLL is \
the tracking loop; aided (`--ins --aided-pll-order N --aided-pll-bw B`) it is the aided loop, \
taken once the feed-forward is on; either way the channel narrows in stages (Bn halved per \
stage, each held 2 / Bn) from its 15 Hz pull-in loop (no FLL after pull-in, T = 1 ms, 1 Hz \
carrier-aided DLL, no weak-signal loops). The lead-in covers the hand-over, the narrowing and \
the settling of the narrowest loop of its scenario (0.4 Hz: {l04} s). Aided cases use the \
receiver's INS feed-forward (`gpsrx run --ins` path, not gated by the integrity monitor) with an \
INS made from the truth by the INS error model: accelerometer bias |B| along (1, 1, 1)/sqrt(3) \
east-north-up, INS 2 twice INS 1's, {INS_RATE_HZ} Hz; INS 1 = {narrow:?} mg at 0.4 Hz (seed 004 \
Table 3), {nd} mg at the other Bn below 1 Hz ({bns:?} Hz), {wide} m/s^2 for the 2-18 Hz and \
1st-order loops (where a sub-mg bias is lost in the noise); a fix at t = 0 gives the \
feed-forward the position and clock drift. Seed {seed}{quick}.\n\n\
Columns: *bias* = the case's INS bias; *tracked* = channels in Track with the PLL lock indicator \
on, sampled every {TICK_S} s over the manoeuvre window (ramp-in start to ramp-out end), min and \
mean; *kept* = tracked at every sample of the window; *lock drops* = lock-indicator drops from \
the window start to the end of the run; *lost* = channels released (C/N0 below 25 dB-Hz for \
1 s). Over the window, while tracked: *phase std* = NCO minus true carrier phase, offset and \
Costas half-cycle removed per satellite, pooled; *disc. std* = the Costas discriminator \
atan(Q/I) (what seed 004 Table 3 measured), pooled; *mean abs phase err* = |mean discriminator| \
averaged over satellites, against *predicted* = the bias theory: 1st order \
360 B_V t / (lambda omega0) (growing, at the mean time), 2nd order 360 B_V / (lambda omega0^2), \
3rd order 0, with B_V = B . u per satellite (unit vector u to the satellite, t from the INS \
start at t = 0); *growth* = least-squares slope of the discriminator over the window against \
1st order 360 B_V / (lambda omega0), else 0 (these four over the satellites in Track, locked or \
not, for at least half of the window without a cycle slip; aided cases only); *PRR std* = \
(NCO Doppler - true Doppler) x lambda; *hand-over df rms* = NCO frequency error over each \
channel's first 20 ms in Track, rms over channels.",
        fs = FS_HZ / 1e6,
        long = lead_in_s(NARROW_BN_HZ[0]),
        l04 = lead_in_s(0.4),
        osc = OSCILLATOR.name,
        adev = OSCILLATOR.allan_deviation_1s,
        h = OSCILLATOR.h_m2,
        narrow = NARROW_INS1_BIAS_MG,
        nd = NARROW_DEFAULT_BIAS_MG,
        bns = NARROW_BN_HZ,
        wide = WIDE_INS1_BIAS_MPS2,
        seed = args.common.seed,
        quick = if args.common.quick {
            " (--quick: the 10 g turn at 45 dB-Hz, orders 2 and 3 at 0.4 Hz with a 1 mg INS 1, and the aided 1st-order loops)"
        } else {
            ""
        },
    )
}
