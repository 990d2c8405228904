//! The conclusions of `study.md` on the headline cases: unaided vs aided, INS 1 vs INS 2, and
//! the 1st-order aided loop.

use super::headline::Headline;
use gpsrx_dsp::constants::LAMBDA_L1_M;
use gpsrx_samples::sim::trajectory::G0_MPS2;

pub(super) fn conclusions_md(h: &Headline<'_>) -> String {
    let (Some(u), Some(i1), Some(i2)) = (h.unaided, h.ins1, h.ins2) else {
        return String::new();
    };
    let mut s = format!(
        "**10 g turn, {cn0} dB-Hz, 2nd-order PLL at Bn = {bn} Hz.** Unaided, the loop kept as few \
as {umin} of {n} satellites (mean {umean:.1}; {ukept} kept throughout, {udrops} lock drops, {ulost} \
channels lost): a 2nd-order loop's steady-state error is 0.2809 a / Bn^2, {ss:.0} cycles for 10 g \
along the line of sight at {bn} Hz, and the turn swings every satellite's line-of-sight \
acceleration through +-10 g cos(elevation). Seed 004 Fig. 12 saw its 0.4 Hz loop drop to 4 \
satellites (its manoeuvre and geometry are not given; a 0.4 Hz loop cannot follow even the \
satellites' own line-of-sight acceleration of up to 0.18 m/s^2 here, 1.7 cycles of error, so \
{bn} Hz is the narrowest unaided 2nd-order loop that holds every satellite before the manoeuvre). \
Aided by INS 1 the loop kept {k1} of {n} (min {m1}, {d1n} lock drops), by INS 2 {k2} \
of {n} (min {m2}, {d2n} lock drops): seed 004 Fig. 15 kept >= 8, all it had.\n\n\
**INS 1 vs INS 2 (seed 004 Table 3).** The aided 2nd-order loop's phase error std against truth \
is {p1:.4} vs {p2:.4} cycle (ratio {std_ratio:.2}); the discriminator std (Table 3's measure) \
{d1:.4} vs {d2:.4} cycle. The bias changes only the *mean* error, {e1:.2} vs {e2:.2} deg (theory \
360 B_V / (lambda omega0^2): {t1:.2} vs {t2:.2} deg), a constant held by the loop's integrator \
(growth {g1:.3} and {g2:.3} deg/s): what is left is thermal and oscillator noise, the same for \
both INS, as in Table 3 (0.085-0.101 cycle there, a real front end at 0.4 Hz; ours {d1:.3} cycle \
at {cn0} dB-Hz and T = 1 ms). The loop is linear and both INS see the same noise, so the two stds \
agree to the digits shown.\n\n",
        cn0 = u.spec.cn0_dbhz,
        bn = u.case.bn_hz,
        umin = u.tracked_min,
        n = u.satellites,
        umean = u.tracked_mean,
        ukept = u.kept,
        udrops = u.lock_drops,
        ulost = u.channels_lost,
        ss = 0.2809 * 10.0 * G0_MPS2 / (u.case.bn_hz * u.case.bn_hz) / LAMBDA_L1_M,
        k1 = i1.kept,
        m1 = i1.tracked_min,
        d1n = i1.lock_drops,
        k2 = i2.kept,
        m2 = i2.tracked_min,
        d2n = i2.lock_drops,
        p1 = i1.phase_std_cycles,
        p2 = i2.phase_std_cycles,
        std_ratio = h.std_ratio(),
        d1 = i1.disc_std_cycles,
        d2 = i2.disc_std_cycles,
        e1 = i1.disc_mean_abs_deg,
        e2 = i2.disc_mean_abs_deg,
        t1 = i1.predicted_mean_abs_deg,
        t2 = i2.predicted_mean_abs_deg,
        g1 = i1.growth_abs_deg_s,
        g2 = i2.growth_abs_deg_s,
    );
    if let (Some(a), Some(b)) = (h.order1_ins1, h.order1_ins2) {
        s += &format!(
            "**1st-order aided loop (Bn = {bn} Hz).** Its error grows with the INS velocity error \
B_V t: {g1:.3} deg/s with INS 1 and {g2:.3} deg/s with INS 2 (ratio {gr:.2}; theory \
360 B_V / (lambda omega0): {tg1:.3} and {tg2:.3} deg/s); mean |phase error| over the manoeuvre \
{e1:.2} and {e2:.2} deg (ratio {er:.2}; theory {t1:.2} and {t2:.2} deg, the rest is the \
frequency offset the loop was handed over with, which a 1st-order loop never removes); \
satellites kept {k1} and {k2} of {n}, lock drops {l1} and {l2}. The error scales with the bias \
and keeps growing, so an aided loop needs order >= 2: seed 004's conclusion (its Table 1 gives \
the 1st-order bias entry as a constant; the bias is a Doppler ramp, and the measured growth \
confirms the ramp).\n\n",
            bn = a.case.bn_hz,
            g1 = a.growth_abs_deg_s,
            g2 = b.growth_abs_deg_s,
            gr = h.order1_growth_ratio(),
            tg1 = a.predicted_growth_deg_s,
            tg2 = b.predicted_growth_deg_s,
            e1 = a.disc_mean_abs_deg,
            e2 = b.disc_mean_abs_deg,
            er = h.order1_mean_ratio(),
            t1 = a.predicted_mean_abs_deg,
            t2 = b.predicted_mean_abs_deg,
            k1 = a.kept,
            k2 = b.kept,
            n = a.satellites,
            l1 = a.lock_drops,
            l2 = b.lock_drops,
        );
    }
    s
}
