//! The introduction of `study.md`: the setup and what the columns mean.

use super::params::{
    ALLAN_DEVIATION_1S, CLOCK_DRIFT_S_S, DURATION_S, FS_HZ, INS1_BIAS_MPS2, INS_RATE_HZ, LEAD_IN_S,
    RAMP_S, SPEED_MPS, STEP_S, TICK_S, TURN_S,
};
use super::DynamicsArgs;

pub(super) fn intro_md(args: &DynamicsArgs) -> String {
    format!(
        "Simulated IF (complex float, {fs} MHz, every visible satellite at one C/N0, data bits on) \
of a vehicle cruising at {SPEED_MPS} m/s for {LEAD_IN_S} s, then a jerk-limited manoeuvre \
(acceleration ramped over {RAMP_S} s in and out): a level left turn at N g for {TURN_S} s, or a \
longitudinal acceleration step of N g for {STEP_S} s; {DURATION_S} s in all. Receiver \
oscillator: white FM, Allan deviation {ALLAN_DEVIATION_1S:e} at 1 s, drift {CLOCK_DRIFT_S_S:e} s/s. \
Channels start from truth at t = 0 (default FLL-assisted pull-in, then the case's PLL, no FLL, \
T = 1 ms, 1 Hz carrier-aided DLL). Aided cases use the receiver's INS feed-forward \
(`gpsrx run --ins` path) with an INS made from the truth by the INS error model: accelerometer \
bias |B| = {b1} m/s^2 (INS 1) or {b2} m/s^2 (INS 2) along (1, 1, 1)/sqrt(3) east-north-up, \
{INS_RATE_HZ} Hz; a fix at t = 0 gives it the position and clock drift. Seed {seed}{quick}.\n\n\
Columns: *tracked* = channels in Track with the PLL lock indicator on, sampled every {TICK_S} s \
over the manoeuvre window (ramp-in start to ramp-out end), min and mean; *kept* = tracked at \
every sample of the window; *lock drops* = lock-indicator drops from the window start to the end \
of the run; *lost* = channels released (C/N0 below 25 dB-Hz for 1 s). Over the window, while \
tracked: *phase std* = NCO minus true carrier phase, offset and Costas half-cycle removed per \
satellite, pooled; *disc. std* = the Costas discriminator atan(Q/I) (what seed 004 Table 3 \
measured); *mean abs phase err* = |mean discriminator| averaged over satellites, against \
*predicted* = the bias theory: 1st order 360 B_V t / (lambda omega0) (growing, at the mean \
time), 2nd order 360 B_V / (lambda omega0^2), 3rd order 0, with B_V = B . u per satellite \
(unit vector u to the satellite, t from the INS start at t = 0); *growth* = least-squares slope \
of the discriminator over the window against 1st order 360 B_V / (lambda omega0), else 0 (these \
four over the satellites in Track, locked or not, for at least half of the window without a \
cycle slip; aided cases only); *PRR std* = (NCO Doppler - true Doppler) x lambda; *hand-over df \
rms* = NCO frequency error over each channel's first 20 ms in Track, rms over channels.",
        fs = FS_HZ / 1e6,
        b1 = INS1_BIAS_MPS2,
        b2 = 2.0 * INS1_BIAS_MPS2,
        seed = args.common.seed,
        quick = if args.common.quick {
            " (--quick: the 10 g turn at 45 dB-Hz only)"
        } else {
            ""
        },
    )
}
