//! DLL thermal jitter and carrier aiding of the code loop.
//!
//! Code-phase simulator: code phase in chips relative to the nominal chip rate, replica rate held
//! over each interval (the returned code rate minus 1.023 Mchip/s). Early, prompt and late
//! correlations of the ideal triangle `R(x) = 1 - |x|` with complex noise whose correlation
//! between taps is `R(offset)` (`R(d/2)` prompt-early/late, `R(d)` early-late), generated through
//! a 3x3 Cholesky factor.

use num_complex::Complex64;

use gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
use gpsrx_tracking::aiding::code_doppler_chips_s;
use gpsrx_tracking::{CodeLoop, DllDiscriminator, DopplerAid, LoopConfig};

use crate::sim::{g_to_hz_s, gauss, rng, std, Trajectory};

const T: f64 = 1e-3;

fn tri(x: f64) -> f64 {
    (1.0 - x.abs()).max(0.0)
}

/// Runs `n` intervals; `code` is the true code-phase deviation trajectory (chips); `aid(t)` the
/// carrier aid (chips/s) for the interval starting at `t`. Returns the true code errors (chips).
fn run_code(
    cfg: &LoopConfig,
    code: &Trajectory,
    cn0_dbhz: Option<f64>,
    seed: u64,
    n: usize,
    mut aid: impl FnMut(f64) -> f64,
) -> Vec<f64> {
    let mut dll = match CodeLoop::new(cfg) {
        Ok(d) => d,
        Err(e) => panic!("{e}"),
    };
    let d = cfg.el_spacing_chips;
    let (r1, r2) = (1.0 - d / 2.0, 1.0 - d);
    let l22 = (1.0 - r1 * r1).sqrt();
    let l32 = (r2 - r1 * r1) / l22;
    let l33 = (1.0 - r1 * r1 - l32 * l32).max(0.0).sqrt();
    let mut r = rng(seed);
    let t = cfg.t_coh_s;
    let amp = cn0_dbhz.map_or(1.0, |c| (2.0 * 10f64.powf(c / 10.0) * t).sqrt());
    let mut psi_hat = code.phase(0.0);
    let mut rate = aid(0.0);
    let mut bit = 1.0;
    let mut errs = Vec::with_capacity(n);
    let mut bit_index = -1_i64;
    for k in 0..n {
        let t0 = k as f64 * t;
        let bi = ((t0 + 1e-9) / 0.02).floor() as i64;
        if bi != bit_index && cn0_dbhz.is_some() {
            bit_index = bi;
            bit = if gauss(&mut r) < 0.0 { -1.0 } else { 1.0 };
        }
        let e = code.mean_phase(t0, t0 + t) - (psi_hat + 0.5 * rate * t);
        errs.push(e);
        let c = Complex64::from_polar(amp * bit, 0.3);
        let (mut ne, mut np, mut nl) = (
            Complex64::default(),
            Complex64::default(),
            Complex64::default(),
        );
        if cn0_dbhz.is_some() {
            let z: [Complex64; 3] = [0, 1, 2].map(|_| Complex64::new(gauss(&mut r), gauss(&mut r)));
            np = z[0];
            ne = z[0] * r1 + z[1] * l22;
            nl = z[0] * r1 + z[1] * l32 + z[2] * l33;
        }
        let early = c * tri(e - d / 2.0) + ne;
        let prompt = c * tri(e) + np;
        let late = c * tri(e + d / 2.0) + nl;
        let out = dll.update(early, prompt, late, aid(t0 + t));
        psi_hat += rate * t;
        rate = out.code_rate_chips_s - CA_CHIP_RATE_HZ;
    }
    errs
}

/// Oracle DLL jitter (chips), non-coherent E-L: `sqrt((Bn d/(2 CN0))(1 + 2/(T CN0 (2 - d))))`.
fn dll_oracle_chips(bn: f64, d: f64, cn0_dbhz: f64, t: f64) -> f64 {
    let c = 10f64.powf(cn0_dbhz / 10.0);
    ((bn * d / (2.0 * c)) * (1.0 + 2.0 / (t * c * (2.0 - d)))).sqrt()
}

/// DLL code jitter against the oracle, for E-L spacings 1, 0.5, 0.2 chip, 1st-order DLL (one
/// 2nd-order case), normalised-envelope and dot-product discriminators.
///
/// Asserted within 20 % where the oracle applies: 45 dB-Hz at T = 1 ms and 35 dB-Hz at T = 20 ms
/// (squaring loss small; ~300 correlation times per run, standard error ~4 %). At 35 dB-Hz and
/// T = 1 ms (per-correlator SNR 8 dB) the oracle's squaring-loss term belongs to the E-L *power*
/// discriminator; the normalised envelope then loses gain (noise inflates |E| + |L|), so its loop
/// is narrower and its jitter lower than the oracle: asserted only as a bound (<= 1.2 x oracle),
/// the ratio is printed.
#[test]
fn dll_jitter_matches_oracle() {
    println!("| discriminator | order | d (chip) | Bn (Hz) | T (ms) | C/N0 | measured (chip) | oracle (chip) | ratio |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut seed = 300;
    let mut cases = Vec::new();
    for d in [1.0, 0.5, 0.2] {
        for bn in [0.5, 2.0] {
            for disc in [
                DllDiscriminator::NormalizedEnvelope,
                DllDiscriminator::DotProduct,
            ] {
                cases.push((disc, 1u8, d, bn, 1e-3, 45.0, true));
                cases.push((disc, 1u8, d, bn, 20e-3, 35.0, true));
            }
            cases.push((
                DllDiscriminator::NormalizedEnvelope,
                1u8,
                d,
                bn,
                1e-3,
                35.0,
                false,
            ));
        }
    }
    cases.push((
        DllDiscriminator::NormalizedEnvelope,
        2,
        0.5,
        1.0,
        1e-3,
        45.0,
        true,
    ));
    for (disc, order, d, bn, t, cn0, strict) in cases {
        seed += 1;
        let cfg = LoopConfig {
            dll_order: order,
            dll_bw_hz: bn,
            el_spacing_chips: d,
            dll_discriminator: disc,
            t_coh_s: t,
            pll_bw_hz: 2.0,
            fll_order: 0,
            ..LoopConfig::default()
        };
        let dur = 300.0 / bn + 5.0;
        let errs = run_code(
            &cfg,
            &Trajectory::constant_freq(0.0),
            Some(cn0),
            seed,
            (dur / t) as usize,
            |_| 0.0,
        );
        let got = std(&errs[(5.0 / t) as usize..]);
        let want = dll_oracle_chips(bn, d, cn0, t);
        println!(
            "| {disc:?} | {order} | {d} | {bn} | {} | {cn0} | {got:.5} | {want:.5} | {:.3} |",
            t * 1e3,
            got / want
        );
        if strict {
            assert!(
                (got / want - 1.0).abs() < 0.20,
                "{disc:?} d {d} Bn {bn} T {t} {cn0}: {got} vs {want}"
            );
        } else {
            assert!(
                got < 1.2 * want,
                "{disc:?} d {d} Bn {bn} T {t} {cn0}: {got} vs {want}"
            );
        }
    }
    // The oracle's worked example: d = 1, Bn = 0.5 Hz, 45 dB-Hz, T = 1 ms -> 0.0029 chip.
    assert!((dll_oracle_chips(0.5, 1.0, 45.0, 1e-3) - 0.0029).abs() < 5e-5);
}

/// Carrier aiding of the code NCO: under the 5 g manoeuvre the code Doppler reaches
/// 5 g * 3.5 s / lambda / 1540 = 0.58 chip/s. A carrier-aided 1st-order DLL (aid = mean carrier
/// Doppler / 1540) keeps zero error; unaided it lags by (code rate)/omega0 chips once the motion is
/// steady again (within 10 %).
#[test]
fn carrier_aided_code_loop() {
    let peak = g_to_hz_s(5.0);
    let carrier = Trajectory::manoeuvre(1.0, 0.5, 3.0, peak);
    // Code phase = carrier phase / 1540.
    let code = Trajectory::manoeuvre(1.0, 0.5, 3.0, code_doppler_chips_s(peak));
    let cfg = LoopConfig {
        dll_order: 1,
        dll_bw_hz: 1.0,
        ..LoopConfig::default()
    };
    let n = (8.0 / T) as usize;
    let aided = run_code(&cfg, &code, None, 0, n, |t| {
        let (_, f, a) = carrier.at(t);
        code_doppler_chips_s(
            DopplerAid {
                doppler_hz: f,
                doppler_rate_hz_s: a,
                coast: false,
                checked: false,
                source: gpsrx_tracking::AidSource::Ins,
            }
            .mean_over_hz(T),
        )
    });
    let unaided = run_code(&cfg, &code, None, 0, n, |_| 0.0);
    let max_aided = aided.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
    let final_rate = code.at(8.0).1;
    let want = final_rate / gpsrx_tracking::loop_filter::omega0(1, 1.0);
    let got = unaided[n - 1];
    println!("5 g manoeuvre: carrier-aided DLL max |error| {max_aided:.2e} chip; unaided final lag {got:.4} chip (predicted {want:.4})");
    assert!(max_aided < 1e-6);
    assert!((got / want - 1.0).abs() < 0.10);
}
