//! The tracking channel: one satellite's replica, loops and detectors, driven code period by
//! code period over a shared window of samples.
//!
//! States: [`ChannelState::PullIn`] (1 ms integration, the wide FLL-assisted pull-in loops,
//! bit synchronisation; or, for an acquisition below [`WeakPullInConfig::enter_dbhz`], the
//! weak-signal pull-in of [`weak_pull_in`](WeakPullInConfig): FLL on 10 ms sums, differential
//! bit synchronisation, bit-aligned 20 ms PLL) -> [`ChannelState::Track`] (the user's loops
//! and integration time, integrations aligned to data-bit edges) -> [`ChannelState::Lost`]
//! (C/N0 below the threshold for too long: the channel is released and the satellite goes back
//! to acquisition).
//!
//! Every integration starts at the first sample of a C/A code period of the replica: the span of
//! a period is `n = ceil((1023 - c0) fs / r)` samples for a code phase `c0` (chips, in [0, 1))
//! at its first sample and code rate `r`, and the next period starts at `c0 + n r / fs - 1023`.
//! The NCO frequencies are held over each integration interval (phase-continuous) and updated by
//! the loops at its end. The carrier NCO runs at the fed-forward Doppler plus the loop filter
//! output (seed 004 Fig. 4); the code NCO at `1.023 MHz (1 + f_carrier / f_L1)` plus the DLL
//! output (carrier aiding).

use crate::aiding::{code_doppler_chips_s, DopplerAid};
use crate::bit_sync::{Bit, BitSync, BitSyncConfig, BitSyncState, MS_PER_BIT};
use crate::carrier_loop::{CarrierLoop, CarrierOutput};
use crate::cn0::SmoothedNwpr;
use crate::code_loop::{CodeLoop, CodeOutput};
use crate::config::{ConfigError, LoopConfig};
use crate::correlator_choice::{CorrelatorArithmetic, CorrelatorIsa};
use crate::fade_detector::FadeDetector;
use crate::lock_detector::{CodeLockDetector, PllLockConfig, PllLockDetector};
use crate::phase_fit::QuadraticPhaseFit;
use gpsrx_dsp::acquisition::AcqResult;
use gpsrx_dsp::ca_code::{CaCode, Prn};
use gpsrx_dsp::constants::{CA_CHIP_RATE_HZ, CA_CODE_LENGTH, F_L1_HZ};
use gpsrx_dsp::correlator::{Correlator, PackedCode, ReplicaState, SampleSlice};
use num_complex::{Complex32, Complex64};
use serde::{Deserialize, Serialize};

mod narrowing;
mod realign;
mod recover;
mod weak_pull_in;
pub use realign::CodeShift;
use weak_pull_in::WeakStage;
pub use weak_pull_in::{WeakPullInConfig, PRESYNC_BLOCK_PROMPTS, PRESYNC_EDGE_LOSS_DB};

/// Channel settings: the pull-in and tracking loops and the lock thresholds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ChannelConfig {
    /// Loops during pull-in (1 ms integration, wide, FLL-assisted).
    pub pull_in: LoopConfig,
    /// Loops after pull-in: the user's order, bandwidth and integration time.
    pub track: LoopConfig,
    /// Loops after pull-in while the aiding port has a feed-forward (`None`: the same as
    /// `track`). The feed-forward removes the dynamics from the loop (seed 004 eq. 7), so an aided
    /// loop can be much narrower than an unaided one and let through less noise; the channel
    /// switches between `track` and these at a data-bit edge whenever the aid comes or goes.
    pub aided_track: Option<LoopConfig>,
    /// Loops after pull-in for weak signals (`None`: never switch): taken while the C/N0 is
    /// below `weak_enter_dbhz`, left when it climbs above `weak_leave_dbhz` (switches at a
    /// data-bit edge). Longer integration and narrower loops hold weaker signals (phase jitter
    /// `sqrt(Bn/(C/N0) (1 + 1/(2 T C/N0)))`) but follow less dynamics, so the default `track`
    /// loops can stay wide enough for 10 g. An aided channel runs `aided_track` instead, with
    /// these loops' integration time while weak (when its bandwidth allows it).
    pub weak_track: Option<LoopConfig>,
    /// Loops for a weak signal whose measurements the navigation filter of vector tracking
    /// checks ([`DopplerAid::checked`]; `None`: `weak_track`, or `aided_track` if set). The
    /// filter's feed-forward takes the dynamics out, so the loop can be narrower than
    /// `weak_track` (3rd order at 3 Hz instead of 6: half the thermal phase variance, 15 deg
    /// of jitter at 17.9 dB-Hz instead of 20.3 with 20 ms), its 3rd order following what the
    /// prediction, 0.2-0.3 s behind, misses of a changing acceleration.
    pub vector_weak_track: Option<LoopConfig>,
    /// C/N0 below which the channel takes the `weak_track` loops, dB-Hz.
    pub weak_enter_dbhz: f64,
    /// C/N0 above which it goes back to `track`, dB-Hz (> `weak_enter_dbhz`: hysteresis).
    pub weak_leave_dbhz: f64,
    /// Minimum time in pull-in before the hand-over to tracking, s.
    pub min_pull_in_s: f64,
    /// Time after which the FLL assist of the pull-in loop is switched off, s: the
    /// data-insensitive FLL discriminator folds on noise at low C/N0 and would keep kicking the
    /// NCO (tracking/README.md), so the PLL finishes the pull-in alone.
    pub fll_assist_s: f64,
    /// C/N0 below which the code is considered lost, dB-Hz.
    pub cn0_lost_dbhz: f64,
    /// C/N0 below which a channel whose measurements the navigation filter of vector tracking
    /// checks ([`DopplerAid::checked`]) is considered lost, dB-Hz (a value above
    /// `cn0_lost_dbhz` acts as `cn0_lost_dbhz`).
    /// A scalar channel needs the margin of `cn0_lost_dbhz` against false locks and
    /// cross-correlations, which nothing else checks; a checked one's pseudorange and Doppler
    /// pass the filter's innovation test against the other satellites every epoch. The
    /// default, 19 dB-Hz, leaves the limit to physics: the 20 ms lock detector's
    /// `|E[exp(2 j phi)]|` is at most `rho/(rho+1)` (`rho = T C/N0`), below its 0.7 under
    /// 20.7 dB-Hz, where the 3 Hz vector loop's thermal jitter is 11 deg; the estimate reads
    /// 0.4-0.9 dB low there (1.3 dB scatter per 0.2 s), so five estimates in a row under 19
    /// release a channel near 20 dB-Hz. Noise reads at most 15 dB-Hz once the signal has gone
    /// (8 channels through a 3 s blockage). Measured on a fade (`scripts/vector-threshold.py`):
    /// the observables of 19-22 dB-Hz carry pseudorange errors of 13 m RMS (the 0.5 Hz DLL's
    /// thermal noise, 17 m at 21 dB-Hz) and no carrier cycle slip.
    pub vector_cn0_lost_dbhz: f64,
    /// Length of one C/N0 estimate (NWPR over 20 ms blocks aligned to data bits), s: a multiple
    /// of 20 ms. 0.2 s estimates scatter by about 0.5 dB; 1 s ones by 0.2 dB.
    pub cn0_window_s: f64,
    /// How many consecutive C/N0 estimates below the threshold release the channel.
    pub lost_estimates: u32,
    /// Time without phase lock after which a tracking channel goes back through a pull-in of
    /// its carrier ([`ChannelState::Recover`]), s (0: never; it then stays in tracking until
    /// its C/N0 is lost).
    pub relock_after_s: f64,
    /// Longest recovery before the channel is released and the satellite searched again, s.
    pub recover_s: f64,
    /// The weak-signal pull-in (`None`: every channel takes the `pull_in` loops): a channel
    /// whose acquisition C/N0 is below [`WeakPullInConfig::enter_dbhz`] pulls in with an FLL on
    /// 10 ms sums, differential bit synchronisation and a bit-aligned 20 ms PLL instead, then
    /// tracks with `weak_track` ([`weak_pull_in`](crate::channel::WeakPullInConfig)).
    pub weak_pull_in: Option<WeakPullInConfig>,
    /// The widest instruction set of the correlator kernel (`auto`: the widest this CPU runs;
    /// `avx2` on an AVX-512 machine times what an AVX2-only CPU does).
    pub correlator: CorrelatorIsa,
    /// The correlator's arithmetic: `auto` (the faster per block format: int16 on ci8 with
    /// AVX2, f32 otherwise), `f32` or `i16` ([`CorrelatorArithmetic`]).
    pub correlator_arithmetic: CorrelatorArithmetic,
    /// Who drives the NCOs: `scalar` (the default) or `vector` (the receiver's navigation
    /// filter feeds every channel forward, [`crate::aiding::TrackingMode`]). The channel itself
    /// only sees the aiding port; the receiver reads this.
    pub mode: crate::aiding::TrackingMode,
}

/// The default weak-signal loops ([`ChannelConfig::weak_track`]; the comment at their use).
fn default_weak_track() -> LoopConfig {
    LoopConfig {
        pll_order: 3,
        pll_bw_hz: 6.0,
        fll_order: 0,
        fll_bw_hz: 0.0,
        dll_order: 1,
        dll_bw_hz: 0.5,
        t_coh_s: 20.0e-3,
        el_spacing_chips: 1.0,
        ..LoopConfig::default()
    }
}

impl Default for ChannelConfig {
    fn default() -> Self {
        Self {
            pull_in: LoopConfig::default(),
            // 3rd order at 18 Hz: no steady-state error under constant acceleration, and a
            // 10 g manoeuvre with a 0.5 s jerk ramp (~200 m/s^3) costs ~0.085 cycle of
            // phase (j / (lambda wn^3), wn = Bn / 0.7845).
            track: LoopConfig {
                pll_order: 3,
                pll_bw_hz: 18.0,
                fll_order: 0,
                fll_bw_hz: 0.0,
                dll_order: 1,
                dll_bw_hz: 1.0,
                t_coh_s: 1.0e-3,
                el_spacing_chips: 1.0,
                ..LoopConfig::default()
            },
            aided_track: None,
            // Below 32 dB-Hz: 20 ms coherent (bit-aligned), 3rd-order PLL at 6 Hz, DLL 0.5 Hz.
            // 3rd order: no steady-state phase error under a constant LOS acceleration (a 2nd
            // order loop at 5 Hz lags `(a/lambda)/wn^2` = 32 deg at 1.5 m/s^2, past the lock
            // indicator's 22.8 deg, so a weak satellite of an accelerating car was dropped
            // from the fixes); a 0.5 s jerk ramp to 1.5 m/s^2 (3 m/s^3 = 15.8 Hz/s^2) costs
            // `j/wn^3` = 0.035 cycle (wn = 6/0.7845 = 7.65 rad/s); thermal jitter at 28 dB-Hz
            // 6.4 deg with the realised Bn (7.6 Hz at Bn T = 0.12, tracking/README.md).
            weak_track: Some(default_weak_track()),
            vector_weak_track: Some(LoopConfig {
                pll_bw_hz: 3.0,
                ..default_weak_track()
            }),
            weak_enter_dbhz: 32.0,
            weak_leave_dbhz: 35.0,
            min_pull_in_s: 0.5,
            fll_assist_s: 0.3,
            cn0_lost_dbhz: 25.0,
            vector_cn0_lost_dbhz: 19.0,
            cn0_window_s: 0.2,
            lost_estimates: 5,
            // A slipped narrow loop does not come back by itself (issue 25): after 2 s out of
            // lock, pull in again (a normal pull-in locks within 0.5-1 s, a weak one within a
            // few seconds). Not sooner: the 20 ms weak loops at 30 dB-Hz drop out of lock for
            // up to 1.5 s and come back by themselves (measured on the simulator, 60 s static:
            // with 1 s, two recoveries cost G16 3 % of its locked time).
            relock_after_s: 2.0,
            recover_s: 5.0,
            weak_pull_in: Some(WeakPullInConfig::default()),
            correlator: CorrelatorIsa::Auto,
            correlator_arithmetic: CorrelatorArithmetic::Auto,
            mode: crate::aiding::TrackingMode::Scalar,
        }
    }
}

impl ChannelConfig {
    /// Checks both loop configurations and the thresholds.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.pull_in.validate()?;
        if let Some(w) = &self.weak_pull_in {
            w.validate()?;
        }
        let others = self
            .aided_track
            .iter()
            .chain(self.weak_track.iter())
            .chain(self.vector_weak_track.iter());
        for l in std::iter::once(&self.track).chain(others) {
            l.validate()?;
            let ms = (l.t_coh_s * 1e3).round() as usize;
            if ms == 0 || !MS_PER_BIT.is_multiple_of(ms) {
                return Err(ConfigError::OutOfRange {
                    field: "t_coh_s",
                    value: l.t_coh_s,
                    valid: "1, 2, 4, 5, 10 or 20 ms (a divisor of the 20 ms data bit)".into(),
                });
            }
        }
        if !(self.min_pull_in_s.is_finite() && self.min_pull_in_s >= 0.0) {
            return Err(ConfigError::OutOfRange {
                field: "min_pull_in_s",
                value: self.min_pull_in_s,
                valid: ">= 0 s".into(),
            });
        }
        if !(self.cn0_window_s.is_finite()
            && self.cn0_window_s >= 0.02
            && self.cn0_window_s <= 10.0)
        {
            return Err(ConfigError::OutOfRange {
                field: "cn0_window_s",
                value: self.cn0_window_s,
                valid: "0.02 to 10 s".into(),
            });
        }
        if !(self.fll_assist_s.is_finite() && self.fll_assist_s >= 0.0) {
            return Err(ConfigError::OutOfRange {
                field: "fll_assist_s",
                value: self.fll_assist_s,
                valid: ">= 0 s".into(),
            });
        }
        if !(self.weak_enter_dbhz.is_finite()
            && self.weak_leave_dbhz.is_finite()
            && self.weak_leave_dbhz > self.weak_enter_dbhz)
        {
            return Err(ConfigError::OutOfRange {
                field: "weak_leave_dbhz",
                value: self.weak_leave_dbhz,
                valid: format!(
                    "a C/N0 above weak_enter_dbhz = {} dB-Hz",
                    self.weak_enter_dbhz
                ),
            });
        }
        for (field, value) in [
            ("relock_after_s", self.relock_after_s),
            ("recover_s", self.recover_s),
        ] {
            if !(value.is_finite() && (0.0..=600.0).contains(&value)) {
                return Err(ConfigError::OutOfRange {
                    field,
                    value,
                    valid: "0 to 600 s".into(),
                });
            }
        }
        if !self.cn0_lost_dbhz.is_finite() {
            return Err(ConfigError::OutOfRange {
                field: "cn0_lost_dbhz",
                value: self.cn0_lost_dbhz,
                valid: "a C/N0 in dB-Hz".into(),
            });
        }
        if !self.vector_cn0_lost_dbhz.is_finite() {
            return Err(ConfigError::OutOfRange {
                field: "vector_cn0_lost_dbhz",
                value: self.vector_cn0_lost_dbhz,
                valid: "a C/N0 in dB-Hz".into(),
            });
        }
        Ok(())
    }
}

/// Where a channel is in its life.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChannelState {
    /// Wide loops at 1 ms (or the weak-signal pull-in's 10 ms FLL and 20 ms PLL), waiting for
    /// phase lock and bit synchronisation.
    PullIn,
    /// The user's loops, integrations aligned to data bits.
    Track,
    /// Carrier lock lost in tracking for [`ChannelConfig::relock_after_s`]: code-only
    /// tracking while the carrier is pulled in again (the pull-in loops, or the weak
    /// pull-in's phase stage); back to [`ChannelState::Track`] on phase lock, released after
    /// [`ChannelConfig::recover_s`]. Its measurements are not used.
    Recover,
    /// Signal lost: release the channel.
    Lost,
}

/// A satellite found by acquisition, to start a channel from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelStart {
    /// The satellite.
    pub prn: Prn,
    /// Absolute index of a sample at which a C/A code period starts.
    pub code_start_sample: u64,
    /// Carrier Doppler, Hz (including any front-end frequency offset).
    pub doppler_hz: f64,
    /// C/N0 estimate from acquisition, dB-Hz (NaN if unknown): reported until the channel's
    /// own estimate is available.
    pub cn0_dbhz: f64,
}

impl ChannelStart {
    /// The start of a channel for a detection of a search whose first sample was
    /// `first_sample` (code phases count from it).
    pub fn from_acquisition(d: &AcqResult, first_sample: u64) -> Self {
        Self {
            prn: d.prn,
            code_start_sample: first_sample + d.code_phase_samples.round().max(0.0) as u64,
            doppler_hz: d.doppler_hz,
            cn0_dbhz: d.cn0_dbhz.unwrap_or(f64::NAN),
        }
    }
}

/// What a channel reports at the end of each integration interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelEpoch {
    /// Satellite PRN.
    pub prn: u8,
    /// State during the interval.
    pub state: ChannelState,
    /// Absolute index of the first sample of the interval.
    pub sample_index: u64,
    /// Receive time of that sample (index / fs), s.
    pub t_rx_s: f64,
    /// Replica code phase at that sample, chips (near 0: intervals start on code periods).
    pub code_phase_chips: f64,
    /// Code NCO rate over the interval, chips/s.
    pub code_rate_chips_s: f64,
    /// Accumulated carrier phase of the replica at that sample, cycles (continuous).
    pub carrier_phase_cycles: f64,
    /// Carrier NCO frequency over the interval (Doppler, Hz).
    pub doppler_hz: f64,
    /// Latest C/N0 estimate, dB-Hz (NaN before the first).
    pub cn0_dbhz: f64,
    /// The C/N0 below which the channel counted as lost over the interval, dB-Hz
    /// ([`ChannelConfig::cn0_lost_dbhz`], or [`ChannelConfig::vector_cn0_lost_dbhz`] while the
    /// navigation filter checks it): below it the report gives no observables.
    pub cn0_lost_dbhz: f64,
    /// Phase lock: the `cos 2 phi` indicator says locked and the prompt power has not just
    /// collapsed ([`crate::fade_detector`]: a wide PLL on noise keeps `cos 2 phi` high for a
    /// second after a blockage). Measurements are usable only with it.
    pub pll_lock: bool,
    /// `cos 2 phi` of the phase-lock indicator.
    pub pll_lock_metric: f64,
    /// Code (C/N0) lock.
    pub code_lock: bool,
    /// Prompt correlation of the interval.
    pub prompt: Complex64,
    /// Early correlation.
    pub early: Complex64,
    /// Late correlation.
    pub late: Complex64,
    /// PLL discriminator output, cycles.
    pub phase_error_cycles: f64,
    /// FLL discriminator output, Hz.
    pub freq_error_hz: f64,
    /// DLL discriminator output, chips.
    pub code_error_chips: f64,
    /// Integration time of the interval, s.
    pub t_coh_s: f64,
    /// The feed-forward Doppler the carrier NCO held over the interval, Hz (None: unaided).
    pub feedforward_hz: Option<f64>,
    /// The loops coasted on the aid at the end of the interval (the signal gone, an aid that
    /// predicts it, [`DopplerAid::coast`]): the NCOs follow the aid alone, so the carrier
    /// phase over the coast is the aid's prediction of the range change.
    pub coasting: bool,
    /// Milliseconds since the channel started (count of code periods).
    pub ms_count: u64,
    /// Whether the interval starts on a data-bit edge (known after bit sync).
    pub bit_edge: bool,
    /// The navigation bit completed in this interval, if any.
    pub bit: Option<Bit>,
    /// `ms_count` of the first code period of that bit (its leading edge), for time tagging.
    pub bit_start_ms: Option<u64>,
}

/// One tracking channel.
#[derive(Debug, Clone)]
pub struct Channel {
    prn: Prn,
    /// The C/A code, bit-packed for the correlator, built once.
    packed_code: PackedCode,
    /// The correlator kernel ([`ChannelConfig::correlator`]), chosen once.
    correlator: Correlator,
    fs_hz: f64,
    cfg: ChannelConfig,
    state: ChannelState,
    carrier: CarrierLoop,
    code_loop: CodeLoop,
    pll_lock: PllLockDetector,
    fade: FadeDetector,
    code_lock: CodeLockDetector,
    cn0: SmoothedNwpr,
    cn0_started: bool,
    /// The bit edges are sought again ([`Channel::restart_bit_sync`]): the Costas gain holds
    /// its C/N0 until the first new edge and [`COSTAS_HOLD_AFTER_EDGE_MS`] after it
    /// (`Some(u32::MAX)` while waiting for the edge, then the milliseconds left). The
    /// phase-lock detector's blocks straddle data-bit transitions meanwhile and read a C/N0
    /// too low, which would raise the loop's gain and bandwidth.
    costas_hold_ms: Option<u32>,
    /// The signal's weak-signal flag when its prompt power collapsed (`None`: not faded).
    /// An outage lowers the C/N0 estimates and sends the loops to the weak ones, which coast
    /// through it on their memories; the signal coming back has its old level.
    weak_before_fade: Option<bool>,
    /// Milliseconds left after a fade during which a C/N0 estimate below
    /// [`ChannelConfig::weak_enter_dbhz`] does not make the channel weak
    /// ([`FADE_RECOVERY_HOLD_MS`]).
    fade_hold_ms: u32,
    /// Milliseconds left after a fade coasted with a feed-forward during which low C/N0
    /// estimates do not release the channel ([`Channel::on_cn0_estimate`]).
    aided_fade_hold_ms: u32,
    cn0_window_blocks: u32,
    bit_sync: BitSync,
    /// Next integration's first sample (absolute index).
    next_sample: u64,
    /// Code phase (chips) at `next_sample`.
    code_phase_chips: f64,
    code_rate_chips_s: f64,
    /// Accumulated carrier phase (cycles) at `next_sample`.
    carrier_phase_cycles: f64,
    carrier_freq_hz: f64,
    /// The external Doppler estimate and the receive time (s) it refers to.
    aid: Option<(DopplerAid, f64)>,
    /// The feed-forward contained in the current NCO frequency, Hz (None: unaided).
    ff_applied_hz: Option<f64>,
    /// The Doppler rate of the last feed-forward applied, Hz/s (0 unaided).
    ff_rate_applied_hz_s: f64,
    /// The last loop update coasted on the aid (`Channel::coasting_on_aid`).
    coasted_last: bool,
    /// The source of the feed-forward applied over the last interval.
    ff_source: Option<crate::AidSource>,
    /// Receive time until which the aid counts as a manoeuvre's, s
    /// ([`AID_MANOEUVRE_HZ_S`]).
    aid_manoeuvre_until_s: f64,
    /// Which tracking loops run (after pull-in).
    loops: TrackLoops,
    /// The C/N0 has fallen below [`ChannelConfig::weak_enter_dbhz`] (and not yet climbed back
    /// above `weak_leave_dbhz`).
    weak: bool,
    /// `ms_count` at the hand-over to tracking.
    track_since_ms: u64,
    /// The receiver is under dynamics ([`Channel::set_dynamics`]): a weak channel runs the
    /// weak-signal loops widened for them ([`dynamic_weak_config`]).
    dynamics: bool,
    /// The feed-forward held over the interval being accumulated.
    acc_feedforward_hz: Option<f64>,
    ms_count: u64,
    /// `ms_count` of the first prompt the bit synchroniser saw since its last reset.
    bit_sync_origin_ms: u64,
    pull_in_ms: u64,
    cn0_dbhz: f64,
    /// The C/N0 while the signal was there (the highest estimate, slowly forgotten), dB-Hz;
    /// NaN before the first.
    tracked_cn0_dbhz: f64,
    /// The channel reached the tracking state (its pull-in confirmed the satellite).
    confirmed: bool,
    /// [`Channel::release`] was called: the channel ends with its current interval.
    release_requested: bool,
    /// The carrier loop is being narrowed in stages to its tracking loops.
    narrowing: Option<narrowing::Narrowing>,
    low_cn0_count: u32,
    /// Time without phase lock in tracking, ms.
    unlocked_ms: u64,
    /// Recoveries from a loss of carrier lock so far.
    recoveries: u32,
    /// Accumulators of the current interval: E, P, L. The early replica leads the prompt by
    /// d/2 chip (its code phase is `c + d/2`), the late one lags it.
    acc: [Complex64; 3],
    acc_ms: usize,
    acc_start: (u64, f64, f64, f64),
    taps: [f64; 3],
    /// Least-squares sums (t, f) of the NCO frequency during pull-in after the FLL assist is
    /// off: n, sum t, sum f, sum t^2, sum t f. They give the Doppler rate that presets a
    /// 3rd-order tracking loop at the hand-over.
    rate_fit: [f64; 5],
    /// A completed bit and the `ms_count` of its first code period, waiting for the end of the
    /// integration interval.
    pending_bit: Option<(Bit, u64)>,
    /// The least-squares fit of the carrier phase the loop tracks (NCO phase less the
    /// feed-forward's, plus the discriminator output): the frequency and Doppler rate a
    /// narrowed loop starts from ([`crate::phase_fit`]).
    phase_fit: QuadraticPhaseFit,
    /// The feed-forward's phase accumulated up to the start of the interval being summed,
    /// cycles.
    ff_phase_cycles: f64,
    /// The aid came (or went) at the last loop update: the feed-forward trajectory
    /// `(t_c, f, rate)` (negated when it went) the phase fit's samples are to be measured
    /// against from then on ([`QuadraticPhaseFit::subtract_trajectory`]).
    aid_switched: Option<(f64, f64, f64)>,
    /// The last step of a vector aid, fading (`Channel::aid_blend_hz`): (receive time s, Hz).
    aid_blend: Option<(f64, f64)>,
    /// The stage of a weak-signal pull-in (`None`: the normal pull-in, or after the hand-over).
    weak_stage: Option<WeakStage>,
    /// The weak pull-in's C/N0 estimator before bit synchronisation (NWPR over unaligned
    /// blocks of [`PRESYNC_BLOCK_PROMPTS`] prompts).
    presync_cn0: SmoothedNwpr,
}

impl Channel {
    /// A channel from an acquisition result.
    pub fn new(start: &ChannelStart, fs_hz: f64, cfg: &ChannelConfig) -> Result<Self, ConfigError> {
        cfg.validate()?;
        if !(fs_hz.is_finite() && fs_hz > 0.0) {
            return Err(ConfigError::OutOfRange {
                field: "fs_hz",
                value: fs_hz,
                valid: "> 0".into(),
            });
        }
        // A weak acquisition (C/N0 below the weak pull-in's threshold; NaN is not) starts with
        // the weak pull-in's frequency stage and its bit synchroniser.
        let weak_pull_in = cfg.weak_pull_in.filter(|w| start.cn0_dbhz < w.enter_dbhz);
        let first_loops = weak_pull_in.map_or(cfg.pull_in, |w| w.fll);
        let bit_sync_cfg = weak_pull_in.map_or(BitSyncConfig::default(), |w| w.bit_sync_config());
        let carrier = CarrierLoop::new(&first_loops, start.doppler_hz)?;
        let code_loop = CodeLoop::new(&first_loops)?;
        let d = first_loops.el_spacing_chips;
        let cn0_window_blocks = ((cfg.cn0_window_s / 0.02).round() as u32).max(1);
        Ok(Self {
            prn: start.prn,
            packed_code: PackedCode::new(CaCode::new(start.prn).chips()),
            correlator: cfg.correlator.correlator(cfg.correlator_arithmetic),
            fs_hz,
            cfg: *cfg,
            state: ChannelState::PullIn,
            carrier,
            code_loop,
            pll_lock: PllLockDetector::new(PllLockConfig::default()),
            fade: FadeDetector::new(),
            code_lock: CodeLockDetector::new(cfg.cn0_lost_dbhz, cfg.lost_estimates),
            cn0_started: false,
            costas_hold_ms: None,
            weak_before_fade: None,
            fade_hold_ms: 0,
            aided_fade_hold_ms: 0,
            cn0_window_blocks,
            cn0: SmoothedNwpr::new(
                1e-3,
                20,
                ((cfg.cn0_window_s / 0.02).round() as u32).max(1),
                5,
            ),
            bit_sync: BitSync::new(bit_sync_cfg),
            next_sample: start.code_start_sample,
            code_phase_chips: 0.0,
            code_rate_chips_s: CA_CHIP_RATE_HZ * (1.0 + start.doppler_hz / F_L1_HZ),
            carrier_phase_cycles: 0.0,
            carrier_freq_hz: start.doppler_hz,
            aid: None,
            ff_applied_hz: None,
            ff_rate_applied_hz_s: 0.0,
            coasted_last: false,
            ff_source: None,
            aid_manoeuvre_until_s: f64::NEG_INFINITY,
            loops: TrackLoops::Normal,
            weak: start.cn0_dbhz < cfg.weak_enter_dbhz || weak_pull_in.is_some(),
            dynamics: false,
            track_since_ms: 0,
            acc_feedforward_hz: None,
            ms_count: 0,
            bit_sync_origin_ms: 0,
            pull_in_ms: 0,
            cn0_dbhz: start.cn0_dbhz,
            tracked_cn0_dbhz: start.cn0_dbhz,
            confirmed: false,
            release_requested: false,
            narrowing: None,
            low_cn0_count: 0,
            unlocked_ms: 0,
            recoveries: 0,
            acc: [Complex64::new(0.0, 0.0); 3],
            acc_ms: 0,
            acc_start: (start.code_start_sample, 0.0, 0.0, 0.0),
            taps: [d / 2.0, 0.0, -d / 2.0],
            rate_fit: [0.0; 5],
            phase_fit: QuadraticPhaseFit::new(),
            ff_phase_cycles: 0.0,
            aid_switched: None,
            aid_blend: None,
            pending_bit: None,
            weak_stage: weak_pull_in.map(|_| WeakStage::Frequency),
            presync_cn0: SmoothedNwpr::new(
                1e-3,
                PRESYNC_BLOCK_PROMPTS,
                2 * cn0_window_blocks,
                cn0_window_blocks,
            ),
        })
    }

    /// A channel started from a prediction of its signal instead of a search (vector
    /// tracking's filter knows the satellite's code phase and Doppler, not its C/N0): it pulls
    /// in with the weak-signal pull-in ([`WeakPullInConfig`], if configured), whose
    /// pre-synchronisation C/N0 test releases it within about a second if no signal is there;
    /// its C/N0 is unknown (NaN) until its own first estimate.
    pub fn predicted(
        start: &ChannelStart,
        fs_hz: f64,
        cfg: &ChannelConfig,
    ) -> Result<Self, ConfigError> {
        let weak = ChannelStart {
            cn0_dbhz: f64::NEG_INFINITY,
            ..*start
        };
        let mut ch = Self::new(&weak, fs_hz, cfg)?;
        ch.cn0_dbhz = f64::NAN;
        ch.tracked_cn0_dbhz = f64::NAN;
        Ok(ch)
    }

    /// Whether the carrier is being pulled in: after acquisition ([`ChannelState::PullIn`])
    /// or after a loss of lock ([`ChannelState::Recover`]).
    fn pulling_in(&self) -> bool {
        matches!(self.state, ChannelState::PullIn | ChannelState::Recover)
    }

    /// The satellite.
    pub fn prn(&self) -> Prn {
        self.prn
    }

    /// Sampling rate the channel runs at, Hz.
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    /// The state.
    pub fn state(&self) -> ChannelState {
        self.state
    }

    /// Latest C/N0 estimate, dB-Hz (NaN before the first).
    pub fn cn0_dbhz(&self) -> f64 {
        self.cn0_dbhz
    }

    /// The C/N0 while the signal was there (the highest estimate, forgotten at 0.25 dB/s; the
    /// acquisition's before the first), dB-Hz: how hard a search must be to find the satellite
    /// again once the channel is lost.
    pub fn tracked_cn0_dbhz(&self) -> f64 {
        self.tracked_cn0_dbhz
    }

    /// Whether the channel reached the tracking state (phase lock and bit sync after its
    /// pull-in): the acquisition that started it found a satellite it could follow.
    pub fn confirmed(&self) -> bool {
        self.confirmed
    }

    /// The carrier NCO frequency (the Doppler the channel holds), Hz.
    pub fn doppler_hz(&self) -> f64 {
        self.carrier_freq_hz
    }

    /// Tells the channel whether the receiver is under dynamics (its strong channels' carrier
    /// loops see a line-of-sight Doppler rate no static receiver has): a weak channel then
    /// takes the weak-signal loops widened for dynamics ([`dynamic_weak_config`]) at its next
    /// data-bit edge, and its narrow ones again when they are over.
    pub fn set_dynamics(&mut self, on: bool) {
        self.dynamics = on;
    }

    /// The line-of-sight Doppler rate the channel's carrier loop follows, Hz/s: the rate
    /// memory of an unaided 3rd-order loop in tracking with phase lock for at least
    /// [`RATE_SETTLED_MS`], on the 1 ms loops (a strong signal, whose loop is wide enough to
    /// follow a manoeuvre's onset); `None` otherwise.
    pub fn los_rate_hz_s(&self) -> Option<f64> {
        let usable = self.state == ChannelState::Track
            && self.ms_count >= self.track_since_ms + RATE_SETTLED_MS
            && self.loops == TrackLoops::Normal
            && self.ff_applied_hz.is_none()
            && self.pll_lock.locked()
            && (self.carrier.t_coh_s() * 1e3).round() as usize == 1;
        usable
            .then(|| self.carrier.filter().rate_memory())
            .flatten()
            .filter(|r| r.is_finite())
    }

    /// Sets the external Doppler estimate valid at receive time `t_s` (the aiding port), fed
    /// forward from the next integration interval on: the NCO gets its mean over that interval,
    /// extrapolated with its rate. `None` removes the aid. Switching the aid on or off keeps the
    /// NCO frequency continuous (the loop's base frequency takes up the difference).
    ///
    /// A vector aid's steps (each filter update moves its prediction: 0.1-0.4 Hz on a static
    /// 25 dB-Hz satellite) are not passed on as steps: the feed-forward moves from the old
    /// prediction to the new one with the time constant [`VECTOR_AID_BLEND_S`]
    /// (`Channel::aid_blend_hz`).
    pub fn set_aid(&mut self, aid: Option<DopplerAid>, t_s: f64) {
        if aid.is_some_and(|a| a.doppler_rate_hz_s.abs() > AID_MANOEUVRE_HZ_S) {
            self.aid_manoeuvre_until_s = t_s + AID_MANOEUVRE_HOLD_S;
        }
        let t_next = self.next_sample as f64 / self.fs_hz;
        let vector = |a: &DopplerAid| a.source == crate::aiding::AidSource::Vector;
        self.aid_blend = match (self.aid, aid) {
            (Some((old, t_old)), Some(new))
                if vector(&old) && vector(&new) && self.ff_applied_hz.is_some() =>
            {
                // What the NCO would get at the next sample, from the old aid and from the
                // new one: the difference fades from there.
                let old_hz = old.doppler_hz
                    + old.doppler_rate_hz_s * (t_next - t_old)
                    + self.aid_blend_hz(t_next);
                let new_hz = new.doppler_hz + new.doppler_rate_hz_s * (t_next - t_s);
                Some((t_next, old_hz - new_hz)).filter(|(_, d)| d.is_finite())
            }
            _ => None,
        };
        self.aid = aid.map(|a| (a, t_s));
    }

    /// The part of a vector aid's last step not yet passed on at receive time `t_s`, Hz:
    /// `d (1 - (t - t0) / tau)` from the step `d` at `t0` over [`VECTOR_AID_BLEND_S`] (renewed
    /// with every code period's aid, so a step fades about exponentially with that time
    /// constant).
    fn aid_blend_hz(&self, t_s: f64) -> f64 {
        self.aid_blend.map_or(0.0, |(t0, d)| {
            d * (1.0 - (t_s - t0) / VECTOR_AID_BLEND_S).clamp(0.0, 1.0)
        })
    }

    /// The aid predicts a manoeuvre: its Doppler rate was above [`AID_MANOEUVRE_HZ_S`] within
    /// [`AID_MANOEUVRE_HOLD_S`].
    fn aid_manoeuvre(&self) -> bool {
        (self.next_sample as f64 / self.fs_hz) < self.aid_manoeuvre_until_s
    }

    /// Feed-forward (Hz) for an interval of `t_coh_s` starting at the channel's next sample.
    fn feedforward_hz(&self, t_coh_s: f64) -> Option<f64> {
        self.aid.map(|(a, t_aid)| {
            let t_next = self.next_sample as f64 / self.fs_hz;
            a.doppler_hz
                + a.doppler_rate_hz_s * (t_next - t_aid + 0.5 * t_coh_s)
                + self.aid_blend_hz(t_next + 0.5 * t_coh_s)
        })
    }

    /// Absolute index of the first sample the next code period needs, and how many samples it
    /// spans.
    pub fn next_span(&self) -> (u64, usize) {
        let n = ((CA_CODE_LENGTH as f64 - self.code_phase_chips) * self.fs_hz
            / self.code_rate_chips_s)
            .ceil();
        (self.next_sample, n.max(1.0) as usize)
    }

    /// Skips whole code periods so that the next one starts at or after `sample` (when the
    /// samples the channel wanted are no longer available).
    pub fn skip_to(&mut self, sample: u64) {
        while self.next_sample < sample {
            let (_, n) = self.next_span();
            self.advance(n);
            self.ms_count += 1;
        }
        self.acc = [Complex64::new(0.0, 0.0); 3];
        self.acc_ms = 0;
        self.carrier.reset_history();
        self.phase_fit.reset();
        self.bit_sync.reset();
        self.bit_sync_origin_ms = self.ms_count;
        self.weak_restart_frequency_stage();
    }

    /// Takes the data-bit edges from outside (vector tracking's predicted SV time, whose
    /// 20 ms boundaries are the edges): a bit starts at every code period whose `ms_count` is
    /// `edge_phase` modulo 20. Only while the bit synchroniser still searches (its histogram
    /// needs 2-10 s at 24-28 dB-Hz); a weak pull-in then moves to its bit-aligned phase stage
    /// at the next edge, as after its own synchronisation.
    pub fn assume_bit_edge(&mut self, edge_phase: usize) {
        if self.state == ChannelState::Lost || self.bit_sync.state() != BitSyncState::Searching {
            return;
        }
        let origin = (self.bit_sync_origin_ms % MS_PER_BIT as u64) as usize;
        self.bit_sync
            .assume_edge((edge_phase % MS_PER_BIT + MS_PER_BIT - origin) % MS_PER_BIT);
    }

    /// Forgets the data-bit edges (after samples were lost, the bits no longer fall where they
    /// did): the bit synchroniser starts again on the coming prompts; the loops keep running.
    /// A channel integrating longer than 1 ms (aligned to the old edges, so now straddling
    /// the new ones) goes back to its 1 ms loops at the frequency and Doppler rate it held; a
    /// weak pull-in goes back to its frequency stage, whose sums need no edges. The C/N0 and
    /// the phase-lock indicator hold until the first new edge.
    pub fn restart_bit_sync(&mut self) {
        if self.weak_stage.is_none() && (self.carrier.t_coh_s() * 1e3).round() as usize != 1 {
            // Integrations aligned to the old bit edges straddle the new ones: back to the
            // 1 ms loops (at the frequency held), where the edges can be found again.
            // With the Doppler rate held (a 10 g turn is 500 Hz/s: a loop restarted at rate 0
            // falls behind by tens of hertz in its first tenth of a second and slips).
            let ff = self.ff_applied_hz.unwrap_or(0.0);
            let f = self.carrier.frequency_memory_hz() + ff;
            let rate = self.carrier.filter().rate_memory().unwrap_or(0.0);
            if self.restart_carrier(f, rate).is_none() {
                return;
            }
            self.acc = [Complex64::new(0.0, 0.0); 3];
            self.acc_ms = 0;
            self.phase_fit.reset();
        }
        self.weak_restart_frequency_stage();
        self.bit_sync.reset();
        self.bit_sync_origin_ms = self.ms_count;
        self.pending_bit = None;
        // The C/N0 and phase-lock blocks are aligned to the bits: until the new edges are
        // found the C/N0 holds its last estimate and the Costas gain its C/N0 (the lock
        // detector still reports; the fade detector, whose blocks need no edges, flags a
        // signal that is gone; the bit synchroniser releases a channel that finds no edges).
        self.cn0_started = false;
        self.costas_hold_ms = Some(u32::MAX);
        // The estimates since the samples were lost (before the gap was found) read the moved
        // bits already: the level the signal had stands, and decides the loops.
        if self.tracked_cn0_dbhz.is_finite() && self.tracked_cn0_dbhz > self.cn0_dbhz {
            self.cn0_dbhz = self.tracked_cn0_dbhz;
            if self.cn0_dbhz > self.cfg.weak_leave_dbhz {
                self.weak = false;
            }
        }
    }

    fn advance(&mut self, n: usize) {
        let t = n as f64 / self.fs_hz;
        self.code_phase_chips =
            (self.code_phase_chips + self.code_rate_chips_s * t - CA_CODE_LENGTH as f64).max(0.0);
        self.carrier_phase_cycles += self.carrier_freq_hz * t;
        self.next_sample += n as u64;
    }

    /// Processes one code period; `samples` must be exactly the span [`Channel::next_span`]
    /// returned. Returns the epoch report when an integration interval ends.
    ///
    /// The steps, in this order (each reads the state the previous one left):
    /// `Channel::correlate_period` (E, P, L over the period, NCOs advanced, accumulated),
    /// `Channel::update_bit_sync` (bits and bit edges from the 1 ms prompt),
    /// `Channel::update_detectors` (C/N0, weak-signal and lock detectors, loss of lock),
    /// `Channel::interval_complete` (integration time reached on a bit-aligned boundary), then
    /// once per integration interval `Channel::update_loops` (discriminators, loop filters,
    /// NCO frequencies), `Channel::build_epoch` (the report) and the state transitions
    /// `Channel::maybe_hand_over` / `Channel::maybe_switch_loops` at a bit edge.
    pub fn process_code_period(&mut self, samples: &[Complex32]) -> Option<ChannelEpoch> {
        self.process_period(SampleSlice::Cf32(samples))
    }

    /// [`Channel::process_code_period`] on samples in any format the correlators read in place
    /// (complex f32, or ci8/ci16 as stored: no conversion, a quarter of the memory traffic).
    pub fn process_period(&mut self, samples: SampleSlice<'_>) -> Option<ChannelEpoch> {
        if self.state == ChannelState::Lost {
            return None;
        }
        let (p, t_start_s, ms_index) = self.correlate_period(samples);
        let timing = self.update_bit_sync(p, t_start_s, ms_index);
        self.update_detectors(p, timing.next_is_edge);
        if self.pulling_in() && self.weak_pull_in_step(timing.next_is_edge) {
            return None;
        }
        if !self.interval_complete(ms_index, timing) {
            return None;
        }
        if self.release_requested {
            self.state = ChannelState::Lost;
        }
        let bit = self.pending_bit.take();
        let (co, cl) = self.update_loops();
        self.feed_phase_fit(co.phase_error_cycles);
        let epoch = self.build_epoch(ms_index, timing, &co, &cl, bit);
        self.watch_carrier_lock(self.acc_ms as u64);
        self.acc = [Complex64::new(0.0, 0.0); 3];
        self.acc_ms = 0;
        self.maybe_hand_over(timing.next_is_edge);
        self.maybe_switch_loops(timing.next_is_edge);
        self.maybe_narrow(timing.next_is_edge);
        Some(epoch)
    }

    /// Correlates one code period and advances the replica over it: records the start of a new
    /// integration interval, computes E, P, L (replica code phases `c + d/2`, `c`, `c - d/2`,
    /// NCOs held over the period), advances code and carrier phase by `n / fs`
    /// ([`Channel::advance`]), counts the period (and the pull-in time, switching the FLL assist
    /// off after [`ChannelConfig::fll_assist_s`]) and adds E, P, L to the interval's sums.
    ///
    /// Returns the 1 ms prompt, the receive time of the period's first sample (`index / fs`, s)
    /// and the period's `ms_count`.
    #[inline]
    fn correlate_period(&mut self, samples: SampleSlice<'_>) -> (Complex64, f64, u64) {
        let state_now = ReplicaState {
            code_phase_chips: self.code_phase_chips,
            code_rate_chips_s: self.code_rate_chips_s,
            carrier_phase_cycles: self.carrier_phase_cycles.rem_euclid(1.0),
            carrier_freq_hz: self.carrier_freq_hz,
            carrier_rate_hz_s: 0.0,
        };
        if self.acc_ms == 0 {
            self.acc_start = (
                self.next_sample,
                self.code_phase_chips,
                self.carrier_phase_cycles,
                self.carrier_freq_hz,
            );
            self.acc_feedforward_hz = self.ff_applied_hz;
        }
        let mut out = [Complex32::new(0.0, 0.0); 3];
        self.correlator.correlate_packed(
            samples,
            self.fs_hz,
            &self.packed_code,
            &state_now,
            &self.taps,
            &mut out,
        );
        let [e, p, l] = out.map(|c| Complex64::new(f64::from(c.re), f64::from(c.im)));
        let t_start_s = self.next_sample as f64 / self.fs_hz;
        self.advance(samples.len());
        let ms_index = self.ms_count;
        self.ms_count += 1;
        if self.pulling_in() {
            self.pull_in_ms += 1;
            // (A weak pull-in switches its own assist: [`Channel::weak_pull_in_step`].)
            if self.pull_in_ms == (self.cfg.fll_assist_s * 1e3).round() as u64
                && self.weak_stage.is_none()
            {
                self.carrier.set_fll_assist(false);
            }
        }
        for (a, v) in self.acc.iter_mut().zip([e, p, l]) {
            *a += v;
        }
        self.acc_ms += 1;
        (p, t_start_s, ms_index)
    }

    /// Bit synchronisation from the 1 ms prompt of code period `ms_index` (first sample at
    /// receive time `t_start_s`): a completed bit waits in `pending_bit`, tagged with the
    /// `ms_count` of its first period (`ms_index + 1 - 20`), for the end of the integration
    /// interval. Once synchronised, bit edges fall on the periods `k` with
    /// `k mod 20 == (origin + edge) mod 20` (IS-GPS-200 20.3.2: 20 C/A periods per 50 bit/s data
    /// bit).
    #[inline]
    fn update_bit_sync(&mut self, p: Complex64, t_start_s: f64, ms_index: u64) -> BitTiming {
        if let Some(b) = self.bit_sync.push(p, t_start_s) {
            // Reported with the integration interval that ends next (bits end on interval ends
            // once the integrations are bit-aligned).
            self.pending_bit = Some((b, (ms_index + 1).saturating_sub(MS_PER_BIT as u64)));
        }
        // Bit edges fall on code periods k with k mod 20 == edge_phase (k counted by ms_count).
        let edge_phase = match self.bit_sync.state() {
            BitSyncState::Synced { edge } => {
                Some(((self.bit_sync_origin_ms + edge as u64) % MS_PER_BIT as u64) as usize)
            }
            _ => None,
        };
        let next_is_edge = edge_phase.is_some_and(|edge| {
            (ms_index + 1) % MS_PER_BIT as u64 == edge as u64 % MS_PER_BIT as u64
        });
        BitTiming {
            edge_phase,
            next_is_edge,
        }
    }

    /// The detectors fed with every 1 ms prompt: the C/N0 ([`Channel::update_cn0`]), the phase
    /// lock indicator (its blocks aligned to the bits once they are synchronised), the fade
    /// detector, and the bit synchroniser's failure
    /// (no bit edges within its patience: no usable signal, the channel is lost).
    #[inline]
    fn update_detectors(&mut self, p: Complex64, next_is_edge: bool) {
        self.update_cn0(p, next_is_edge);
        self.pll_lock.update(p);
        match self.costas_hold_ms {
            // The carrier loop's Costas gain follows the detector's C/N0 (bit-aligned,
            // unbiased).
            None => self.carrier.set_cn0_hz(self.pll_lock.cn0_hz(1e-3)),
            Some(u32::MAX) => {}
            Some(0) => self.costas_hold_ms = None,
            Some(n) => self.costas_hold_ms = Some(n - 1),
        }
        if next_is_edge {
            // Lock-detector blocks hold whole data bits (no transition cancels a block's sum).
            self.pll_lock.align_block();
            if self.costas_hold_ms == Some(u32::MAX) {
                self.costas_hold_ms = Some(COSTAS_HOLD_AFTER_EDGE_MS);
            }
        }
        // A blocked signal that an aid predicts: its noise is no new level (unless the C/N0
        // still reads the signal: then the gain changed).
        let signal_read = self.cn0_dbhz >= self.cn0_lost_dbhz();
        self.fade.hold_reference(self.coast_aid() && !signal_read);
        self.fade.push(p);
        self.watch_fade();
        if matches!(self.bit_sync.state(), BitSyncState::Failed) {
            // No bit edges within the synchroniser's patience: no usable signal. Release the
            // channel so the satellite goes back to acquisition.
            self.state = ChannelState::Lost;
        }
    }

    /// C/N0 from NWPR blocks of 20 prompts aligned to the data bits
    /// (`C/N0 = 10 log10((mu - 1) / (M T (M - mu)))`, `mu` the mean of NBP/WBP, see
    /// [`crate::cn0`]): measured from the first bit edge after bit synchronisation (before it,
    /// the acquisition's estimate stands). A new estimate goes to [`Channel::on_cn0_estimate`].
    #[inline]
    fn update_cn0(&mut self, p: Complex64, next_is_edge: bool) {
        let estimate = if self.cn0_started {
            self.cn0.push(p)
        } else {
            if self.weak_stage.is_some() {
                if let Some(c) = self.presync_cn0.push(p) {
                    self.on_presync_estimate(c);
                }
            }
            None
        };
        if next_is_edge {
            if !self.cn0_started {
                self.cn0_started = true;
                self.cn0.reset();
                self.low_cn0_count = 0;
            }
            self.cn0.align_block();
        }
        if let Some(c) = estimate {
            self.on_cn0_estimate(c);
        }
    }

    /// A new C/N0 estimate `c` (dB-Hz): stored, the weak-signal flag updated with hysteresis
    /// (set below [`ChannelConfig::weak_enter_dbhz`], cleared above
    /// [`ChannelConfig::weak_leave_dbhz`]), and once per estimation window the code lock
    /// decided: [`ChannelConfig::lost_estimates`] consecutive estimates below
    /// [`ChannelConfig::cn0_lost_dbhz`] with the code lock detector out release the channel
    /// (not counting, with a feed-forward applied, the estimates of an outage: while the fade
    /// detector says the power is gone, and up to [`FADE_RECOVERY_HOLD_MS`] after it).
    fn on_cn0_estimate(&mut self, c: f64) {
        self.cn0_dbhz = c;
        // The level the signal had: the highest estimate, forgotten at 0.05 dB per estimate
        // (0.25 dB/s with 0.2 s estimates), so the fall into a blockage does not lower it.
        self.tracked_cn0_dbhz = if self.tracked_cn0_dbhz.is_finite() {
            c.max(self.tracked_cn0_dbhz - 0.05)
        } else {
            c
        };
        if c < self.cfg.weak_enter_dbhz {
            // (Not while the estimates still average the outage a fade has just ended.)
            self.weak |= self.fade_hold_ms == 0;
        } else {
            self.fade_hold_ms = 0;
            if c > self.cfg.weak_leave_dbhz {
                self.weak = false;
            }
        }
        // Lock decisions once per estimation window.
        if self.cn0.blocks().is_multiple_of(self.cn0_window_blocks) {
            let ok = self.code_lock.update(c);
            // An outage with a feed-forward: the NCO follows the motion through it, and the
            // estimates that average it are not the signal's (a search could do no better).
            let coasting = self.ff_applied_hz.is_some()
                && (self.fade.faded() || self.aided_fade_hold_ms > 0)
                || self.coasting_on_aid();
            self.low_cn0_count = if c < self.cn0_lost_dbhz() && !coasting {
                self.low_cn0_count + 1
            } else {
                0
            };
            if !ok && self.low_cn0_count >= self.cfg.lost_estimates {
                self.state = ChannelState::Lost;
            }
        }
    }

    /// The fade detector's verdict changing: at a collapse of the prompt power the weak-signal
    /// flag is kept aside (the estimates of the outage then send the loops to the weak ones,
    /// which coast through it); when the power comes back, the flag of before stands for
    /// [`FADE_RECOVERY_HOLD_MS`] or until an estimate reaches
    /// [`ChannelConfig::weak_enter_dbhz`]: the C/N0 estimator still averages the outage (after
    /// 1 s of zeros, a 35 dB-Hz satellite's estimates climbed from 21 to 32 dB-Hz over 0.4 s),
    /// and in the weak loops (20 ms, 6 Hz) a satellite that came back with a few hertz of
    /// drift from the outage took 0.8 s to lock again, on a 4.3 g climb with an INS. (Not
    /// unaided under dynamics: see the code.)
    #[inline]
    fn watch_fade(&mut self) {
        self.fade_hold_ms = self.fade_hold_ms.saturating_sub(1);
        self.aided_fade_hold_ms = self.aided_fade_hold_ms.saturating_sub(1);
        match (self.weak_before_fade, self.fade.faded()) {
            (None, true) => self.weak_before_fade = Some(self.weak),
            (Some(before), false) => {
                self.weak_before_fade = None;
                if self.ff_applied_hz.is_some() {
                    self.aided_fade_hold_ms = FADE_RECOVERY_HOLD_MS;
                }
                if self.state == ChannelState::Track && self.coast_aid() {
                    // Coasted on the aid: the estimator's window holds the outage, so it
                    // starts again on the returned signal, the level before standing until
                    // its first estimate (five blocks, 0.1 s).
                    self.cn0.reset();
                    if self.tracked_cn0_dbhz.is_finite() {
                        self.cn0_dbhz = self.tracked_cn0_dbhz;
                    }
                }
                // Only where the NCO followed the signal through the outage: with a
                // feed-forward, or without dynamics. Unaided in a manoeuvre it coasted tens
                // of hertz off (a 10 g turn's jerk over 1 s: 100 Hz), and the normal loops
                // took such a channel on as if it held the signal (fixes 50 m off, within
                // their 3-sigma, where it was lost and found again before).
                let coasted = self.ff_applied_hz.is_some() || !self.dynamics;
                if !before && self.weak && coasted {
                    self.weak = false;
                    self.fade_hold_ms = FADE_RECOVERY_HOLD_MS;
                }
            }
            _ => {}
        }
    }

    /// Whether the integration interval ends with code period `ms_index`: `T_coh` (ms) periods
    /// accumulated and the next period starting on a boundary of the `T_coh` grid anchored on
    /// the bit edges (`(ms_index + 1 - edge) mod 20` a multiple of `T_coh`), or on an edge, or
    /// `T_coh = 1 ms`. A full sum that is not aligned (only after a loop switch) is dropped.
    #[inline]
    fn interval_complete(&mut self, ms_index: u64, timing: BitTiming) -> bool {
        let t_coh_ms = (self.carrier.t_coh_s() * 1e3).round() as usize;
        let aligned = t_coh_ms == 1
            || self.weak_frequency_stage()
            || timing.next_is_edge
            || timing.edge_phase.is_some_and(|edge| {
                let k = (ms_index + 1 + MS_PER_BIT as u64 - edge as u64 % MS_PER_BIT as u64)
                    % MS_PER_BIT as u64;
                k.is_multiple_of(t_coh_ms as u64)
            });
        if self.state == ChannelState::Lost && self.acc_ms > 0 {
            return true; // report the loss (a weak pull-in can end mid-interval)
        }
        if self.acc_ms < t_coh_ms || !aligned {
            if self.acc_ms >= t_coh_ms {
                // Not aligned to a bit boundary yet (only after a switch): drop the partial sum.
                self.acc = [Complex64::new(0.0, 0.0); 3];
                self.acc_ms = 0;
            }
            return false;
        }
        true
    }

    /// Closes the loops at the end of an integration interval: the feed-forward for the next
    /// interval (the aid's Doppler at its middle, `f + f' (t_next - t_aid + T/2)`; the loop's base
    /// frequency takes up the step when the aid comes or goes, keeping the NCO continuous), the
    /// carrier loop on the summed prompt (seed 004 Fig. 4: NCO = feed-forward + filter), the
    /// carrier-aided DLL on E, P, L (code rate `1.023 MHz (1 + f / f_L1)` + DLL), and the
    /// Doppler-rate fit of the pull-in ([`Channel::accumulate_rate_fit`]).
    #[inline]
    fn update_loops(&mut self) -> (CarrierOutput, CodeOutput) {
        let [ea, pa, la] = self.acc;
        let ff_opt = self.feedforward_hz(self.carrier.t_coh_s());
        // The aid coming or going: the loop stops or starts holding what the feed-forward
        // supplies, its Doppler and its Doppler rate, so the NCO does not move (bumpless).
        // Keeping the rate a 3rd-order loop learned in a turn would count it twice.
        let ff_rate = self.aid.map_or(0.0, |(a, _)| a.doppler_rate_hz_s);
        let ff_source = self.aid.map(|(a, _)| a.source);
        match (self.ff_applied_hz, ff_opt) {
            (None, Some(f)) => {
                // The feed-forward's phase is counted from the next interval's first sample: the
                // phase fit's earlier samples move onto it with the same origin (an origin off
                // by dt would put them f dt cycles off the later ones).
                let t_c = self.next_sample as f64 / self.fs_hz;
                self.aid_switched = Some((t_c, f, ff_rate));
                self.carrier.shift_base_hz(-f);
                self.carrier.shift_doppler_rate(-ff_rate);
                self.ff_rate_applied_hz_s = ff_rate;
            }
            (Some(f), None) => {
                let t_c = self.next_sample as f64 / self.fs_hz;
                self.aid_switched = Some((t_c, -f, -self.ff_rate_applied_hz_s));
                self.carrier.shift_base_hz(f);
                self.carrier.shift_doppler_rate(self.ff_rate_applied_hz_s);
                self.ff_rate_applied_hz_s = 0.0;
            }
            (Some(old), Some(f)) if self.ff_source != ff_source => {
                // Another source (vector tracking taking over from the INS feed-forward, or
                // handing back): as the old aid going and the new one coming.
                let t_c = self.next_sample as f64 / self.fs_hz;
                self.aid_switched = Some((t_c, f - old, ff_rate - self.ff_rate_applied_hz_s));
                self.carrier.shift_base_hz(old - f);
                self.carrier
                    .shift_doppler_rate(self.ff_rate_applied_hz_s - ff_rate);
                self.ff_rate_applied_hz_s = ff_rate;
            }
            (Some(_), Some(_)) => self.ff_rate_applied_hz_s = ff_rate,
            (None, None) => {}
        }
        self.ff_applied_hz = ff_opt;
        self.ff_source = ff_source.filter(|_| ff_opt.is_some());
        let ff = ff_opt.unwrap_or(0.0);
        let coasting = self.coasting_on_aid();
        if coasting && !self.coasted_last {
            // The feed-forward supplies the Doppler rate; what the loop learned of it in the
            // noise before the loss was seen would be carried on as a ramp (measured: 16 Hz/s,
            // 40 Hz after 2.5 s).
            self.carrier.start_coast();
            self.code_loop.start_coast();
        }
        if !coasting && self.coasted_last {
            // The C/N0 estimates still average the outage for a while (a 31 dB-Hz satellite
            // back from 3 s of blockage read 24.7 dB-Hz 1 s later and was released).
            self.aided_fade_hold_ms = FADE_RECOVERY_HOLD_MS;
        }
        self.coasted_last = coasting;
        let (co, cl) = if coasting {
            let co = self.carrier.coast(ff);
            (
                co,
                self.code_loop.coast(code_doppler_chips_s(co.nco_freq_hz)),
            )
        } else {
            let co = self.carrier.update(pa, ff);
            let aid = code_doppler_chips_s(co.nco_freq_hz);
            (co, self.code_loop.update(ea, pa, la, aid))
        };
        self.carrier_freq_hz = co.nco_freq_hz;
        self.code_rate_chips_s = cl.code_rate_chips_s;
        self.accumulate_rate_fit(co.nco_freq_hz, ff);
        (co, cl)
    }

    /// During pull-in, once the FLL assist is off: adds the point `(t, f)` (pull-in time, s;
    /// NCO frequency less the feed-forward, Hz) to the least-squares sums
    /// `(n, sum t, sum f, sum t^2, sum t f)`, whose slope
    /// `(n sum tf - sum t sum f) / (n sum t^2 - (sum t)^2)` presets the Doppler rate of a
    /// 3rd-order tracking loop at the hand-over ([`Channel::maybe_hand_over`]).
    #[inline]
    fn accumulate_rate_fit(&mut self, nco_freq_hz: f64, ff: f64) {
        if self.pulling_in()
            && self.weak_stage.is_none()
            && self.pull_in_ms > (self.cfg.fll_assist_s * 1e3) as u64
        {
            let t = self.pull_in_ms as f64 * 1e-3;
            let f = nco_freq_hz - ff;
            for (acc, v) in self.rate_fit.iter_mut().zip([1.0, t, f, t * t, t * f]) {
                *acc += v;
            }
        }
    }

    /// The report of the integration interval that ends with code period `ms_index`: the
    /// replica state at its first sample (kept by [`Channel::correlate_period`]), the summed
    /// E, P, L, the discriminator outputs of [`Channel::update_loops`] (`co`, `cl`), the lock
    /// indicators, and the bit completed in it (`bit`, with the `ms_count` of its first period).
    /// The interval's first period is `ms_index + 1 - acc_ms`; it is a bit edge when that is
    /// `edge mod 20`.
    #[inline]
    fn build_epoch(
        &self,
        ms_index: u64,
        timing: BitTiming,
        co: &CarrierOutput,
        cl: &CodeOutput,
        bit: Option<(Bit, u64)>,
    ) -> ChannelEpoch {
        let [ea, pa, la] = self.acc;
        let (s0, cp0, ph0, f0) = self.acc_start;
        ChannelEpoch {
            prn: self.prn.get(),
            state: self.state,
            sample_index: s0,
            t_rx_s: s0 as f64 / self.fs_hz,
            code_phase_chips: cp0,
            code_rate_chips_s: self.code_rate_chips_s,
            carrier_phase_cycles: ph0,
            doppler_hz: f0,
            cn0_dbhz: self.cn0_dbhz,
            cn0_lost_dbhz: self.cn0_lost_dbhz(),
            pll_lock: self.pll_lock.locked() && !self.fade.faded(),
            pll_lock_metric: self.pll_lock.cos_2phi(),
            code_lock: self.code_lock.locked(),
            prompt: pa,
            early: ea,
            late: la,
            phase_error_cycles: co.phase_error_cycles,
            freq_error_hz: co.freq_error_hz,
            code_error_chips: cl.code_error_chips,
            t_coh_s: self.carrier.t_coh_s(),
            feedforward_hz: self.acc_feedforward_hz,
            coasting: self.coasted_last,
            ms_count: ms_index + 1 - self.acc_ms as u64,
            bit_edge: timing.edge_phase.is_some_and(|edge| {
                (ms_index + 1 - self.acc_ms as u64) % MS_PER_BIT as u64
                    == edge as u64 % MS_PER_BIT as u64
            }),
            bit: bit.map(|(b, _)| b),
            bit_start_ms: bit.map(|(_, m)| m),
        }
    }

    /// Pull-in -> track once the phase is locked, the bits are synchronised and the minimum
    /// pull-in time has passed; the switch happens on a bit edge so that the longer
    /// integrations are aligned with the data bits.
    fn maybe_hand_over(&mut self, at_edge: bool) {
        if !self.pulling_in() || !at_edge {
            return;
        }
        let min_ms = (self.cfg.min_pull_in_s * 1e3) as u64;
        if self.pull_in_ms < min_ms || !self.pll_lock.locked() || !self.weak_ready_for_hand_over() {
            return;
        }
        let which = self.wanted_loops();
        let loops = self.loop_config(which);
        if self.state == ChannelState::Recover && !self.recovery_ready(&loops) {
            return;
        }
        self.weak_stage = None;
        let (Some((carrier, from_fit)), Ok(code_loop)) =
            (self.carrier_toward(&loops), CodeLoop::new(&loops))
        else {
            return; // validated at construction; keep pulling in otherwise
        };
        self.carrier = carrier;
        let [n, st, sf, stt, stf] = self.rate_fit;
        let den = n * stt - st * st;
        if !from_fit && !self.phase_fit_started() && n >= 100.0 && den > 0.0 {
            self.carrier.preset_doppler_rate((n * stf - st * sf) / den);
        }
        self.code_loop = code_loop;
        let d = loops.el_spacing_chips;
        self.taps = [d / 2.0, 0.0, -d / 2.0];
        self.state = ChannelState::Track;
        self.track_since_ms = self.ms_count;
        self.confirmed = true;
        self.loops = which;
    }

    /// The loops the tracking state should run now: the aided ones while a feed-forward is
    /// applied (if configured), else the weak-signal ones while the C/N0 is low (if
    /// configured), else the normal ones; first of all the vector weak-signal loops while weak
    /// and checked by vector tracking (if configured), unless the aid predicts a manoeuvre
    /// ([`AID_MANOEUVRE_HZ_S`]).
    fn wanted_loops(&self) -> TrackLoops {
        if self.weak
            && self.checked_aid()
            && !self.aid_manoeuvre()
            && self.cfg.vector_weak_track.is_some()
        {
            return TrackLoops::VectorWeak;
        }
        if self.ff_applied_hz.is_some() && self.cfg.aided_track.is_some() {
            if self.weak && self.aided_weak_config().is_some() {
                TrackLoops::AidedWeak
            } else {
                TrackLoops::Aided
            }
        } else if self.weak
            && self.dynamics
            && self.signal_present()
            && self.cfg.weak_track.is_some()
        {
            // Not while the signal is gone: the narrow loops coast through an outage on their
            // memories, a 15 Hz loop wanders off on the noise (measured: two 37 dB-Hz
            // satellites lost after 1 s of zeros on a 4.3 g climb).
            TrackLoops::WeakDynamic
        } else if self.weak && self.cfg.weak_track.is_some() {
            TrackLoops::Weak
        } else {
            TrackLoops::Normal
        }
    }

    /// The C/N0 below which the channel counts as lost now: [`ChannelConfig::cn0_lost_dbhz`],
    /// or [`ChannelConfig::vector_cn0_lost_dbhz`] while an aid that checks its measurements is
    /// applied ([`DopplerAid::checked`]), dB-Hz.
    pub fn cn0_lost_dbhz(&self) -> f64 {
        if self.checked_aid() {
            self.cfg.vector_cn0_lost_dbhz.min(self.cfg.cn0_lost_dbhz)
        } else {
            self.cfg.cn0_lost_dbhz
        }
    }

    /// An aid that checks the channel's measurements is applied ([`DopplerAid::checked`]):
    /// vector tracking's filter admitted them, or its prediction vouches for the channel's
    /// code, within the last second.
    pub fn checked_aid(&self) -> bool {
        self.ff_applied_hz.is_some() && self.aid.is_some_and(|(a, _)| a.checked)
    }

    /// An aid that predicts the signal through an outage is applied ([`DopplerAid::coast`]).
    fn coast_aid(&self) -> bool {
        self.ff_applied_hz.is_some() && self.aid.is_some_and(|(a, _)| a.coast)
    }

    /// The channel coasts on its aid: in tracking, its signal is gone (the prompt power has
    /// collapsed, or, where the fade detector cannot see the fall of a weak signal, its C/N0
    /// estimate is [`COAST_BELOW_LOST_DB`] below its loss threshold, [`Channel::cn0_lost_dbhz`]) and the aid
    /// predicts it through the outage ([`DopplerAid::coast`]: vector tracking). Its
    /// loops hold their memories (their discriminators would read noise) and its NCOs follow
    /// the aid; its lock is not counted lost, its loops are not switched or narrowed, and its
    /// C/N0 does not release it (the fade detector holds its reference, so the fade lasts
    /// until the power comes back). The aid's source decides how long (vector tracking: while
    /// its filter predicts the satellite).
    pub(crate) fn coasting_on_aid(&self) -> bool {
        self.state == ChannelState::Track
            && (self.fade.faded() || self.cn0_dbhz < self.cn0_lost_dbhz() - COAST_BELOW_LOST_DB)
            && self.coast_aid()
    }

    /// The signal is there: its prompt power has not collapsed ([`crate::fade_detector`]). (Not
    /// the C/N0: a loop under a manoeuvre's stress reads a falling C/N0 too, and narrowing it
    /// then loses the satellite.)
    fn signal_present(&self) -> bool {
        !self.fade.faded()
    }

    /// The aided loops with the weak-signal loops' integration time (`None` without both, or
    /// when the aided bandwidth is too wide for it). Issue 25: an aided loop at 1 ms on a
    /// satellite at 30 dB-Hz runs its Costas discriminator at 0 dB SNR per update, where it
    /// slips whatever the bandwidth (measured: G16 at 30.3 dB-Hz lost lock for 5 s in the
    /// 0.4 Hz aided staging); at 20 ms the SNR is 13 dB. The feed-forward has taken the
    /// dynamics out, so the longer integration costs nothing in a turn.
    fn aided_weak_config(&self) -> Option<LoopConfig> {
        let (aided, weak) = (self.cfg.aided_track?, self.cfg.weak_track?);
        let cfg = LoopConfig {
            t_coh_s: weak.t_coh_s,
            ..aided
        };
        cfg.validate().ok().map(|()| cfg)
    }

    /// The configuration of `which` loops.
    fn loop_config(&self, which: TrackLoops) -> LoopConfig {
        match which {
            TrackLoops::AidedWeak => self.aided_weak_config().or(self.cfg.aided_track),
            TrackLoops::Aided => self.cfg.aided_track,
            TrackLoops::Weak => self.cfg.weak_track,
            TrackLoops::WeakDynamic => self.cfg.weak_track.map(|w| dynamic_weak_config(&w)),
            TrackLoops::VectorWeak => self.cfg.vector_weak_track,
            TrackLoops::Normal => None,
        }
        .unwrap_or(self.cfg.track)
    }

    /// In tracking, switches loops when the aid has come or gone or the C/N0 has crossed a
    /// weak-signal threshold (at a data-bit edge, so that the integrations stay aligned). The
    /// carrier NCO frequency is kept: the new loop starts from the current base frequency; the
    /// code loop restarts from the current code rate (carrier-aided, so only the DLL's small
    /// correction resets).
    fn maybe_switch_loops(&mut self, at_edge: bool) {
        if self.state != ChannelState::Track || !at_edge || self.coasting_on_aid() {
            return;
        }
        let which = self.wanted_loops();
        if which == self.loops {
            return;
        }
        let loops = self.loop_config(which);
        let (Some((carrier, _)), Ok(code_loop)) =
            (self.carrier_toward(&loops), CodeLoop::new(&loops))
        else {
            return;
        };
        self.carrier = carrier;
        self.code_loop = code_loop;
        let d = loops.el_spacing_chips;
        self.taps = [d / 2.0, 0.0, -d / 2.0];
        self.loops = which;
    }

    /// Ends the channel from outside (its receiver found it follows another satellite's
    /// cross-correlation): its report at the end of the current integration interval is its
    /// last, in state [`ChannelState::Lost`].
    pub fn release(&mut self) {
        self.release_requested = true;
    }

    /// Whether the channel is running its aided tracking loops.
    pub fn aided_loops(&self) -> bool {
        matches!(self.loops, TrackLoops::Aided | TrackLoops::AidedWeak)
    }

    /// Whether the channel is running its weak-signal tracking loops (narrow, or widened for
    /// dynamics).
    pub fn weak_loops(&self) -> bool {
        matches!(self.loops, TrackLoops::Weak | TrackLoops::WeakDynamic)
    }

    /// Whether the channel is running the weak-signal loops widened for dynamics.
    pub fn dynamic_weak_loops(&self) -> bool {
        self.loops == TrackLoops::WeakDynamic
    }
}

/// How far below its loss threshold ([`Channel::cn0_lost_dbhz`]) a C/N0 estimate says the signal is gone, so
/// that a channel with a coasting aid coasts (`Channel::coasting_on_aid`), dB: the NWPR
/// estimator on noise alone read 0-15 dB-Hz in 3 s blockages; a signal between this and the
/// loss threshold keeps its loops running (coasting there froze satellites at 24-26 dB-Hz,
/// whose estimates cross the threshold back and forth, out of their lock: 0.91 of the time
/// locked scalar, 0.73 coasting).
pub const COAST_BELOW_LOST_DB: f64 = 6.0;

/// An aid's Doppler rate above which it predicts a manoeuvre, Hz/s (1 m/s^2 along the line of
/// sight; a satellite's own motion gives at most 0.9 Hz/s). Its prediction is then good to
/// tenths of a hertz but not steady: the vector weak-signal loops (3 Hz) lost phase lock on
/// its 0.3-0.9 Hz swings in a 10 g turn with an INS (31-32 dB-Hz satellites: 0.36 of the turn
/// locked); the weak-signal loops (6 Hz) held them.
pub const AID_MANOEUVRE_HZ_S: f64 = 5.0;

/// Time constant over which a vector aid's step (a filter update) reaches the carrier NCO, s:
/// the filter's update interval. A 3 Hz 3rd-order loop (`wn` = 3.8 rad/s) answers a frequency
/// step `df` with a transient phase error of about `2 pi df / wn` rad (0.3 Hz: 28 deg); spread
/// over 0.1 s, the same change costs about a fifth of it.
pub const VECTOR_AID_BLEND_S: f64 = 0.1;
/// How long after its last rate above [`AID_MANOEUVRE_HZ_S`] an aid still counts as a
/// manoeuvre's, s (the end of a turn swings as its start does).
pub const AID_MANOEUVRE_HOLD_S: f64 = 2.0;

/// How long the Costas gain keeps its C/N0 after the first new bit edge of a restarted bit
/// synchronisation, ms: the phase-lock detector's memory then holds the unaligned blocks;
/// its power-change test restarts it from five aligned 20 ms tests.
const COSTAS_HOLD_AFTER_EDGE_MS: u32 = 200;
/// How long after a fade the C/N0 estimates cannot make a channel that was not weak before
/// it weak, ms ([`Channel::watch_fade`]): about the time the estimator takes to forget an
/// outage.
const FADE_RECOVERY_HOLD_MS: u32 = 1000;

/// Which of the configured tracking loops a channel runs after pull-in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TrackLoops {
    /// [`ChannelConfig::track`].
    Normal,
    /// [`ChannelConfig::aided_track`].
    Aided,
    /// [`ChannelConfig::aided_track`] with the integration time of
    /// [`ChannelConfig::weak_track`], while aided and weak.
    AidedWeak,
    /// [`ChannelConfig::weak_track`].
    Weak,
    /// [`ChannelConfig::weak_track`] widened for dynamics ([`dynamic_weak_config`]).
    WeakDynamic,
    /// [`ChannelConfig::vector_weak_track`], while weak and checked by vector tracking.
    VectorWeak,
}

/// Time in tracking before a channel's Doppler rate is read ([`Channel::los_rate_hz_s`]), ms:
/// the rate memory of a loop just handed over still carries the pull-in's (9 Hz/s on a static
/// simulator 3.5 s into a run).
pub const RATE_SETTLED_MS: u64 = 2000;

/// Noise bandwidth of the weak-signal PLL under dynamics, Hz, and its integration time, s.
///
/// The weak loops (3rd order, 6 Hz, 20 ms) hold 28 dB-Hz but not the onset of a 10 g turn:
/// a jerk of 98 m/s^3 along the line of sight costs `j / (lambda wn^3)` = 7 rad at 6 Hz
/// (`wn = Bn / 0.7845`), so G03, G16 and G22 (29-32 dB-Hz) were lost at every onset on the
/// simulator. At 15 Hz and 10 ms (`Bn T` = 0.15) the jerk costs 0.46 rad (26 deg) and the
/// thermal jitter at 30 dB-Hz `sqrt(Bn/(C/N0) (1 + 1/(2 T C/N0)))` = 0.125 rad (7 deg): within
/// the 45 deg rule at 3 sigma (the order stays the weak loops' own: 3rd by default); measured,
/// every satellite held through the turn. Not kept in
/// static conditions: its Doppler is noisier (velocity RMS 0.056 -> 0.103 m/s at 28 dB-Hz).
pub const DYNAMIC_WEAK_BW_HZ: f64 = 15.0;
/// See [`DYNAMIC_WEAK_BW_HZ`].
pub const DYNAMIC_WEAK_T_COH_S: f64 = 0.010;

/// The weak-signal loops `weak` widened for dynamics: at least [`DYNAMIC_WEAK_BW_HZ`], at most
/// [`DYNAMIC_WEAK_T_COH_S`] of integration (`weak` itself when that is not a valid loop).
pub fn dynamic_weak_config(weak: &LoopConfig) -> LoopConfig {
    let wide = LoopConfig {
        pll_bw_hz: weak.pll_bw_hz.max(DYNAMIC_WEAK_BW_HZ),
        t_coh_s: weak.t_coh_s.min(DYNAMIC_WEAK_T_COH_S),
        ..*weak
    };
    if wide.validate().is_ok() {
        wide
    } else {
        *weak
    }
}

/// Where a code period stands relative to the data bits, from the bit synchroniser.
#[derive(Debug, Clone, Copy)]
struct BitTiming {
    /// Bit edges fall on code periods `k` (counted by `ms_count`) with `k mod 20` equal to this
    /// (None before bit synchronisation).
    edge_phase: Option<usize>,
    /// The next code period starts on a data-bit edge.
    next_is_edge: bool,
}
