//! The grid: scenarios (manoeuvre, C/N0, lead-in) and the loop/aiding cases tracked over each.

use super::aiding::Aiding;
use super::manoeuvre::Manoeuvre;
use super::params::{
    lead_in_s, MG_MPS2, NARROW_BN_HZ, NARROW_DEFAULT_BIAS_MG, NARROW_INS1_BIAS_MG, ORDER1_BN_HZ,
    RAMP_S, TAIL_S, WIDE_BN_HZ, WIDE_INS1_BIAS_MPS2,
};

/// C/N0 of the grid, dB-Hz: 33, where the Costas discriminator's std at T = 1 ms,
/// `sqrt(1/(2 C/N0 T) (1 + 1/(2 C/N0 T)))` = 0.089 cycle, is that of seed 004 Table 3
/// (0.085-0.101 cycle), and 45, a strong signal.
pub(super) const CN0_DBHZ: [f64; 2] = [33.0, 45.0];

/// One scenario: a manoeuvre at one C/N0 after a lead-in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct ScenarioSpec {
    pub(super) manoeuvre: Manoeuvre,
    pub(super) cn0_dbhz: f64,
    /// Cruise before the manoeuvre, s (long enough for the narrowest loop tracked over it).
    pub(super) lead_in_s: f64,
}

impl ScenarioSpec {
    /// The window the statistics cover: from the start of the ramp-in to the end of the
    /// ramp-out, s.
    pub(super) fn window_s(&self) -> (f64, f64) {
        let t0 = self.lead_in_s;
        (t0, t0 + self.manoeuvre.segment_s() + RAMP_S)
    }

    /// Recording length: the window and [`TAIL_S`], s.
    pub(super) fn duration_s(&self) -> f64 {
        self.window_s().1 + TAIL_S
    }
}

/// One tracking run over a scenario.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Case {
    pub(super) order: u8,
    pub(super) bn_hz: f64,
    pub(super) aiding: Aiding,
    /// Accelerometer bias magnitude of INS 1 of this case's pair, m/s^2 (INS 2 has twice it;
    /// 0 unaided).
    pub(super) ins1_bias_mps2: f64,
}

impl Case {
    /// Accelerometer bias magnitude of this case's INS, m/s^2 (0 unaided).
    pub(super) fn bias_mps2(&self) -> f64 {
        self.aiding.bias_factor() * self.ins1_bias_mps2
    }
}

/// A loop unaided, and aided by INS 1 and INS 2 for each INS 1 bias of `ins1_biases_mps2`.
fn loop_cases(order: u8, bn_hz: f64, ins1_biases_mps2: &[f64]) -> Vec<Case> {
    let mut out = vec![Case {
        order,
        bn_hz,
        aiding: Aiding::Unaided,
        ins1_bias_mps2: 0.0,
    }];
    for &b in ins1_biases_mps2 {
        for aiding in [Aiding::Ins1, Aiding::Ins2] {
            out.push(Case {
                order,
                bn_hz,
                aiding,
                ins1_bias_mps2: b,
            });
        }
    }
    out
}

/// The aided 1st-order loops (they drift with the bias; no unaided run).
fn order1_cases() -> Vec<Case> {
    [Aiding::Ins1, Aiding::Ins2]
        .map(|aiding| Case {
            order: 1,
            bn_hz: ORDER1_BN_HZ,
            aiding,
            ins1_bias_mps2: WIDE_INS1_BIAS_MPS2,
        })
        .to_vec()
}

/// The cases of `bns_hz` that fit in a scenario of lead-in `lead_s`, at orders 2 and 3: the
/// headline bandwidth with every bias of [`NARROW_INS1_BIAS_MG`], other narrow ones with
/// [`NARROW_DEFAULT_BIAS_MG`], wide ones with [`WIDE_INS1_BIAS_MPS2`].
fn cases_for(bns_hz: &[f64]) -> Vec<Case> {
    let mut out = Vec::new();
    for order in [2u8, 3] {
        for &bn in bns_hz {
            let biases: Vec<f64> = if bn == super::params::HEADLINE_BN_HZ {
                NARROW_INS1_BIAS_MG.iter().map(|m| m * MG_MPS2).collect()
            } else if bn < 1.0 {
                vec![NARROW_DEFAULT_BIAS_MG * MG_MPS2]
            } else {
                vec![WIDE_INS1_BIAS_MPS2]
            };
            out.extend(loop_cases(order, bn, &biases));
        }
    }
    out
}

/// The grid: each scenario with its cases. Quick: the 10 g turn at 45 dB-Hz, orders 2 and 3 at
/// 0.4 Hz with a 1 mg INS 1, and the aided 1st-order loops. Full: turns of 1-20 g and a 10 g
/// step at both C/N0 of [`CN0_DBHZ`] with the wide loops, the 0.4 Hz loops at every bias and
/// the 0.8 Hz loops (12 s lead-in); and the 10 g turn again with a lead-in long enough for the
/// 0.1 and 0.2 Hz loops.
pub(super) fn grid(quick: bool) -> Vec<(ScenarioSpec, Vec<Case>)> {
    let spec = |manoeuvre, cn0_dbhz, bn_min: f64| ScenarioSpec {
        manoeuvre,
        cn0_dbhz,
        lead_in_s: lead_in_s(bn_min),
    };
    let headline = super::params::HEADLINE_BN_HZ;
    if quick {
        let mut cases: Vec<Case> = [2u8, 3]
            .iter()
            .flat_map(|&o| loop_cases(o, headline, &[NARROW_DEFAULT_BIAS_MG * MG_MPS2]))
            .collect();
        cases.extend(order1_cases());
        return vec![(spec(Manoeuvre::Turn(10.0), 45.0, headline), cases)];
    }
    let short_bns: Vec<f64> = NARROW_BN_HZ
        .iter()
        .copied()
        .filter(|&bn| lead_in_s(bn) <= lead_in_s(headline))
        .chain(WIDE_BN_HZ)
        .collect();
    let long_bns: Vec<f64> = NARROW_BN_HZ
        .iter()
        .copied()
        .filter(|&bn| lead_in_s(bn) > lead_in_s(headline))
        .collect();
    let mut out = Vec::new();
    for m in [
        Manoeuvre::Turn(1.0),
        Manoeuvre::Turn(5.0),
        Manoeuvre::Turn(10.0),
        Manoeuvre::Turn(20.0),
        Manoeuvre::Step(10.0),
    ] {
        for cn0 in CN0_DBHZ {
            let mut cases = cases_for(&short_bns);
            cases.extend(order1_cases());
            out.push((spec(m, cn0, headline), cases));
        }
    }
    if let Some(&narrowest) = long_bns.iter().min_by(|a, b| a.total_cmp(b)) {
        for cn0 in CN0_DBHZ {
            out.push((
                spec(Manoeuvre::Turn(10.0), cn0, narrowest),
                cases_for(&long_bns),
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::params::LEAD_IN_S;
    use crate::dynamics::scenario::scenario_toml;

    #[test]
    fn manoeuvre_windows_and_grid() {
        let g = grid(true);
        assert_eq!(g.len(), 1);
        let (s, c) = &g[0];
        assert_eq!(s.window_s(), (LEAD_IN_S, LEAD_IN_S + 9.0));
        assert_eq!(s.duration_s(), LEAD_IN_S + 11.0);
        assert_eq!(c.len(), 8);
        let g = grid(false);
        // 5 manoeuvres x 2 C/N0, and the 10 g turn with the long lead-in at both.
        assert_eq!(g.len(), 12);
        // Per order: 0.4 Hz unaided + 3 biases x 2 INS, 0.8 Hz and 5 wide Bn x 3; order 1 x 2.
        assert_eq!(g[0].1.len(), 2 * (7 + 6 * 3) + 2);
        // 0.1 and 0.2 Hz x 3 per order.
        assert_eq!(g[11].1.len(), 12);
        assert!(g[11].0.lead_in_s >= 45.0);
        let step = Manoeuvre::Step(10.0);
        let s = g.iter().find(|(s, _)| s.manoeuvre == step).map(|p| p.0);
        assert_eq!(s.map(|s| s.window_s()), Some((LEAD_IN_S, LEAD_IN_S + 5.0)));
        for (spec, cases) in &g {
            let sc =
                gpsrx_samples::sim::Scenario::from_toml(&scenario_toml(spec, 1, Some(&[1, 3])));
            assert!(sc.is_ok(), "{:?}", sc.err());
            for c in cases {
                let want = match c.aiding {
                    Aiding::Unaided => 0.0,
                    Aiding::Ins1 => c.ins1_bias_mps2,
                    Aiding::Ins2 => 2.0 * c.ins1_bias_mps2,
                };
                assert_eq!(c.bias_mps2(), want);
                assert!(lead_in_s(c.bn_hz) <= spec.lead_in_s, "{c:?} in {spec:?}");
            }
        }
    }
}
