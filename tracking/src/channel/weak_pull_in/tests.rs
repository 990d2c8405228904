//! The weak pull-in on synthetic signals with a known truth: C/A code with its code Doppler,
//! random 50 bit/s data whose edges fall at a known code period, a carrier at a known Doppler,
//! unit-variance complex white noise (fixed seeds).

use super::*;
use crate::channel::{ChannelConfig, ChannelEpoch, ChannelStart, ChannelState};
use gpsrx_dsp::ca_code::{CaCode, Prn};
use gpsrx_dsp::constants::{CA_CHIP_RATE_HZ, F_L1_HZ};
use num_complex::Complex32;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

const FS: f64 = 2.048e6;
const PRN: u8 = 11;
const DOPPLER_HZ: f64 = -1234.5;
/// The first data-bit edge falls at the start of code period 7 of the signal (unless a test
/// moves it: [`Signal::edge_period`]).
const EDGE_PERIOD: u64 = 7;

/// A signal at `cn0_dbhz` (`None`: noise alone) against noise of unit total variance:
/// amplitude `sqrt(C/N0 / fs)`. Samples must be asked for in order, each once.
struct Signal {
    code: CaCode,
    amp: f64,
    bits: Vec<f64>,
    rng: Xoshiro256PlusPlus,
    next: u64,
    /// Data-bit edges fall at the starts of code periods `edge_period mod 20`.
    edge_period: u64,
}

impl Signal {
    fn new(cn0_dbhz: Option<f64>, seed: u64) -> Self {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let bits = (0..2000)
            .map(|_| if rng.random::<bool>() { 1.0 } else { -1.0 })
            .collect();
        Self {
            code: CaCode::new(Prn::new(PRN).expect("PRN")),
            amp: cn0_dbhz.map_or(0.0, |c| (10f64.powf(c / 10.0) / FS).sqrt()),
            bits,
            rng,
            next: 0,
            edge_period: EDGE_PERIOD,
        }
    }

    /// The data bit of code period `m` (bit 0 before the first edge).
    fn bit_of_period(&self, m: u64) -> f64 {
        let idx = (m + 20 - self.edge_period) / 20;
        self.bits[idx as usize % self.bits.len()]
    }

    fn sample(&mut self, k: u64) -> Complex32 {
        assert_eq!(k, self.next, "samples in order");
        self.next += 1;
        let t = k as f64 / FS;
        let chips = t * CA_CHIP_RATE_HZ * (1.0 + DOPPLER_HZ / F_L1_HZ);
        let period = (chips / 1023.0).floor() as u64;
        let chip = f64::from(self.code.chip(chips.floor() as usize % 1023));
        let s = Complex64::from_polar(
            self.amp * chip * self.bit_of_period(period),
            std::f64::consts::TAU * DOPPLER_HZ * t + 0.7,
        );
        let s2 = std::f64::consts::FRAC_1_SQRT_2;
        let nr: f64 = self.rng.sample(StandardNormal);
        let ni: f64 = self.rng.sample(StandardNormal);
        Complex32::new((s.re + s2 * nr) as f32, (s.im + s2 * ni) as f32)
    }
}

/// Runs `ch` over `seconds` of the signal (or until it is lost); returns the reports.
fn run(ch: &mut Channel, sig: &mut Signal, seconds: f64) -> Vec<ChannelEpoch> {
    let end = (seconds * FS) as u64;
    let mut out = Vec::new();
    let mut x = Vec::new();
    while ch.state() != ChannelState::Lost {
        let (start, n) = ch.next_span();
        if start + n as u64 > end {
            break;
        }
        x.clear();
        x.extend((start..start + n as u64).map(|k| sig.sample(k)));
        if let Some(e) = ch.process_code_period(&x) {
            out.push(e);
        }
    }
    out
}

fn start(doppler_hz: f64, cn0_dbhz: f64) -> ChannelStart {
    ChannelStart {
        prn: Prn::new(PRN).expect("PRN"),
        code_start_sample: 0,
        doppler_hz,
        cn0_dbhz,
    }
}

#[test]
fn a_28_dbhz_signal_is_pulled_in_bit_synchronised_and_held() {
    // The acquisition's Doppler 6 Hz off and its C/N0 a little high, as in the receiver.
    let mut sig = Signal::new(Some(28.0), 2811);
    let cfg = ChannelConfig::default();
    let mut ch = Channel::new(&start(DOPPLER_HZ + 6.0, 29.0), FS, &cfg).expect("channel");
    assert!(ch.weak_pull_in(), "29 dB-Hz takes the weak pull-in");
    let reports = run(&mut ch, &mut sig, 16.0);
    assert_eq!(ch.state(), ChannelState::Track, "held for 16 s");
    assert!(ch.weak_loops(), "tracks with the weak loops");
    let confirmed_at = reports
        .iter()
        .find(|e| e.state == ChannelState::Track)
        .map(|e| e.t_rx_s);
    assert!(
        confirmed_at.is_some_and(|t| t < 8.0),
        "hand-over at {confirmed_at:?} s (want within 8 s)"
    );
    // Before the bit edges are known, the unaligned 10 ms NWPR estimate (after its first
    // 0.2 s) reads the C/N0 to within 2.5 dB on average (its edge loss at this C/N0: module
    // documentation) and never as low as the loss threshold.
    let presync: Vec<f64> = reports
        .iter()
        .filter(|e| e.t_coh_s < 0.015 && e.t_rx_s > 0.2 && e.state == ChannelState::PullIn)
        .map(|e| e.cn0_dbhz)
        .collect();
    let presync_mean = presync.iter().sum::<f64>() / presync.len().max(1) as f64;
    assert!(
        presync.len() > 50
            && (presync_mean - 28.0).abs() < 2.5
            && presync
                .iter()
                .all(|&c| c > WeakPullInConfig::default().lost_dbhz),
        "pre-sync C/N0 {presync_mean:.2} dB-Hz over {} reports",
        presync.len()
    );
    // The bit edges found are the true ones: every bit starts on a code period m with
    // m = EDGE_PERIOD mod 20 (the channel's code periods are the signal's: code start 0).
    let bits: Vec<(u64, i8)> = reports
        .iter()
        .filter_map(|e| e.bit.zip(e.bit_start_ms).map(|(b, m)| (m, b.value)))
        .collect();
    assert!(bits.len() > 300, "{} bits", bits.len());
    for (m, _) in &bits {
        assert_eq!(m % 20, EDGE_PERIOD % 20, "bit starting at code period {m}");
    }
    // After the hand-over the bits are the data (up to the Costas polarity).
    let tracked: Vec<(u64, i8)> = bits
        .iter()
        .copied()
        .filter(|(m, _)| *m as f64 * 1e-3 > confirmed_at.unwrap_or(f64::MAX) + 1.0)
        .collect();
    let agree = tracked
        .iter()
        .filter(|(m, v)| f64::from(*v) == sig.bit_of_period(*m))
        .count();
    let agree = agree.max(tracked.len() - agree) as f64 / tracked.len() as f64;
    assert!(
        agree > 0.99 && tracked.len() > 250,
        "bit agreement {agree} over {}",
        tracked.len()
    );
    // The C/N0 estimate over the last 5 s, and the Doppler held.
    let last: Vec<&ChannelEpoch> = reports.iter().filter(|e| e.t_rx_s > 11.0).collect();
    let cn0 = last.iter().map(|e| e.cn0_dbhz).sum::<f64>() / last.len() as f64;
    assert!((cn0 - 28.0).abs() < 1.5, "C/N0 estimate {cn0:.2} dB-Hz");
    let df = last.iter().map(|e| e.doppler_hz - DOPPLER_HZ).sum::<f64>() / last.len() as f64;
    assert!(df.abs() < 0.5, "Doppler error {df:.3} Hz");
    assert!(
        last.iter().all(|e| e.pll_lock),
        "phase lock through the last 5 s"
    );
    eprintln!(
        "28 dB-Hz: pre-sync C/N0 {presync_mean:.2} dB-Hz, hand-over at {confirmed_at:?} s, {} bits, agreement {agree:.4}, C/N0 {cn0:.2} dB-Hz, Doppler error {df:.3} Hz",
        bits.len()
    );
}

/// Runs a channel started at a weak C/N0 on `sig`; returns when it was lost (None: never)
/// and whether it was ever confirmed.
fn released(sig: &mut Signal, seconds: f64) -> (Option<f64>, bool) {
    let cfg = ChannelConfig::default();
    let mut ch = Channel::new(&start(DOPPLER_HZ, 29.0), FS, &cfg).expect("channel");
    let reports = run(&mut ch, sig, seconds);
    let lost = reports
        .iter()
        .find(|e| e.state == ChannelState::Lost)
        .map(|e| e.t_rx_s);
    (lost, ch.confirmed())
}

#[test]
fn noise_is_released_within_seconds_and_never_confirmed() {
    for seed in [1u64, 2, 3] {
        let (lost, confirmed) = released(&mut Signal::new(None, seed), 6.0);
        eprintln!("noise seed {seed}: lost at {lost:?} s");
        assert!(
            lost.is_some_and(|t| t < 3.0),
            "seed {seed}: noise lost at {lost:?} s"
        );
        assert!(!confirmed, "seed {seed}: noise confirmed");
    }
}

#[test]
fn a_20_dbhz_signal_is_too_weak_released_and_never_confirmed() {
    for seed in [4u64, 5] {
        let (lost, confirmed) = released(&mut Signal::new(Some(20.0), seed), 8.0);
        eprintln!("20 dB-Hz seed {seed}: lost at {lost:?} s");
        assert!(
            lost.is_some_and(|t| t < 5.0),
            "seed {seed}: 20 dB-Hz lost at {lost:?} s"
        );
        assert!(!confirmed, "seed {seed}: 20 dB-Hz confirmed");
    }
}

#[test]
fn strong_acquisitions_keep_the_normal_pull_in_and_weak_settings_are_checked() {
    let cfg = ChannelConfig::default();
    let ch = Channel::new(&start(DOPPLER_HZ, 40.0), FS, &cfg).expect("channel");
    assert!(!ch.weak_pull_in());
    let ch = Channel::new(&start(DOPPLER_HZ, f64::NAN), FS, &cfg).expect("channel");
    assert!(!ch.weak_pull_in(), "an unknown C/N0 is not weak");
    let mut bad = WeakPullInConfig::default();
    bad.fll.pll_order = 2;
    assert!(bad.validate().is_err());
    let mut bad = WeakPullInConfig::default();
    bad.pll.t_coh_s = 3e-3;
    assert!(bad.validate().is_err());
    let bad = WeakPullInConfig {
        patience_s: f64::NAN,
        ..WeakPullInConfig::default()
    };
    let msg = bad
        .validate()
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(msg.contains("patience_s"), "{msg}");
    // The lead threshold of the weak bit synchroniser (module documentation): 18 at 26 dB-Hz.
    assert_eq!(WeakPullInConfig::default().bit_sync_config().min_lead, 18);
}

#[test]
fn the_weak_pull_in_holds_28_and_30_dbhz_whatever_the_seed_edge_and_doppler_error() {
    // Six runs at each C/N0: other noise and data, bit edges at other code periods, the
    // acquisition's Doppler -8 to +12 Hz off. Every run is held for 10 s with the true edges.
    let mut summary = Vec::new();
    for (cn0, first_seed) in [(28.0, 100u64), (30.0, 200)] {
        let mut handovers = Vec::new();
        for seed in first_seed..first_seed + 6 {
            let mut sig = Signal::new(Some(cn0), seed);
            sig.edge_period = (seed * 7) % 20;
            let off_hz = (seed % 6) as f64 * 4.0 - 8.0;
            let cfg = ChannelConfig::default();
            let mut ch =
                Channel::new(&start(DOPPLER_HZ + off_hz, cn0 + 1.0), FS, &cfg).expect("channel");
            let reports = run(&mut ch, &mut sig, 10.0);
            assert_eq!(
                ch.state(),
                ChannelState::Track,
                "{cn0} dB-Hz, seed {seed}, {off_hz} Hz off: not held"
            );
            let edges_ok = reports
                .iter()
                .filter_map(|e| e.bit_start_ms)
                .all(|m| m % 20 == sig.edge_period);
            assert!(edges_ok, "{cn0} dB-Hz, seed {seed}: wrong bit edges");
            let t = reports
                .iter()
                .find(|e| e.state == ChannelState::Track)
                .map_or(f64::NAN, |e| e.t_rx_s);
            assert!(t < 7.0, "{cn0} dB-Hz, seed {seed}: hand-over at {t} s");
            handovers.push(t);
        }
        let mean = handovers.iter().sum::<f64>() / handovers.len() as f64;
        let max = handovers.iter().copied().fold(0.0, f64::max);
        summary.push(format!(
            "{cn0} dB-Hz: hand-over mean {mean:.2} s, max {max:.2} s"
        ));
    }
    eprintln!("{}", summary.join("; "));
}
