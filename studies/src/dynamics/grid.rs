//! The grid: scenarios (manoeuvre, C/N0) and the loop/aiding cases tracked over each.

use super::aiding::Aiding;
use super::manoeuvre::Manoeuvre;
use super::params::{HEADLINE_BN_HZ, ORDER1_BN_HZ};

/// One scenario: a manoeuvre at one C/N0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct ScenarioSpec {
    pub(super) manoeuvre: Manoeuvre,
    pub(super) cn0_dbhz: f64,
}

/// One tracking run over a scenario.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Case {
    pub(super) order: u8,
    pub(super) bn_hz: f64,
    pub(super) aiding: Aiding,
}

/// The grid: scenarios and, for each, the cases.
pub(super) fn grid(quick: bool) -> (Vec<ScenarioSpec>, Vec<Case>) {
    let (manoeuvres, cn0s, loops): (Vec<Manoeuvre>, Vec<f64>, Vec<(u8, f64)>) = if quick {
        (
            vec![Manoeuvre::Turn(10.0)],
            vec![45.0],
            vec![(2, HEADLINE_BN_HZ)],
        )
    } else {
        let loops = [2u8, 3]
            .iter()
            .flat_map(|&o| [2.0, HEADLINE_BN_HZ, 5.0, 10.0, 18.0].map(|bn| (o, bn)))
            .collect();
        (
            vec![
                Manoeuvre::Turn(1.0),
                Manoeuvre::Turn(5.0),
                Manoeuvre::Turn(10.0),
                Manoeuvre::Turn(20.0),
                Manoeuvre::Step(10.0),
            ],
            vec![35.0, 45.0],
            loops,
        )
    };
    let scenarios = manoeuvres
        .iter()
        .flat_map(|&m| {
            cn0s.iter().map(move |&c| ScenarioSpec {
                manoeuvre: m,
                cn0_dbhz: c,
            })
        })
        .collect();
    let mut cases: Vec<Case> = loops
        .iter()
        .flat_map(|&(order, bn_hz)| {
            [Aiding::Unaided, Aiding::Ins1, Aiding::Ins2].map(|aiding| Case {
                order,
                bn_hz,
                aiding,
            })
        })
        .collect();
    for aiding in [Aiding::Ins1, Aiding::Ins2] {
        cases.push(Case {
            order: 1,
            bn_hz: ORDER1_BN_HZ,
            aiding,
        });
    }
    (scenarios, cases)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::scenario::scenario_toml;

    #[test]
    fn manoeuvre_windows_and_grid() {
        assert_eq!(Manoeuvre::Turn(10.0).window_s(), (4.0, 13.0));
        assert_eq!(Manoeuvre::Step(10.0).window_s(), (4.0, 9.0));
        let (s, c) = grid(true);
        assert_eq!((s.len(), c.len()), (1, 5));
        let (s, c) = grid(false);
        assert_eq!((s.len(), c.len()), (10, 32));
        for spec in &s {
            let sc =
                gpsrx_samples::sim::Scenario::from_toml(&scenario_toml(spec, 1, Some(&[1, 3])));
            assert!(sc.is_ok(), "{:?}", sc.err());
        }
    }
}
