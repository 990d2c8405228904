//! Unit tests of the acquisition engine on synthetic signals.

use super::*;
use crate::constants::{CA_CHIP_RATE_HZ, F_L1_HZ};
use crate::CaCode;
use num_complex::{Complex32, Complex64};

/// SplitMix64 with Box-Muller: reproducible Gaussian noise without extra dependencies.
struct Noise(u64);

impl Noise {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    /// Complex Gaussian with standard deviation `sigma` per component.
    fn complex(&mut self, sigma: f64) -> Complex64 {
        let r = sigma * (-2.0 * self.uniform().ln()).sqrt();
        let t = 2.0 * std::f64::consts::PI * self.uniform();
        Complex64::new(r * t.cos(), r * t.sin())
    }
}

/// A C/A signal: code period starting at sample `tau` (fractional), Doppler `f` (code Doppler
/// included), data bits flipping every 20 ms from `bit_edge_ms`, in unit-variance complex noise
/// (sigma 1/sqrt 2 per component) at `cn0_dbhz`.
struct Sig {
    prn: u8,
    tau: f64,
    doppler_hz: f64,
    cn0_dbhz: f64,
}

fn synth(fs: f64, n: usize, sigs: &[Sig], seed: u64) -> Vec<Complex32> {
    let mut noise = Noise(seed);
    let sigma = std::f64::consts::FRAC_1_SQRT_2;
    let mut x: Vec<Complex64> = (0..n).map(|_| noise.complex(sigma)).collect();
    for s in sigs {
        let code = CaCode::new(Prn::new(s.prn).unwrap_or_else(|e| panic!("{e}")));
        let amp = (10f64.powf(s.cn0_dbhz / 10.0) / fs).sqrt(); // C/N0 = A^2 fs / sigma_x^2
        let rate = CA_CHIP_RATE_HZ * (1.0 + s.doppler_hz / F_L1_HZ) / fs;
        for (k, v) in x.iter_mut().enumerate() {
            let chips = (k as f64 - s.tau) * rate;
            let bit = if (chips / 20_460.0 + 7.0).floor() as i64 % 3 == 0 {
                -1.0
            } else {
                1.0
            };
            let c = f64::from(code.chip(chips.rem_euclid(1023.0) as usize));
            let ph = 2.0 * std::f64::consts::PI * s.doppler_hz * k as f64 / fs + 0.7;
            *v += Complex64::from_polar(amp * c * bit, ph);
        }
    }
    x.iter()
        .map(|v| Complex32::new(v.re as f32, v.im as f32))
        .collect()
}

fn prn(p: u8) -> Prn {
    Prn::new(p).unwrap_or_else(|e| panic!("{e}"))
}

fn engine(fs: f64, cfg: AcqConfig) -> AcquisitionEngine {
    AcquisitionEngine::new(fs, cfg).unwrap_or_else(|e| panic!("{e}"))
}

/// The FFT grid equals the correlation computed sample by sample (f64), for a whole and a
/// fractional number of samples per code period.
#[test]
fn grid_matches_direct_correlation() {
    for &(fs, ms) in &[(1.2e6, 2u32), (1.5345e6, 3u32), (1.1e6, 1u32)] {
        let cfg = AcqConfig {
            coherent_ms: ms,
            noncoherent: 1,
            doppler_max_hz: 1500.0,
            bit_edge_offsets: Some(false),
            ..AcqConfig::default()
        };
        let e = engine(fs, cfg);
        let mut noise = Noise(11);
        let x: Vec<Complex32> = (0..e.samples_needed())
            .map(|_| {
                let v = noise.complex(1.0);
                Complex32::new(v.re as f32, v.im as f32)
            })
            .collect();
        let g = e
            .grid(&x, &SearchTarget::full(prn(7)))
            .unwrap_or_else(|err| panic!("{err}"));
        let code = CaCode::new(prn(7));
        let period = fs * 1e-3;
        let n = (f64::from(ms) * period).round() as usize;
        let whole = (period - period.round()).abs() < 1e-6;
        for &(row, lag) in &[(0usize, 0usize), (1, 17), (3, 400), (5, g.n_lags - 1)] {
            let row = row.min(g.doppler_hz.len() - 1);
            let f = g.doppler_hz[row];
            let mut acc = Complex64::new(0.0, 0.0);
            for (k, v) in x[..n].iter().enumerate() {
                // The replica as the engine samples it: one period (L-periodic) or the block.
                let idx = if whole {
                    (k + n - lag) % period.round() as usize
                } else {
                    (k + n - lag) % n
                };
                let chip = (idx as f64 * CA_CHIP_RATE_HZ / fs) as usize;
                let c = f64::from(code.chip(chip % 1023));
                let ph = -2.0 * std::f64::consts::PI * f * k as f64 / fs;
                acc +=
                    Complex64::new(f64::from(v.re), f64::from(v.im)) * Complex64::from_polar(c, ph);
            }
            let got = f64::from(g.power[row * g.n_lags + lag]);
            let want = acc.norm_sqr();
            let scale = n as f64; // noise power of one cell
            assert!(
                (got - want).abs() < 2e-4 * scale + 1e-4 * want,
                "fs {fs} ms {ms} row {row} lag {lag}: fft {got} direct {want}"
            );
        }
    }
}

#[test]
fn finds_signals_at_awkward_rates() {
    // 2.6 MHz (whole, not a power of two), 5 MHz, and 2.0471 MHz (fractional period).
    for &(fs, seed) in &[(2.6e6, 1u64), (5.0e6, 2), (2.0471e6, 3)] {
        let e = engine(fs, AcqConfig::default());
        let period = fs * 1e-3;
        let sigs = [
            Sig {
                prn: 3,
                tau: 0.37 * period,
                doppler_hz: 3210.0,
                cn0_dbhz: 45.0,
            },
            Sig {
                prn: 17,
                tau: 0.81 * period + 0.4,
                doppler_hz: -4444.0,
                cn0_dbhz: 42.0,
            },
        ];
        let x = synth(fs, e.samples_wanted(), &sigs, seed);
        let targets: Vec<SearchTarget> = [3u8, 17, 22]
            .iter()
            .map(|&p| SearchTarget::full(prn(p)))
            .collect();
        let res = e.search(&x, &targets).unwrap_or_else(|err| panic!("{err}"));
        for (s, r) in sigs.iter().zip(&res) {
            assert!(r.detected, "fs {fs}: {r:?}");
            // Early/late refinement: well inside a sample; 100 prompts: Doppler to ~1 Hz;
            // C/N0 reads 0.1-0.2 dB low (the signal's own sidelobes raise its row floor).
            let d = (r.code_phase_samples - s.tau).abs();
            assert!(
                d.min(period - d) < 0.25,
                "fs {fs}: code {} vs {}",
                r.code_phase_samples,
                s.tau
            );
            assert!((r.doppler_hz - s.doppler_hz).abs() < 3.0, "fs {fs}: {r:?}");
            let cn0 = r.cn0_dbhz.unwrap_or(0.0);
            assert!(
                (cn0 - s.cn0_dbhz).abs() < 0.8,
                "fs {fs}: C/N0 {cn0} vs {}",
                s.cn0_dbhz
            );
        }
        assert!(!res[2].detected, "fs {fs}: PRN 22 absent but {:?}", res[2]);
    }
}

#[test]
fn long_coherent_with_bit_edges_and_code_doppler() {
    // 10 ms x 10 at 32 dB-Hz with a Doppler of 9 kHz: the 100 ms sum spans 0.6 chip of code
    // Doppler, and bits flip inside blocks.
    let fs = 4.0e6;
    let cfg = AcqConfig {
        coherent_ms: 10,
        noncoherent: 10,
        doppler_max_hz: 10_000.0,
        ..AcqConfig::default()
    };
    let e = engine(fs, cfg);
    assert!((e.doppler_step_hz() - 50.0).abs() < 1e-9);
    let sig = Sig {
        prn: 11,
        tau: 2222.3,
        doppler_hz: 9_013.0,
        cn0_dbhz: 32.0,
    };
    let x = synth(fs, e.samples_wanted(), std::slice::from_ref(&sig), 5);
    let r = &e
        .search(&x, &[SearchTarget::around(prn(11), 9_000.0, 500.0)])
        .unwrap_or_else(|err| panic!("{err}"))[0];
    assert!(r.detected, "{r:?}");
    assert!((r.code_phase_samples - sig.tau).abs() < 1.0, "{r:?}");
    assert!((r.doppler_hz - sig.doppler_hz).abs() < 10.0, "{r:?}");
}

#[test]
fn noise_only_gives_no_detection_and_unit_floor() {
    let fs = 4.0e6;
    let e = engine(fs, AcqConfig::default());
    let x = synth(fs, e.samples_needed(), &[], 99);
    let res = e.search_all(&x).unwrap_or_else(|err| panic!("{err}"));
    for r in &res {
        assert!(!r.detected, "{r:?}");
        assert!(r.metric < r.threshold);
    }
}

#[test]
fn bad_settings_and_short_input_are_errors() {
    let cases = [
        AcqConfig {
            coherent_ms: 0,
            ..AcqConfig::default()
        },
        AcqConfig {
            coherent_ms: 11,
            ..AcqConfig::default()
        },
        AcqConfig {
            noncoherent: 0,
            ..AcqConfig::default()
        },
        AcqConfig {
            pfa: 0.0,
            ..AcqConfig::default()
        },
        AcqConfig {
            pfa: f64::NAN,
            ..AcqConfig::default()
        },
        AcqConfig {
            doppler_step_hz: Some(700.0),
            ..AcqConfig::default()
        },
        AcqConfig {
            doppler_step_hz: Some(10.0),
            ..AcqConfig::default()
        },
        AcqConfig {
            doppler_max_hz: -1.0,
            ..AcqConfig::default()
        },
        AcqConfig {
            doppler_max_hz: f64::INFINITY,
            ..AcqConfig::default()
        },
    ];
    for c in cases {
        assert!(AcquisitionEngine::new(4e6, c.clone()).is_err(), "{c:?}");
    }
    assert!(AcquisitionEngine::new(0.5e6, AcqConfig::default()).is_err());
    assert!(AcquisitionEngine::new(f64::NAN, AcqConfig::default()).is_err());
    let e = engine(4e6, AcqConfig::default());
    let short = vec![Complex32::new(0.0, 0.0); e.samples_needed() - 1];
    assert!(matches!(
        e.search_all(&short),
        Err(AcqError::NotEnoughSamples { .. })
    ));
    let far = SearchTarget::around(prn(1), 20_500.0, 500.0);
    let x = vec![Complex32::new(0.0, 0.0); e.samples_needed()];
    assert!(matches!(
        e.search(&x, &[far]),
        Err(AcqError::EmptyDopplerWindow { .. })
    ));
    // All-zero input: no panic, no detection.
    let res = e.search_all(&x).unwrap_or_else(|err| panic!("{err}"));
    assert!(res.iter().all(|r| !r.detected));
    // NaN and infinities (the sample layer zeroes them, but the engine must not panic either).
    let mut bad = synth(4e6, e.samples_wanted(), &[], 3);
    for (i, v) in bad.iter_mut().enumerate().step_by(997) {
        *v = match i % 3 {
            0 => Complex32::new(f32::NAN, 0.0),
            1 => Complex32::new(f32::INFINITY, 1.0),
            _ => Complex32::new(0.0, f32::NEG_INFINITY),
        };
    }
    assert!(e.search_all(&bad).is_ok());
}

#[test]
fn doppler_step_is_never_wider_than_asked() {
    let e = engine(
        4e6,
        AcqConfig {
            doppler_step_hz: Some(300.0),
            ..AcqConfig::default()
        },
    );
    assert!((e.doppler_step_hz() - 250.0).abs() < 1e-9);
    let e = engine(
        4e6,
        AcqConfig {
            coherent_ms: 4,
            ..AcqConfig::default()
        },
    );
    assert!((e.doppler_step_hz() - 125.0).abs() < 1e-9);
    assert_eq!(e.doppler_range_hz(), (-5000.0, 5000.0));
}
